//! The README's first command end to end: `subfric reproduce` writes the tables, the fits and
//! decodable PNG overlays whose fitted curves lie inside the axes; bad input is an error that
//! names what is wrong, never a panic.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_subfric"))
}

fn experiments() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments")
}

fn copy_set(name: &str, to: &Path) {
    let from = experiments().join(name);
    let dest = to.join(name);
    std::fs::create_dir_all(&dest).unwrap();
    for e in std::fs::read_dir(&from).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dest.join(p.file_name().unwrap())).unwrap();
    }
}

#[test]
fn reproduce_writes_tables_fits_and_valid_plots() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = tmp.path().join("experiments");
    for s in ["table1-medium", "table4-two-way"] {
        copy_set(s, &exp);
    }
    let out = tmp.path().join("fits");
    let o = bin()
        .args(["reproduce", "--experiments"])
        .arg(&exp)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "README.md",
        "table1.md",
        "table1.csv",
        "table4.md",
        "table4.csv",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // Every published value lies inside the reported interval (fixed rows have none).
    let csv = std::fs::read_to_string(out.join("table1.csv")).unwrap();
    for line in csv.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        if c[6].is_empty() || c[11].is_empty() {
            continue;
        }
        let (lo, hi, published): (f64, f64, f64) = (
            c[6].parse().unwrap(),
            c[7].parse().unwrap(),
            c[11].parse().unwrap(),
        );
        assert!(lo <= published && published <= hi, "{line}");
    }
    let fit: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("table1-medium/fit.json")).unwrap())
            .unwrap();
    let mu_s = fit["params"]["mu_s"].as_f64().unwrap();
    assert!((mu_s - 0.37).abs() / 0.37 < 0.05, "mu_s {mu_s}");
    for (set, test) in [
        ("table1-medium", "monotonic"),
        ("table4-two-way", "two-way-cyclic"),
    ] {
        let png = out.join(set).join(format!("{test}.png"));
        let check = subfric_plot::inspect_png(&png).expect("a valid PNG");
        assert_eq!((check.width, check.height), (1000, 750));
        assert!(
            check.inked_fraction > 0.02 && check.inked_fraction < 0.6,
            "{check:?}"
        );
        // The fitted curve's colour is there, and only inside the plotting areas.
        let img = subfric_plot::read_rgb(&png).unwrap();
        let red = subfric_plot::FITTED_RGB;
        let mut inside = 0;
        let (mut left, mut right, mut top, mut bottom) = (u32::MAX, 0, u32::MAX, 0);
        for y in 0..img.height {
            for x in 0..img.width {
                if img.pixel(x, y) == Some(red) {
                    inside += 1;
                    left = left.min(x);
                    right = right.max(x);
                    top = top.min(y);
                    bottom = bottom.max(y);
                }
            }
        }
        assert!(
            inside > 500,
            "{set}: fitted curve not drawn ({inside} pixels)"
        );
        // Margins hold the axis labels: no curve pixel may sit there.
        assert!(
            left > 40 && right < img.width - 10 && top > 30 && bottom < img.height - 40,
            "{set}: curve outside the axes"
        );
    }
}

fn run_err(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(
        o.status.code(),
        Some(1),
        "expected an error for {args:?}: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    err
}

#[test]
fn bad_input_is_reported_by_file_line_and_field() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("nowhere");
    let err = run_err(&["check", missing.to_str().unwrap()]);
    assert!(err.contains("nowhere"), "{err}");

    copy_set("table1-medium", tmp.path());
    let set = tmp.path().join("table1-medium");
    let csv = set.join("monotonic.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    // A NaN in the fifth data row (line 7 counting the comment and the header).
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[6] = "0.300,0.00500,NaN".into();
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let err = run_err(&["fit", set.to_str().unwrap(), "--no-profiles"]);
    assert!(
        err.contains("monotonic.csv") && err.contains(":7") && err.contains("shear_kpa"),
        "{err}"
    );

    let params = tmp.path().join("params.json");
    std::fs::write(
        &params,
        r#"{"mu_s": 0.3, "mu_k": 0.5, "kappa": -1, "xi": 0.01, "u_tilde": 10, "alpha_t": 100}"#,
    )
    .unwrap();
    let out = tmp.path().join("sim");
    let err = run_err(&[
        "simulate",
        experiments().join("table1-medium").to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        err.contains("params.json") && err.contains("mu_k") && err.contains("kappa"),
        "{err}"
    );

    std::fs::write(&params, "{\"mu_s\": 0.3,\n \"mu_k\": }").unwrap();
    let err = run_err(&[
        "simulate",
        experiments().join("table1-medium").to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(err.contains("params.json:2:"), "{err}");

    let err = run_err(&[
        "fit",
        experiments().join("table1-medium").to_str().unwrap(),
        "--free",
        "nonsense",
    ]);
    assert!(err.contains("nonsense") && err.contains("mu_s"), "{err}");
}

#[test]
fn simulate_with_the_published_parameters_gives_back_the_curve() {
    let tmp = tempfile::tempdir().unwrap();
    let set = experiments().join("table1-medium");
    let out = tmp.path().join("sim");
    let o = bin()
        .arg("simulate")
        .arg(&set)
        .arg("--params")
        .arg(set.join("experiment.json"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = bin().arg("check").arg(&out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let read = |p: &Path| -> Vec<f64> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .skip(1)
            .map(|l| l.split(',').nth(2).unwrap().parse().unwrap())
            .collect()
    };
    let (a, b) = (
        read(&set.join("monotonic.csv")),
        read(&out.join("monotonic.csv")),
    );
    assert_eq!(a.len(), b.len());
    let peak = a.iter().fold(0.0f64, |m, v| m.max(*v));
    let rms = (a.iter().zip(&b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
    assert!(rms / peak < 0.005, "relative RMS {}", rms / peak);
}
