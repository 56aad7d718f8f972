//! A manifest file parsed into values that know the line they start on, from JSON (serde_json's
//! raw values borrow from the text, so their offset gives their line) or from TOML (toml's
//! `DeTable` keeps the span of every key and value): the checks of [`super::manifest`] then
//! name the line of every problem.

use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::value::RawValue;
use std::path::Path;
use subfric_data::InputProblem;

pub(super) struct Node {
    pub line: usize,
    pub value: Val,
}

pub(super) enum Val {
    /// Entries in file order (duplicates kept, so that they can be reported).
    Table(Vec<(String, Node)>),
    Array(Vec<Node>),
    Number {
        value: f64,
        integer: Option<i128>,
    },
    Text(String),
    Bool(bool),
    /// Anything else, by its type name.
    Other(&'static str),
}

impl Val {
    pub fn kind(&self) -> &'static str {
        match self {
            Val::Table(_) => "a table",
            Val::Array(_) => "a list",
            Val::Number { .. } => "a number",
            Val::Text(_) => "a text",
            Val::Bool(_) => "true/false",
            Val::Other(t) => t,
        }
    }

    /// The kind, with a number's value.
    pub fn describe(&self) -> String {
        match self {
            Val::Number { value, .. } => format!("{value}"),
            Val::Array(v) => format!("a list of {}", v.len()),
            v => v.kind().to_string(),
        }
    }
}

/// 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
        + 1
}

/// The entries of a JSON object in file order, duplicates kept; the items of an array.
enum Raw<'a> {
    Entries(Vec<(String, &'a RawValue)>),
    Items(Vec<&'a RawValue>),
}

impl<'de> Deserialize<'de> for Raw<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Raw<'de>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object or an array")
            }
            fn visit_map<M: MapAccess<'de>>(
                self,
                mut map: M,
            ) -> std::result::Result<Raw<'de>, M::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = map.next_entry::<String, &'de RawValue>()? {
                    out.push((k, v));
                }
                Ok(Raw::Entries(out))
            }
            fn visit_seq<S: SeqAccess<'de>>(
                self,
                mut seq: S,
            ) -> std::result::Result<Raw<'de>, S::Error> {
                let mut out = Vec::new();
                while let Some(v) = seq.next_element::<&'de RawValue>()? {
                    out.push(v);
                }
                Ok(Raw::Items(out))
            }
        }
        d.deserialize_any(V)
    }
}

pub(super) fn json_root(text: &str, path: &Path) -> std::result::Result<Node, InputProblem> {
    let raw: &RawValue = serde_json::from_str(text).map_err(|e| json_error(path, &e))?;
    json_node(text, raw, path, 0)
}

fn json_error(path: &Path, e: &serde_json::Error) -> InputProblem {
    let message = e.to_string();
    let message = match message.find(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message,
    };
    InputProblem::new(
        path,
        Some(e.line().max(1)),
        None,
        format!("{message} (expected JSON: an object with `sets` and optionally `options`)"),
    )
}

/// Nesting deeper than any manifest needs is refused rather than followed.
const MAX_DEPTH: usize = 32;

fn json_node(
    text: &str,
    raw: &RawValue,
    path: &Path,
    depth: usize,
) -> std::result::Result<Node, InputProblem> {
    let s = raw.get();
    let offset = (s.as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
    let line = line_of(text, offset);
    if depth > MAX_DEPTH {
        return Err(InputProblem::new(
            path,
            Some(line),
            None,
            "nested too deeply (expected a manifest of sets and options)",
        ));
    }
    let value = match s.as_bytes().first() {
        Some(b'{' | b'[') => {
            match serde_json::from_str::<Raw>(s).map_err(|e| json_error(path, &e))? {
                Raw::Entries(entries) => Val::Table(
                    entries
                        .into_iter()
                        .map(|(k, v)| Ok((k, json_node(text, v, path, depth + 1)?)))
                        .collect::<std::result::Result<_, _>>()?,
                ),
                Raw::Items(items) => Val::Array(
                    items
                        .into_iter()
                        .map(|v| json_node(text, v, path, depth + 1))
                        .collect::<std::result::Result<_, _>>()?,
                ),
            }
        }
        Some(b'"') => Val::Text(serde_json::from_str(s).unwrap_or_default()),
        Some(b't') => Val::Bool(true),
        Some(b'f') => Val::Bool(false),
        Some(b'n') => Val::Other("null"),
        _ => Val::Number {
            value: serde_json::from_str::<f64>(s).map_err(|e| json_error(path, &e))?,
            integer: s.parse::<i128>().ok(),
        },
    };
    Ok(Node { line, value })
}

pub(super) fn toml_root(text: &str, path: &Path) -> std::result::Result<Node, InputProblem> {
    use toml::de::DeTable;
    let table = DeTable::parse(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of(text, s.start));
        InputProblem::new(
            path,
            Some(line),
            None,
            format!(
                "{} (expected TOML: `[[sets]]` tables with a `path`, and optionally `[options]`)",
                e.message().trim()
            ),
        )
    })?;
    Ok(Node {
        line: 1,
        value: toml_table(text, table.get_ref()),
    })
}

fn toml_table(text: &str, table: &toml::de::DeTable) -> Val {
    let mut items: Vec<(String, Node)> = table
        .iter()
        .map(|(k, v)| {
            let line = line_of(text, k.span().start);
            (
                k.get_ref().to_string(),
                Node {
                    line,
                    value: toml_value(text, v.get_ref()),
                },
            )
        })
        .collect();
    items.sort_by_key(|(_, n)| n.line);
    Val::Table(items)
}

fn toml_value(text: &str, v: &toml::de::DeValue) -> Val {
    use toml::de::DeValue;
    match v {
        DeValue::Table(t) => toml_table(text, t),
        DeValue::String(s) => Val::Text(s.to_string()),
        DeValue::Float(f) => Val::Number {
            value: f.as_str().replace('_', "").parse().unwrap_or(f64::NAN),
            integer: None,
        },
        DeValue::Integer(i) => {
            let digits = i.as_str().replace('_', "");
            let digits = digits
                .trim_start_matches('+')
                .trim_start_matches("0x")
                .trim_start_matches("0o")
                .trim_start_matches("0b");
            let integer = i128::from_str_radix(digits, i.radix()).ok();
            Val::Number {
                value: integer.map_or(f64::NAN, |v| v as f64),
                integer,
            }
        }
        DeValue::Boolean(b) => Val::Bool(*b),
        DeValue::Datetime(_) => Val::Other("a date"),
        DeValue::Array(items) => Val::Array(
            items
                .iter()
                .map(|item| Node {
                    line: line_of(text, item.span().start),
                    value: toml_value(text, item.get_ref()),
                })
                .collect(),
        ),
    }
}
