//! The prior file: what it accepts, and every kind of mistake reported with the file, the line
//! and the field, never a panic.

use std::path::Path;
use subfric_fit::Param;
use subfric_posterior::prior::{Prior, PriorError, Priors};
use subfric_posterior::prior_file::parse;

fn problems(text: &str, file: &str) -> Vec<String> {
    match parse(text, Path::new(file)) {
        Ok(p) => panic!("accepted: {p:?}"),
        Err(PriorError::Invalid(ps)) => ps.iter().map(|p| p.to_string()).collect(),
        Err(e) => panic!("unexpected error {e}"),
    }
}

fn one_problem(text: &str, file: &str) -> String {
    let ps = problems(text, file);
    assert_eq!(ps.len(), 1, "{ps:#?}");
    ps.into_iter().next().unwrap()
}

const GOOD_TOML: &str = r#"# priors of a sand-steel fit
[kappa]
dist = "log-uniform"
lo = 0.1
hi = 100.0

[xi]
dist = "log-normal"
median = 0.002
sigma = 1.0

[rate.a]
dist = "normal"
mean = 0.0
sd = 0.01

["rate.v_c"]
dist = "uniform"
lo = 1e-6
hi = 1_000
"#;

#[test]
fn a_toml_file_with_every_distribution_is_read() {
    let p = parse(GOOD_TOML, Path::new("priors.toml")).unwrap();
    assert_eq!(p.entries().len(), 4);
    let k = p.get(Param::Kappa).unwrap();
    assert_eq!(k.prior, Prior::LogUniform { lo: 0.1, hi: 100.0 });
    assert_eq!(k.origin.as_ref().unwrap().line, 2);
    match p.get(Param::Xi).unwrap().prior {
        Prior::LogNormal { mu, sigma } => {
            assert!((mu - 0.002f64.ln()).abs() < 1e-12);
            assert_eq!(sigma, 1.0);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(
        p.get(Param::from_key("rate.a").unwrap()).unwrap().prior,
        Prior::Normal {
            mean: 0.0,
            sd: 0.01
        }
    );
    assert_eq!(
        p.get(Param::from_key("rate.a").unwrap())
            .unwrap()
            .origin
            .as_ref()
            .unwrap()
            .line,
        12
    );
    assert_eq!(
        p.get(Param::from_key("rate.v_c").unwrap()).unwrap().prior,
        Prior::Uniform {
            lo: 1e-6,
            hi: 1000.0
        }
    );
}

#[test]
fn a_json_file_is_read_with_the_lines_of_its_entries() {
    let text = r#"{
  "mu_s": {"dist": "uniform", "lo": 0.2, "hi": 1.5},
  "u_tilde": {"dist": "log_normal", "mu": 2.5, "sigma": 0.7},
  "healing.b": {"dist": "normal", "mean": 0.01, "sd": 0.005}
}"#;
    let p = parse(text, Path::new("p.json")).unwrap();
    assert_eq!(p.entries().len(), 3);
    assert_eq!(p.get(Param::MuS).unwrap().origin.as_ref().unwrap().line, 2);
    assert_eq!(
        p.get(Param::UTilde).unwrap().prior,
        Prior::LogNormal {
            mu: 2.5,
            sigma: 0.7
        }
    );
    assert_eq!(
        p.get(Param::from_key("healing.b").unwrap())
            .unwrap()
            .origin
            .as_ref()
            .unwrap()
            .line,
        4
    );
    // An empty TOML file gives no priors: every parameter keeps the default.
    assert!(parse("", Path::new("p.toml")).unwrap().entries().is_empty());
}

#[test]
fn an_unknown_parameter_lists_the_valid_keys() {
    let e = one_problem("[kapa]\ndist = \"uniform\"\nlo = 1\nhi = 2\n", "p.toml");
    assert!(
        e.starts_with("p.toml:1: field `kapa`: unknown parameter `kapa`"),
        "{e}"
    );
    assert!(
        e.contains("mu_s, mu_k, kappa, xi, u_tilde") && e.contains("direction.d_k"),
        "{e}"
    );
    let e = one_problem("[rate.q]\ndist = \"uniform\"\nlo = 1\nhi = 2\n", "p.toml");
    assert!(e.contains("unknown parameter `rate.q`"), "{e}");
}

#[test]
fn lo_not_below_hi_is_located() {
    let text = "{\n  \"kappa\": {\"dist\": \"uniform\",\n    \"lo\": 5, \"hi\": 5}\n}";
    let e = one_problem(text, "p.json");
    assert!(e.starts_with("p.json:2: field `kappa`:"), "{e}");
    assert!(
        e.contains("lo = 5 is not below hi = 5 (expected lo < hi)"),
        "{e}"
    );
}

#[test]
fn a_negative_sd_or_sigma_is_located() {
    let e = one_problem(
        "[mu_s]\ndist = \"normal\"\nmean = 0.6\nsd = -0.1\n",
        "p.toml",
    );
    assert!(e.starts_with("p.toml:1: field `mu_s`:"), "{e}");
    assert!(
        e.contains("sd = -0.1 is not positive (expected sd > 0)"),
        "{e}"
    );
    let e = one_problem(
        "[xi]\ndist = \"log-normal\"\nmedian = 0.1\nsigma = 0\n",
        "p.toml",
    );
    assert!(e.contains("sigma = 0 is not positive"), "{e}");
    let e = one_problem(
        "[xi]\ndist = \"log-normal\"\nmedian = -3\nsigma = 1\n",
        "p.toml",
    );
    assert!(
        e.contains("field `xi.median`") && e.contains("expected median > 0"),
        "{e}"
    );
}

#[test]
fn a_log_prior_on_a_parameter_that_can_be_negative_is_refused() {
    let e = one_problem(
        "[pressure.beta]\ndist = \"log-uniform\"\nlo = 0.01\nhi = 0.5\n",
        "p.toml",
    );
    assert!(e.starts_with("p.toml:1: field `pressure.beta`:"), "{e}");
    assert!(e.contains("can be zero or negative"), "{e}");
    assert!(e.contains("expected a uniform or normal prior"), "{e}");
    // A log prior on a positive parameter is fine, and on μ_k (kept above 0 by its chart) too.
    parse(
        "[mu_k]\ndist = \"log-uniform\"\nlo = 0.1\nhi = 0.5\n",
        Path::new("p.toml"),
    )
    .unwrap();
    let e = one_problem(
        "[kappa]\ndist = \"log-uniform\"\nlo = 0\nhi = 5\n",
        "p.toml",
    );
    assert!(e.contains("lo = 0 is not positive"), "{e}");
}

#[test]
fn a_duplicate_key_is_refused_with_both_lines() {
    let text = "{\n \"xi\": {\"dist\": \"normal\", \"mean\": 0.001, \"sd\": 0.001},\n \"kappa\": {\"dist\": \"normal\", \"mean\": 1, \"sd\": 1},\n \"xi\": {\"dist\": \"normal\", \"mean\": 0.002, \"sd\": 0.001}\n}";
    let e = one_problem(text, "p.json");
    assert!(
        e.starts_with("p.json:4: field `xi`: a second prior for xi (the first is on line 2"),
        "{e}"
    );
    // TOML refuses duplicate tables itself; the line is that of the second.
    let text =
        "[xi]\ndist = \"normal\"\nmean = 1\nsd = 1\n\n[xi]\ndist = \"normal\"\nmean = 1\nsd = 1\n";
    let e = one_problem(text, "p.toml");
    assert!(e.starts_with("p.toml:6:"), "{e}");
    // The same parameter once quoted and once nested is still the same parameter.
    let text = "[\"rate.a\"]\ndist = \"normal\"\nmean = 0\nsd = 1\n\n[rate.a]\ndist = \"normal\"\nmean = 0\nsd = 1\n";
    let e = one_problem(text, "p.toml");
    assert!(e.contains("a second prior for rate.a"), "{e}");
}

#[test]
fn non_finite_numbers_are_refused() {
    let e = one_problem(
        "[kappa]\ndist = \"uniform\"\nlo = 0.1\nhi = inf\n",
        "p.toml",
    );
    assert!(
        e.starts_with("p.toml:4: field `kappa.hi`: inf is not finite"),
        "{e}"
    );
    let e = one_problem("[kappa]\ndist = \"normal\"\nmean = nan\nsd = 1\n", "p.toml");
    assert!(e.contains("field `kappa.mean`: NaN is not finite"), "{e}");
    let e = one_problem(
        "{\"kappa\": {\"dist\": \"uniform\", \"lo\": 0, \"hi\": 1e999}}",
        "p.json",
    );
    assert!(
        e.starts_with("p.json:1:") && e.contains("out of range"),
        "{e}"
    );
}

#[test]
fn missing_unknown_and_mistyped_fields_are_each_reported() {
    let text = "[kappa]\ndist = \"uniform\"\nlo = 0.1\n\n[xi]\ndist = \"normal\"\nmean = \"0.002\"\nsd = 0.001\nsigma = 2\n\n[mu_s]\ndist = \"gamma\"\n\n[u_tilde]\nlo = 1\n";
    let ps = problems(text, "p.toml");
    let all = ps.join("\n");
    assert!(
        all.contains("p.toml:1: field `kappa.hi`: missing (a uniform prior needs lo and hi)"),
        "{all}"
    );
    let e = one_problem("[xi]\ndist = \"log-normal\"\nmedian = 0.002\n", "p.toml");
    assert!(
        e.contains("field `xi.sigma`: missing (a log-normal prior needs median or mu, and sigma)"),
        "{e}"
    );
    assert!(
        all.contains("p.toml:7: field `xi.mean`: \"0.002\" is text (expected a number)"),
        "{all}"
    );
    assert!(
        all.contains("p.toml:9: field `xi.sigma`: not a field of a normal prior"),
        "{all}"
    );
    assert!(
        all.contains("p.toml:12: field `mu_s.dist`: unknown distribution \"gamma\""),
        "{all}"
    );
    assert!(
        all.contains("p.toml:14: field `u_tilde.dist`: missing"),
        "{all}"
    );
    assert_eq!(ps.len(), 5, "{all}");
    let e = one_problem(
        "[xi]\ndist = \"log-normal\"\nmedian = 0.1\nmu = -2\nsigma = 1\n",
        "p.toml",
    );
    assert!(e.contains("both median and mu given"), "{e}");
    let e = one_problem("{\"kappa\": 3}", "p.json");
    assert!(e.contains("a number where a prior belongs"), "{e}");
    let e = one_problem("[1, 2]", "p.json");
    assert!(
        e.starts_with("p.json:1:") && e.contains("expected a table of priors"),
        "{e}"
    );
}

#[test]
fn syntax_errors_name_their_line() {
    let e = one_problem(
        "{\n \"kappa\": {\"dist\": \"uniform\" \"lo\": 1}\n}",
        "p.json",
    );
    assert!(e.starts_with("p.json:2:"), "{e}");
    let e = one_problem("[kappa]\ndist = \"uniform\"\nlo = = 1\n", "p.toml");
    assert!(e.starts_with("p.toml:3:"), "{e}");
    let e = one_problem("{}", "priors.yaml");
    assert!(
        e.contains("expected a file ending in .json or .toml"),
        "{e}"
    );
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let e = Priors::load(Path::new("/nonexistent/priors.toml")).unwrap_err();
    assert!(matches!(e, PriorError::Io { .. }));
    assert!(e.to_string().contains("/nonexistent/priors.toml"), "{e}");
}

#[test]
fn no_truncation_or_corruption_of_a_file_panics() {
    let json = r#"{"kappa": {"dist": "log-uniform", "lo": 0.1, "hi": 100}, "rate.a": {"dist": "normal", "mean": 0, "sd": 0.01}}"#;
    for (text, file) in [(GOOD_TOML, "p.toml"), (json, "p.json")] {
        let cuts: Vec<usize> = (0..=text.len())
            .filter(|i| text.is_char_boundary(*i))
            .collect();
        for &i in &cuts {
            let _ = parse(&text[..i], Path::new(file));
        }
        for (i, _) in text.char_indices() {
            for c in ['"', '{', '[', '=', ':', ',', '\n', '-', 'e', '}'] {
                let mut t = text.to_string();
                t.replace_range(
                    i..i + text[i..].chars().next().unwrap().len_utf8(),
                    &c.to_string(),
                );
                let _ = parse(&t, Path::new(file));
            }
        }
    }
}
