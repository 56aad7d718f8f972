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
            Param::all()
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

/// Smallest and largest test weight accepted. Weights are relative (the fit scales them to a
/// mean of 1 over the rows); beyond a factor 10⁶ one test's rows vanish under the rounding of
/// the others' and the optimiser stops where it starts: leave a test out with `--tests`.
pub const WEIGHT_RANGE: (f64, f64) = (1e-6, 1e6);

/// `name=w` of `--weight`: a weight from 10⁻⁶ to 10⁶ ([`WEIGHT_RANGE`]).
pub fn parse_weight(s: &str) -> Result<(String, f64), String> {
    let (k, v) = key_value(s, "test=weight")?;
    let w = number(v, k)?;
    let (lo, hi) = WEIGHT_RANGE;
    if w <= 0.0 {
        Err(format!(
            "{k}: weight {w} is not positive (expected a weight > 0)"
        ))
    } else if !(lo..=hi).contains(&w) {
        Err(format!(
            "{k}: weight {w:e} is outside {lo:e} to {hi:e} (expected a relative weight in that range: beyond it one test's rows vanish under the rounding of the others' and the fit stops where it starts; to leave a test out, name the others with --tests)"
        ))
    } else {
        Ok((k.to_string(), w))
    }
}

/// A count of at least 1 (`--starts`, `selfcheck --per-class`): 0 would run nothing, or one
/// start without saying so.
pub fn parse_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(0) => Err("0 (expected a whole number >= 1)".into()),
        Ok(n) => Ok(n),
        Err(_) => Err(format!(
            "`{s}` is not a whole number (expected a whole number >= 1)"
        )),
    }
}

/// Hours of lab time (`--setup-hours`): a finite number >= 0.
pub fn parse_hours(s: &str) -> Result<f64, String> {
    let h = number(s.trim(), "hours")?;
    if h >= 0.0 {
        Ok(h)
    } else {
        Err(format!(
            "{h} hours is negative (expected a number of hours >= 0)"
        ))
    }
}

/// Options of a fit that contradict each other, named as the flags that gave them: two values
/// of `--fix` for one parameter, two ranges of `--bounds`, two weights of `--weight` for one
/// test, a parameter both in `--free` (when given; `None`: the default list, which `--fix`
/// narrows) and in `--fix`. The same value given twice is no conflict.
pub fn conflicts(
    free: Option<&[Param]>,
    fix: &[(Param, f64)],
    bounds: &[(Param, f64, f64)],
    weights: &[(String, f64)],
) -> Result<(), String> {
    for (i, (p, v)) in fix.iter().enumerate() {
        if let Some((_, w)) = fix[..i].iter().find(|(q, w)| q == p && w != v) {
            let k = p.key();
            return Err(format!(
                "--fix {k}={w} and --fix {k}={v}: two values for {k} (expected one value per parameter)"
            ));
        }
        if free.is_some_and(|f| f.contains(p)) {
            let k = p.key();
            return Err(format!(
                "--free {k} and --fix {k}={v}: {k} cannot be both free and fixed (expected each parameter in one of the two)"
            ));
        }
    }
    for (i, (p, lo, hi)) in bounds.iter().enumerate() {
        if let Some((_, a, b)) = bounds[..i]
            .iter()
            .find(|(q, a, b)| q == p && (a, b) != (lo, hi))
        {
            let k = p.key();
            return Err(format!(
                "--bounds {k}={a}:{b} and --bounds {k}={lo}:{hi}: two ranges for {k} (expected one range per parameter)"
            ));
        }
    }
    for (i, (t, w)) in weights.iter().enumerate() {
        if let Some((_, v)) = weights[..i].iter().find(|(u, v)| u == t && v != w) {
            return Err(format!(
                "--weight {t}={v} and --weight {t}={w}: two weights for test `{t}` (expected one weight per test)"
            ));
        }
    }
    Ok(())
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
        for w in ["a=1e-30", "a=1e-7", "a=2e6"] {
            let e = parse_weight(w).unwrap_err();
            assert!(e.contains("outside") && e.contains("--tests"), "{e}");
        }
        assert!(parse_weight("a=1e-6").is_ok() && parse_weight("a=1e6").is_ok());
        assert!(parse_hours("NaN").unwrap_err().contains("finite"));
        assert!(parse_hours("-1").unwrap_err().contains(">= 0"));
        assert_eq!(parse_hours("0.25"), Ok(0.25));
    }

    #[test]
    fn contradicting_options_are_named_both() {
        let fix = |s: &str| parse_fix(s).unwrap();
        let e = conflicts(None, &[fix("xi=0.1"), fix("xi=0.2")], &[], &[]).unwrap_err();
        assert!(e.contains("--fix xi=0.1 and --fix xi=0.2"), "{e}");
        assert!(conflicts(None, &[fix("xi=0.1"), fix("xi=0.1")], &[], &[]).is_ok());
        let free = [Param::MuS, Param::Xi];
        let e = conflicts(Some(&free), &[fix("mu_s=0.4")], &[], &[]).unwrap_err();
        assert!(e.contains("--free mu_s and --fix mu_s=0.4"), "{e}");
        // The default free list is narrowed by --fix, not contradicted.
        assert!(conflicts(None, &[fix("mu_s=0.4")], &[], &[]).is_ok());
        let b = |s: &str| parse_bound(s).unwrap();
        let e = conflicts(None, &[], &[b("kappa=1:10"), b("kappa=20:30")], &[]).unwrap_err();
        assert!(
            e.contains("--bounds kappa=1:10 and --bounds kappa=20:30"),
            "{e}"
        );
        let w = |s: &str| parse_weight(s).unwrap();
        let e = conflicts(None, &[], &[], &[w("t=2"), w("u=1"), w("t=3")]).unwrap_err();
        assert!(e.contains("--weight t=2 and --weight t=3"), "{e}");
    }
}
