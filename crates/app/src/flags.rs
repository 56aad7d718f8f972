//! Values of the fit's options as text, parsed and checked the same way for every front end:
//! the command line's `--free`, `--fix`, `--bounds` and `--weight` (clap calls these as value
//! parsers, so a malformed value is a usage error naming the flag) and the Python package's
//! `free`, `fix`, `bounds` and `weights`. Errors say what was given and what was expected.

use subfric_fit::Param;

/// A parameter key.
pub fn parse_param(s: &str) -> Result<Param, String> {
    Param::from_key(s.trim()).ok_or_else(|| {
        format!(
            "unknown parameter `{}` (expected one of {})",
            s.trim(),
            Param::ALL
                .iter()
                .map(|p| p.key())
                .collect::<Vec<_>>()
                .join(", ")
        )
    })
}

fn key_value<'a>(s: &'a str, form: &str) -> Result<(&'a str, &'a str), String> {
    s.split_once('=')
        .map(|(k, v)| (k.trim(), v.trim()))
        .ok_or_else(|| format!("`{s}` is not of the form {form} (expected key=value)"))
}

fn number(s: &str, what: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("{what}: `{s}` is not a number (expected a decimal number)"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "{what}: `{s}` is not a finite number (expected a finite number)"
        ))
    }
}

/// `key=value` of `--fix`.
pub fn parse_fix(s: &str) -> Result<(Param, f64), String> {
    let (k, v) = key_value(s, "key=value")?;
    let p = parse_param(k)?;
    Ok((p, number(v, k)?))
}

/// `key=lo:hi` of `--bounds`, checked against the parameter's domain.
pub fn parse_bound(s: &str) -> Result<(Param, f64, f64), String> {
    let (k, v) = key_value(s, "key=lo:hi")?;
    let p = parse_param(k)?;
    let (a, b) = v
        .split_once(':')
        .ok_or_else(|| format!("{k}: `{v}` is not of the form lo:hi (expected key=lo:hi)"))?;
    let (lo, hi) = (
        number(a.trim(), &format!("{k} lower bound"))?,
        number(b.trim(), &format!("{k} upper bound"))?,
    );
    match p.bounds_problem(lo, hi) {
        Some(msg) => Err(format!("{k}: {msg}")),
        None => Ok((p, lo, hi)),
    }
}

/// `name=w` of `--weight`.
pub fn parse_weight(s: &str) -> Result<(String, f64), String> {
    let (k, v) = key_value(s, "test=weight")?;
    let w = number(v, k)?;
    if w > 0.0 {
        Ok((k.to_string(), w))
    } else {
        Err(format!(
            "{k}: weight {w} is not positive (expected a weight > 0)"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn option_values_are_parsed_or_refused_with_the_reason() {
        assert_eq!(parse_fix("kappa=2").unwrap(), (Param::Kappa, 2.0));
        assert!(parse_fix("kappa").unwrap_err().contains("key=value"));
        assert!(parse_fix("kappa=abc").unwrap_err().contains("not a number"));
        assert!(parse_fix("kapa=1")
            .unwrap_err()
            .contains("unknown parameter"));
        assert_eq!(parse_bound("xi=1e-3:1").unwrap(), (Param::Xi, 1e-3, 1.0));
        let e = parse_bound("kappa=-5:-1").unwrap_err();
        assert!(e.contains("kappa") && e.contains("> 0"), "{e}");
        assert!(parse_bound("mu_s=0.5:0.1").unwrap_err().contains("below"));
        assert!(parse_bound("mu_s=0.1").unwrap_err().contains("lo:hi"));
        assert!(parse_bound("mu_k=-0.1:0.2").unwrap_err().contains(">= 0"));
        assert_eq!(parse_weight("a=2").unwrap(), ("a".to_string(), 2.0));
        assert!(parse_weight("a=0").unwrap_err().contains("> 0"));
        assert!(parse_weight("a=inf").unwrap_err().contains("finite"));
    }
}
