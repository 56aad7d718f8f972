//! A [`Model`] from JSON text: the one reader of the files that hold parameters, for every front
//! end (the command line, the Python package, the C interface). It accepts
//!
//! - a `fit.json` written by `subfric fit`: its `model` object (`params` and `ext`);
//! - a model object `{"params": {...}, "ext": {...}}` (what `fit.json`'s `model` holds);
//! - an `experiment.json`: its `reference_parameters`;
//! - a `params.json`: the parameters at the top level (the keys of `reference_parameters`).
//!
//! Unknown keys among the parameters are ignored (a published `reference_parameters` carries a
//! `source`), but an unknown key among the extensions is refused: a misspelt extension or field
//! would otherwise silently give another model. Reading the file is the caller's business: this
//! module parses text and values only.

use crate::{Extensions, Model, ParamError, Params};
use serde_json::Value;

/// The base parameters a parameter object must hold, as numbers.
const REQUIRED: [&str; 6] = ["mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t"];

/// Why JSON is not a model.
#[derive(Debug, thiserror::Error)]
pub enum ModelJsonError {
    /// Not JSON at all.
    #[error("not valid JSON at line {line} column {column}: {message} (expected an object with mu_s, mu_k, kappa, xi, u_tilde, alpha_t)")]
    Syntax {
        /// Line of the mistake (from 1).
        line: usize,
        /// Column of the mistake (from 1).
        column: usize,
        /// What the JSON parser says.
        message: String,
    },
    /// JSON, but not a parameter object: a missing or mistyped field, an unknown extension;
    /// the message names the field by its path (`model.params.mu_k`, `ext.rate`, ...).
    #[error("{0}")]
    Shape(String),
    /// A key given twice in one object (`{"mu_s": 0.3, "mu_s": 0.4}`): JSON readers disagree on
    /// which one counts, so neither does.
    #[error("field `{key}` appears twice at line {line} column {column} (expected each field once: which of the two values is meant?)")]
    Duplicate {
        /// The key's path (`model.params.mu_s`, `xi`, ...).
        key: String,
        /// Line of its second occurrence (from 1).
        line: usize,
        /// Column just past its second occurrence (from 1).
        column: usize,
    },
    /// A model, but with invalid parameters (every one named).
    #[error(transparent)]
    Invalid(#[from] ParamError),
}

/// The model in a JSON text (see the module documentation for the shapes accepted).
///
/// ```
/// let m = subfric_model::model_from_json(
///     r#"{"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000}"#,
/// ).unwrap();
/// assert_eq!(m.params, subfric_model::Params::sample());
/// ```
pub fn model_from_json(text: &str) -> Result<Model, ModelJsonError> {
    let v: Value = serde_json::from_str(text).map_err(|e| ModelJsonError::Syntax {
        line: e.line(),
        column: e.column(),
        message: e.to_string(),
    })?;
    unique_keys::check(text)?;
    model_from_value(&v)
}

/// A walk over a JSON text that fails at the first key given twice in one object (a
/// `serde_json::Value` keeps the last one silently).
mod unique_keys {
    use super::ModelJsonError;
    use serde::de::{DeserializeSeed, Deserializer, Error, MapAccess, SeqAccess, Visitor};
    use std::collections::HashSet;
    use std::fmt;

    /// The text's first duplicate key, as [`ModelJsonError::Duplicate`].
    pub(super) fn check(text: &str) -> Result<(), ModelJsonError> {
        let mut de = serde_json::Deserializer::from_str(text);
        let mut found = None;
        let walk = Walk {
            path: String::new(),
            found: &mut found,
        };
        match walk.deserialize(&mut de) {
            Ok(()) => Ok(()),
            Err(e) => Err(match found {
                Some(key) => ModelJsonError::Duplicate {
                    key,
                    line: e.line(),
                    column: e.column(),
                },
                None => ModelJsonError::Syntax {
                    line: e.line(),
                    column: e.column(),
                    message: e.to_string(),
                },
            }),
        }
    }

    /// One value at `path`; `found` receives the path of a duplicate key.
    struct Walk<'a> {
        path: String,
        found: &'a mut Option<String>,
    }

    impl<'de> DeserializeSeed<'de> for Walk<'_> {
        type Value = ();
        fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
            d.deserialize_any(self)
        }
    }

    impl<'de> Visitor<'de> for Walk<'_> {
        type Value = ();

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a JSON value")
        }

        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
            let mut seen = HashSet::new();
            while let Some(key) = map.next_key::<String>()? {
                let path = if self.path.is_empty() {
                    key.clone()
                } else {
                    format!("{}.{key}", self.path)
                };
                if !seen.insert(key) {
                    *self.found = Some(path);
                    return Err(A::Error::custom("duplicate key"));
                }
                map.next_value_seed(Walk {
                    path,
                    found: &mut *self.found,
                })?;
            }
            Ok(())
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
            let mut i = 0;
            while seq
                .next_element_seed(Walk {
                    path: format!("{}[{i}]", self.path),
                    found: &mut *self.found,
                })?
                .is_some()
            {
                i += 1;
            }
            Ok(())
        }

        fn visit_bool<E: Error>(self, _: bool) -> Result<(), E> {
            Ok(())
        }
        fn visit_i64<E: Error>(self, _: i64) -> Result<(), E> {
            Ok(())
        }
        fn visit_u64<E: Error>(self, _: u64) -> Result<(), E> {
            Ok(())
        }
        fn visit_f64<E: Error>(self, _: f64) -> Result<(), E> {
            Ok(())
        }
        fn visit_str<E: Error>(self, _: &str) -> Result<(), E> {
            Ok(())
        }
        fn visit_unit<E: Error>(self) -> Result<(), E> {
            Ok(())
        }
    }
}

/// The model in a parsed JSON value (see the module documentation for the shapes accepted).
pub fn model_from_value(v: &Value) -> Result<Model, ModelJsonError> {
    let (params, ext, at) = if let Some(m) = v.get("model") {
        (m.get("params"), m.get("ext"), "model.params")
    } else if v.get("params").is_some_and(Value::is_object) {
        (v.get("params"), v.get("ext"), "params")
    } else if let Some(r) = v.get("reference_parameters") {
        (Some(r), None, "reference_parameters")
    } else {
        (Some(v), None, "")
    };
    let params = params_of(params, at)?;
    let ext_path = if at.starts_with("model") {
        "model.ext"
    } else {
        "ext"
    };
    let ext = match ext {
        Some(e) if !e.is_null() => extensions_of(e, ext_path)?,
        _ => Extensions::default(),
    };
    Ok(Model::new(params, ext)?)
}

/// The field path `key` inside the object at `at` (`at` empty: the top level).
fn field(at: &str, key: &str) -> String {
    if at.is_empty() {
        key.to_string()
    } else {
        format!("{at}.{key}")
    }
}

/// The base parameters in the object `obj` found at `at`; every required key a number.
fn params_of(obj: Option<&Value>, at: &str) -> Result<Params, ModelJsonError> {
    let shape = |m: String| Err(ModelJsonError::Shape(m));
    let Some(obj) = obj.filter(|o| o.is_object()) else {
        let place = if at.is_empty() {
            String::new()
        } else {
            format!(" at `{at}`")
        };
        return shape(format!(
            "expected a JSON object of parameters{place} (mu_s, mu_k, kappa, xi, u_tilde, alpha_t, ...)"
        ));
    };
    for key in REQUIRED {
        match obj.get(key) {
            None => {
                return shape(format!(
                    "field `{}` is missing (expected a number)",
                    field(at, key)
                ))
            }
            Some(x) if !x.is_number() => {
                return shape(format!(
                    "field `{}` is {x} (expected a number)",
                    field(at, key)
                ))
            }
            _ => {}
        }
    }
    serde_json::from_value(obj.clone()).map_err(|e| {
        let place = if at.is_empty() {
            "the parameters".to_string()
        } else {
            format!("`{at}`")
        };
        ModelJsonError::Shape(format!("{place}: {e}"))
    })
}

/// The extensions in `e` (found at `path`), every key known.
fn extensions_of(e: &Value, path: &str) -> Result<Extensions, ModelJsonError> {
    let ext: Extensions = serde_json::from_value(e.clone())
        .map_err(|err| ModelJsonError::Shape(format!("field `{path}`: {err}")))?;
    // serde ignores unknown keys; everything read is written back, so a key of the input that
    // is not is unknown. What differs in shape only is compared as the reader writes it
    // ([`as_read`]).
    let back = serde_json::to_value(ext).unwrap_or_default();
    let input = as_read(e);
    if let Some(key) = unknown_key(input.as_ref().unwrap_or(e), &back, path) {
        return Err(ModelJsonError::Shape(format!(
            "field `{key}` is not a known extension or extension field"
        )));
    }
    Ok(ext)
}

/// `e` as the reader writes it back, where it may differ in shape only: a `term` object
/// (`{"family": name, ...}`, older files) moved under the family's key without its name, and a
/// registered family's parameter that its form does not use left out when it holds its default
/// (older files wrote every field, e.g. the direction effect's `"d_k": 0` whatever its target),
/// or whatever it holds for a family whose older files wrote every parameter (time healing's
/// `"n"` beside a log law).
/// `None` when `e` needs neither.
fn as_read(e: &Value) -> Option<Value> {
    let mut obj = e.as_object()?.clone();
    let mut changed = false;
    if let Some(mut term) = obj.get("term").and_then(Value::as_object).cloned() {
        if let Some((_, family)) = term
            .remove("family")
            .and_then(|n| crate::terms::family_named(n.as_str()?))
        {
            obj.remove("term");
            obj.insert(family.key(), Value::Object(term));
            changed = true;
        }
    }
    for family in crate::terms::FAMILIES {
        let Some(Value::Object(body)) = obj.get_mut(&family.key()) else {
            continue;
        };
        let form = &family.forms()[family.read_form(body).unwrap_or(0)];
        for (i, q) in family.params().iter().enumerate() {
            let at_default = body.get(q.name).and_then(Value::as_f64) == Some(q.default);
            let dropped = at_default || family.older_files_wrote_every_param();
            if dropped && body.contains_key(q.name) && !form.params.contains(&i) {
                body.remove(q.name);
                changed = true;
            }
        }
    }
    changed.then_some(Value::Object(obj))
}

/// The first key of `input` (an object, recursively) with a non-null value that `back` (what
/// was read, written back) lacks, as a dotted path.
fn unknown_key(input: &Value, back: &Value, path: &str) -> Option<String> {
    let obj = input.as_object()?;
    for (key, value) in obj {
        if value.is_null() {
            continue;
        }
        let here = format!("{path}.{key}");
        match back.get(key) {
            None => return Some(here),
            Some(b) => {
                if let Some(k) = unknown_key(value, b, &here) {
                    return Some(k);
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const FLAT: &str =
        r#"{"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000}"#;
    const EXT: &str = r#"{"slip_hardening":{"h":0.01,"s_h":1}}"#;

    fn fit_json() -> String {
        format!(
            r#"{{"set":"x","params":{FLAT},"model":{{"params":{FLAT},"ext":{EXT}}},"report":{{}}}}"#
        )
    }

    fn model_object() -> String {
        format!(r#"{{"params":{FLAT},"ext":{EXT}}}"#)
    }

    fn shape(text: &str) -> String {
        match model_from_json(text) {
            Err(ModelJsonError::Shape(m)) => m,
            other => panic!("expected a shape error for {text}, got {other:?}"),
        }
    }

    #[test]
    fn every_shape_gives_the_same_model() {
        let flat = model_from_json(FLAT).unwrap();
        assert_eq!(flat.params, Params::sample());
        assert_eq!(flat.ext, Extensions::default());
        let exp = format!(
            r#"{{"name":"x","reference_parameters":{}}}"#,
            FLAT.replace('}', r#","source":"Table 3"}"#)
        );
        assert_eq!(model_from_json(&exp).unwrap(), flat);
        let fit = model_from_json(&fit_json()).unwrap();
        let object = model_from_json(&model_object()).unwrap();
        assert_eq!(fit, object);
        assert_eq!(fit.params, Params::sample());
        let h = fit.ext.terms.iter().next().expect("slip hardening read");
        assert_eq!(
            (h.family().name(), h.p[0], h.p[1]),
            ("slip-hardening", 0.01, 1.0)
        );
        // A model object without extensions, or with `ext: null`, is the base model.
        let bare = format!(r#"{{"params":{FLAT},"ext":null}}"#);
        assert_eq!(model_from_json(&bare).unwrap(), flat);
    }

    #[test]
    fn a_missing_or_mistyped_parameter_is_named_by_its_path() {
        assert!(shape(r#"{"mu_s":0.4}"#).contains("field `mu_k` is missing"));
        let m = shape(&FLAT.replace("1.2", "\"1.2\""));
        assert!(
            m.contains("field `kappa` is \"1.2\" (expected a number)"),
            "{m}"
        );
        let m = shape(&fit_json().replace(r#""kappa":1.2,"#, ""));
        assert!(m.contains("field `model.params.kappa` is missing"), "{m}");
        let m = shape(&model_object().replace(r#""xi":0.003,"#, ""));
        assert!(m.contains("field `params.xi` is missing"), "{m}");
        let m = shape(r#"{"model":{"ext":{}}}"#);
        assert!(m.contains("at `model.params`"), "{m}");
        let m = shape("[1, 2]");
        assert!(
            m.starts_with("expected a JSON object of parameters ("),
            "{m}"
        );
    }

    #[test]
    fn a_healing_that_states_its_defaults_reads_as_one_that_leaves_them_out() {
        // `recovery` and `d_h` were left out when written at their defaults, and the check of
        // unknown keys (every key read is written back) then refused a file that stated them.
        let with = |healing: &str| format!(r#"{{"params":{FLAT},"ext":{{"healing":{healing}}}}}"#);
        let bare = model_from_json(&with(r#"{"b":0.005,"t_c":1}"#)).expect("reads");
        let stated = model_from_json(&with(
            r#"{"b":0.005,"t_c":1,"form":"log","recovery":false,"d_h":0}"#,
        ))
        .expect("the defaults stated are read");
        assert_eq!(bare, stated);
        // What is written is read back.
        let text = format!(
            r#"{{"params":{FLAT},"ext":{}}}"#,
            serde_json::to_string(&stated.ext).unwrap()
        );
        assert_eq!(model_from_json(&text).expect("written, read back"), stated);
        // A field healing does not have is still refused.
        let m = shape(&with(r#"{"b":0.005,"d_hh":0.1}"#));
        assert!(m.contains("`ext.healing.d_hh` is not a known"), "{m}");
    }

    #[test]
    fn a_rate_effect_as_older_files_wrote_it_reads_as_the_same_law() {
        // Older files wrote every field of the rate effect whatever the form.
        let with = |rate: &str| format!(r#"{{"params":{FLAT},"ext":{{"rate":{rate}}}}}"#);
        let old = model_from_json(&with(
            r#"{"form":"state-slip","a":0.01,"v_c":1e-6,"b":0.012,"d_c":0.05,"n":0.0,"v_ref":0.01,"at_rest":"locked"}"#,
        ))
        .expect("reads");
        let law = old.ext.rate().expect("a rate law");
        assert_eq!(law.form, crate::RateForm::StateSlip);
        assert!(law.locked());
        assert_eq!(
            (law.a, law.b, law.d_c, law.v_c, law.v_ref),
            (0.01, 0.012, 0.05, 1e-6, 0.01)
        );
        // A direct effect as they wrote it, with the b and D_c it does not use.
        let direct = model_from_json(&with(
            r#"{"form":"log-direct","a":0.01,"v_c":1e-6,"b":0.3,"d_c":0.01,"n":0.0,"v_ref":0.0,"at_rest":"creep"}"#,
        ))
        .expect("reads");
        let law = direct.ext.rate().expect("a rate law");
        assert_eq!(
            (law.form, law.a, law.v_c),
            (crate::RateForm::LogDirect, 0.01, 1e-6)
        );
        // What is written is read back.
        let text = format!(
            r#"{{"params":{FLAT},"ext":{}}}"#,
            serde_json::to_string(&old.ext).unwrap()
        );
        assert_eq!(model_from_json(&text).expect("written, read back"), old);
        // A field the family does not have, or an invalid value, is refused by name.
        let m = shape(&with(r#"{"form":"power","n":0.1,"d_cc":1}"#));
        assert!(m.contains("`ext.rate.d_cc` is not a known"), "{m}");
        let e = model_from_json(&with(r#"{"form":"state-ageing","a":0.01,"v_c":-1}"#))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rate.v_c"), "{e}");
    }

    #[test]
    fn a_direction_effect_as_older_files_wrote_it_reads_and_an_unused_size_is_refused() {
        // Older files wrote every field of the direction effect, `d_k` at 0 whatever the target.
        let with = |dir: &str| format!(r#"{{"params":{FLAT},"ext":{{"direction":{dir}}}}}"#);
        let old = model_from_json(&with(r#"{"d":0.1,"target":"mu-k","d_k":0.0}"#)).expect("reads");
        let bare = model_from_json(&with(r#"{"d":0.1,"target":"mu-k"}"#)).expect("reads");
        assert_eq!(old, bare);
        let e = old
            .ext
            .terms
            .iter()
            .next()
            .expect("the direction effect is on");
        assert_eq!(
            (e.family().name(), e.form().key, e.p[0]),
            ("direction", "mu-k", 0.1)
        );
        // Written with its target, read back the same.
        let text = serde_json::to_string(&old.ext).unwrap();
        assert!(
            text.contains(r#""direction":{"target":"mu-k","d":0.1}"#),
            "{text}"
        );
        // A size the target does not use, away from its default, is no silent no-op.
        let m = shape(&with(r#"{"d":0.1,"target":"mu-k","d_k":0.2}"#));
        assert!(m.contains("`ext.direction.d_k` is not a known"), "{m}");
        // The general form uses it.
        let both = model_from_json(&with(r#"{"d":0.1,"target":"bounds","d_k":0.2}"#)).unwrap();
        assert_eq!(both.ext.terms.iter().next().unwrap().p[1], 0.2);
        // Out of its range: refused by name.
        match model_from_json(&with(r#"{"d":1.5}"#)) {
            Err(ModelJsonError::Invalid(e)) => {
                assert!(e.to_string().contains("direction.d"), "{e}")
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_pressure_effect_as_older_files_wrote_it_reads_back_the_same() {
        let with = |p: &str| format!(r#"{{"params":{FLAT},"ext":{{"pressure":{p}}}}}"#);
        // Every field, as the pressure effect was always written.
        let old = r#"{"beta":0.1,"form":"linear","target":"mu-s","p_ref":196.0,"beta_k":0.0}"#;
        let m = model_from_json(&with(old)).expect("reads");
        let e = m
            .ext
            .terms
            .iter()
            .next()
            .expect("the pressure effect is on");
        assert_eq!(e.form().describe, "linear on mu_s only");
        assert_eq!((e.p[0], e.p[2]), (0.1, 196.0));
        let text = serde_json::to_string(&m.ext).unwrap();
        assert!(
            text.contains(
                r#""pressure":{"form":"linear","target":"mu-s","beta":0.1,"p_ref":196.0}"#
            ),
            "{text}"
        );
        let back = format!(r#"{{"params":{FLAT},"ext":{text}}}"#);
        assert_eq!(model_from_json(&back).unwrap(), m);
        // Left out: a power law on μ as a whole at 100 kPa.
        let bare = model_from_json(&with(r#"{"beta":0.1}"#)).unwrap();
        let e = bare.ext.terms.iter().next().unwrap();
        assert_eq!((e.form().key, e.p[2]), ("power-friction", 100.0));
        // A target pressure cannot scale is refused by name.
        let m = shape(&with(r#"{"beta":0.1,"target":"kappa"}"#));
        assert!(m.contains("`pressure.target` is \"kappa\""), "{m}");
    }

    #[test]
    fn an_unknown_extension_or_field_is_refused_in_both_model_shapes() {
        for (text, path) in [(fit_json(), "model.ext"), (model_object(), "ext")] {
            let m = shape(&text.replace("slip_hardening", "slip_softening"));
            assert!(
                m.contains(&format!("`{path}.slip_softening` is not a known extension")),
                "{m}"
            );
            let m = shape(&text.replace(r#""s_h":1"#, r#""s_h":1,"sh":2"#));
            assert!(
                m.contains(&format!("`{path}.slip_hardening.sh` is not")),
                "{m}"
            );
            let m = shape(&text.replace(r#""h":0.01"#, r#""h":"x""#));
            assert!(m.contains(&format!("field `{path}`")), "{m}");
        }
    }

    #[test]
    fn a_key_given_twice_is_refused_with_its_path_and_line() {
        let twice = "{\"mu_s\": 0.45, \"mu_k\": 0.3, \"kappa\": 1.2, \"xi\": 0.003,\n \"u_tilde\": 15, \"alpha_t\": 1000, \"mu_s\": 0.5}";
        match model_from_json(twice) {
            Err(ModelJsonError::Duplicate { key, line, .. }) => {
                assert_eq!((key.as_str(), line), ("mu_s", 2));
            }
            other => panic!("{other:?}"),
        }
        let nested = fit_json().replace(r#""s_h":1"#, r#""s_h":1,"s_h":2"#);
        match model_from_json(&nested) {
            Err(e @ ModelJsonError::Duplicate { .. }) => {
                assert!(
                    e.to_string()
                        .contains("`model.ext.slip_hardening.s_h` appears twice"),
                    "{e}"
                )
            }
            other => panic!("{other:?}"),
        }
        // The same key in two objects is no duplicate.
        assert!(model_from_json(&fit_json()).is_ok());
    }

    #[test]
    fn invalid_values_and_bad_json_are_told_apart() {
        match model_from_json(&FLAT.replace("0.3", "0.9")) {
            Err(ModelJsonError::Invalid(e)) => assert!(e.to_string().contains("mu_k = 0.9")),
            other => panic!("{other:?}"),
        }
        let bad_ext = fit_json().replace(r#""s_h":1"#, r#""s_h":-1"#);
        match model_from_json(&bad_ext) {
            Err(ModelJsonError::Invalid(e)) => {
                assert!(e.to_string().contains("slip_hardening.s_h"), "{e}")
            }
            other => panic!("{other:?}"),
        }
        match model_from_json("{\"mu_s\": 0.3,\n  \"mu_k\": }") {
            Err(e @ ModelJsonError::Syntax { line: 2, .. }) => {
                assert!(e.to_string().contains("line 2 column 11"), "{e}")
            }
            other => panic!("{other:?}"),
        }
    }
}
