//! Files of settings (a campaign's manifest, a prior file) parsed into values that know the
//! line they start on, from JSON (serde_json's raw values borrow from the text, so their offset
//! gives their line) or from TOML (toml's `DeTable` keeps the span of every key and value): the
//! checks of each file then name the line of every problem. Nothing in a file can make this
//! module panic; nesting deeper than [`MAX_DEPTH`] is refused.

use crate::InputProblem;
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_json::value::RawValue;
use std::path::Path;

/// A parsed value with the 1-based line it starts on.
#[derive(Debug)]
pub struct Node {
    /// Line of the value (of its key, for a table entry in TOML).
    pub line: usize,
    /// The value.
    pub value: Val,
}

/// A parsed value.
#[derive(Debug)]
pub enum Val {
    /// Entries in file order (duplicates kept, so that they can be reported).
    Table(Vec<(String, Node)>),
    /// Items in file order.
    Array(Vec<Node>),
    /// A number, with its exact value when it is written as an integer.
    Number {
        /// The value (NaN when the text is not a number a float can hold).
        value: f64,
        /// The integer written, when it is one.
        integer: Option<i128>,
    },
    /// A string.
    Text(String),
    /// true or false.
    Bool(bool),
    /// Anything else, by its type name.
    Other(&'static str),
}

impl Val {
    /// What it is, for messages ("a table", "a number", "true/false", "null", "a date").
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

    /// The kind, with a number's value and a list's length.
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
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Raw<'de>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object or an array")
            }
            fn visit_map<M: MapAccess<'de>>(self, mut map: M) -> Result<Raw<'de>, M::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = map.next_entry::<String, &'de RawValue>()? {
                    out.push((k, v));
                }
                Ok(Raw::Entries(out))
            }
            fn visit_seq<S: SeqAccess<'de>>(self, mut seq: S) -> Result<Raw<'de>, S::Error> {
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

/// What a file of one kind should hold, in the words of its messages: `json` and `toml` follow
/// "expected JSON: " and "expected TOML: ", `content` follows "nested too deeply (expected ".
#[derive(Clone, Copy, Debug)]
pub struct Expected<'a> {
    /// What the file is, e.g. "manifest" ("unknown manifest format").
    pub file: &'a str,
    /// E.g. "an object with `sets` and optionally `options`".
    pub json: &'a str,
    /// E.g. "`[[sets]]` tables with a `path`, and optionally `[options]`".
    pub toml: &'a str,
    /// E.g. "a manifest of sets and options".
    pub content: &'a str,
}

/// Parses JSON or TOML by the extension of `path` (`.json`, `.toml`; any other is refused).
pub fn parse(text: &str, path: &Path, expected: &Expected) -> Result<Node, InputProblem> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    match ext.as_deref() {
        Some("json") => json_root(text, path, expected),
        Some("toml") => toml_root(text, path, expected),
        _ => Err(InputProblem::new(
            path,
            None,
            None,
            format!(
                "unknown {} format (expected a file ending in .json or .toml)",
                expected.file
            ),
        )),
    }
}

/// Parses JSON text.
pub fn json_root(text: &str, path: &Path, expected: &Expected) -> Result<Node, InputProblem> {
    let raw: &RawValue = serde_json::from_str(text).map_err(|e| json_error(path, &e, expected))?;
    json_node(text, raw, path, expected, 0)
}

fn json_error(path: &Path, e: &serde_json::Error, expected: &Expected) -> InputProblem {
    let message = e.to_string();
    let message = match message.find(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message,
    };
    InputProblem::new(
        path,
        Some(e.line().max(1)),
        None,
        format!("{message} (expected JSON: {})", expected.json),
    )
}

/// Nesting deeper than any file of ours needs is refused rather than followed.
pub const MAX_DEPTH: usize = 32;

fn json_node(
    text: &str,
    raw: &RawValue,
    path: &Path,
    expected: &Expected,
    depth: usize,
) -> Result<Node, InputProblem> {
    let s = raw.get();
    let offset = (s.as_ptr() as usize).saturating_sub(text.as_ptr() as usize);
    let line = line_of(text, offset);
    if depth > MAX_DEPTH {
        return Err(InputProblem::new(
            path,
            Some(line),
            None,
            format!("nested too deeply (expected {})", expected.content),
        ));
    }
    let value = match s.as_bytes().first() {
        Some(b'{' | b'[') => {
            match serde_json::from_str::<Raw>(s).map_err(|e| json_error(path, &e, expected))? {
                Raw::Entries(entries) => Val::Table(
                    entries
                        .into_iter()
                        .map(|(k, v)| Ok((k, json_node(text, v, path, expected, depth + 1)?)))
                        .collect::<std::result::Result<_, _>>()?,
                ),
                Raw::Items(items) => Val::Array(
                    items
                        .into_iter()
                        .map(|v| json_node(text, v, path, expected, depth + 1))
                        .collect::<std::result::Result<_, _>>()?,
                ),
            }
        }
        Some(b'"') => Val::Text(serde_json::from_str(s).unwrap_or_default()),
        Some(b't') => Val::Bool(true),
        Some(b'f') => Val::Bool(false),
        Some(b'n') => Val::Other("null"),
        _ => Val::Number {
            value: serde_json::from_str::<f64>(s).map_err(|e| json_error(path, &e, expected))?,
            integer: s.parse::<i128>().ok(),
        },
    };
    Ok(Node { line, value })
}

/// Parses TOML text.
pub fn toml_root(text: &str, path: &Path, expected: &Expected) -> Result<Node, InputProblem> {
    use toml::de::DeTable;
    let table = DeTable::parse(text).map_err(|e| {
        let line = e.span().map_or(1, |s| line_of(text, s.start));
        InputProblem::new(
            path,
            Some(line),
            None,
            format!("{} (expected TOML: {})", e.message().trim(), expected.toml),
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

#[cfg(test)]
mod tests {
    use super::*;

    const EXPECTED: Expected = Expected {
        file: "small file",
        json: "an object",
        toml: "tables",
        content: "a small file",
    };

    fn table(n: &Node) -> &[(String, Node)] {
        match &n.value {
            Val::Table(t) => t,
            v => panic!("{}", v.kind()),
        }
    }

    #[test]
    fn json_values_know_their_lines_and_keep_duplicates() {
        let text = "{\n  \"a\": 1,\n  \"b\": [true, \"x\"],\n  \"a\": 2.5\n}";
        let root = parse(text, Path::new("f.json"), &EXPECTED).unwrap();
        let t = table(&root);
        let lines: Vec<(&str, usize)> = t.iter().map(|(k, n)| (k.as_str(), n.line)).collect();
        assert_eq!(lines, [("a", 2), ("b", 3), ("a", 4)]);
        assert!(matches!(
            t[0].1.value,
            Val::Number {
                integer: Some(1),
                ..
            }
        ));
        assert!(matches!(t[2].1.value, Val::Number { integer: None, value } if value == 2.5));
        assert_eq!(t[1].1.value.describe(), "a list of 2");
    }

    #[test]
    fn toml_values_know_their_lines_and_integers_keep_their_radix() {
        let text = "x = 0x1F\n\n[t]\nflag = true\nwhen = 2026-11-24\n";
        let root = parse(text, Path::new("f.TOML"), &EXPECTED).unwrap();
        let t = table(&root);
        assert_eq!((t[0].0.as_str(), t[0].1.line), ("x", 1));
        assert!(matches!(
            t[0].1.value,
            Val::Number {
                integer: Some(31),
                ..
            }
        ));
        let inner = table(&t[1].1);
        assert_eq!(inner[0].1.line, 4);
        assert_eq!(inner[0].1.value.kind(), "true/false");
        assert_eq!(inner[1].1.value.kind(), "a date");
    }

    #[test]
    fn errors_name_the_file_the_line_and_what_was_expected() {
        let e = parse("{\n\"a\": 1,\n\"b\": }", Path::new("m.json"), &EXPECTED).unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(
            e.to_string().contains("m.json") && e.to_string().contains("expected JSON: an object"),
            "{e}"
        );
        let e = parse("a = 1\nb = = 2\n", Path::new("m.toml"), &EXPECTED).unwrap_err();
        assert_eq!(e.line, Some(2));
        assert!(e.to_string().contains("expected TOML: tables"), "{e}");
        let e = parse("a = 1", Path::new("m.yaml"), &EXPECTED).unwrap_err();
        assert!(
            e.to_string()
                .contains("unknown small file format (expected a file ending in .json or .toml)"),
            "{e}"
        );
        let deep = format!("{}{}", "[".repeat(MAX_DEPTH + 5), "]".repeat(MAX_DEPTH + 5));
        let e = parse(&deep, Path::new("d.json"), &EXPECTED).unwrap_err();
        assert!(
            e.to_string()
                .contains("nested too deeply (expected a small file)"),
            "{e}"
        );
    }
}
