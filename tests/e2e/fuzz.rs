//! Random corruptions of valid sets — spikes, zeros, huge values, units off by 10³, jitter,
//! one- or few-row tests, repeated times — fed to `fit` (short budgets) and `diagnose`. The
//! program must never panic, and must either refuse with an error that names the set's file
//! (and its line for a bad row) or give a result whose numbers are all finite.
//!
//! The corruptions are drawn from a fixed seed, so a failure is reproducible; every kind is
//! drawn on every base set.

use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use subfric_e2e::{args, copy_set, read_data_csv, read_json, subfric, text};

#[derive(Clone, Copy, Debug)]
enum Corruption {
    /// A few rows of the measured or imposed column multiplied by up to ±10⁴.
    Spikes,
    /// A block of rows of one column set to 0.
    ZeroBlock,
    /// The shear is 0 on every row.
    AllZeroShear,
    /// One cell set to ±1e300 (refused), or ±1e9 or ±1e11 (accepted).
    Huge,
    /// One column in units 10³ off (both ways).
    UnitsOff,
    /// Noise of 1 µm to 0.1 mm on the slip.
    Jitter,
    /// Only the first 1–3 rows kept.
    FewRows,
    /// A row's time repeated (not increasing).
    RepeatedTime,
}

const KINDS: [Corruption; 8] = [
    Corruption::Spikes,
    Corruption::ZeroBlock,
    Corruption::AllZeroShear,
    Corruption::Huge,
    Corruption::UnitsOff,
    Corruption::Jitter,
    Corruption::FewRows,
    Corruption::RepeatedTime,
];

fn corrupt(rows: &mut Vec<Vec<f64>>, kind: Corruption, rng: &mut ChaCha8Rng) {
    let n = rows.len();
    match kind {
        Corruption::Spikes => {
            for _ in 0..rng.gen_range(1..6) {
                let (i, c) = (rng.gen_range(0..n), rng.gen_range(1..3));
                let f = rng.gen_range(-4.0f64..4.0);
                rows[i][c] *= 10f64.powf(f.abs()) * f.signum();
            }
        }
        Corruption::ZeroBlock => {
            let (a, c) = (rng.gen_range(0..n), rng.gen_range(1..3));
            for r in rows.iter_mut().skip(a).take(rng.gen_range(5..100)) {
                r[c] = 0.0;
            }
        }
        Corruption::AllZeroShear => rows.iter_mut().for_each(|r| r[2] = 0.0),
        Corruption::Huge => {
            let (i, c) = (rng.gen_range(0..n), rng.gen_range(0..3));
            let v = [1e300, 1e11, 1e9][rng.gen_range(0..3)];
            rows[i][c] = if rng.gen() { v } else { -v };
        }
        Corruption::UnitsOff => {
            let c = rng.gen_range(0..3);
            let f = if rng.gen() { 1e3 } else { 1e-3 };
            rows.iter_mut().for_each(|r| r[c] *= f);
        }
        Corruption::Jitter => {
            let a = 10f64.powf(rng.gen_range(-3.0..-1.0));
            rows.iter_mut()
                .for_each(|r| r[1] += a * rng.gen_range(-1.0..1.0));
        }
        Corruption::FewRows => rows.truncate(rng.gen_range(1..4)),
        Corruption::RepeatedTime => {
            let i = rng.gen_range(1..n);
            rows[i][0] = rows[i - 1][0];
        }
    }
}

/// Writes a corrupted copy of the bundled set `base` under `root`; returns its folder and CSV.
fn corrupted_set(
    base: &str,
    root: &Path,
    kind: Corruption,
    rng: &mut ChaCha8Rng,
) -> std::path::PathBuf {
    let set = copy_set(base, root);
    let meta = read_json(&set.join("experiment.json"));
    let file = set.join(meta["tests"][0]["file"].as_str().unwrap());
    let (header, mut rows) = read_data_csv(&file);
    corrupt(&mut rows, kind, rng);
    let mut csv = header.join(",") + "\n";
    for r in &rows {
        let cells: Vec<String> = r.iter().map(|v| format!("{v}")).collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    std::fs::write(&file, csv).unwrap();
    set
}

fn finite(v: &Value) -> bool {
    v.as_f64().is_some_and(f64::is_finite)
}

/// Runs the program; asserts no panic and a located error or success. Returns whether it
/// succeeded.
fn no_panic_and_located(a: &[&std::ffi::OsStr], set: &Path, what: &str) -> bool {
    let o = subfric!().run(a);
    let err = text(&o.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{what}: panicked:\n{err}"
    );
    match o.status.code() {
        Some(0) => true,
        Some(1) => {
            // Warnings may come first; the error is the last message.
            let error = err
                .rfind("error:")
                .map(|i| &err[i..])
                .unwrap_or_else(|| panic!("{what}: no error message:\n{err}"));
            assert!(
                error.contains(&set.display().to_string()),
                "{what}: the error does not name the set's file:\n{err}"
            );
            false
        }
        other => panic!("{what}: exit {other:?}:\n{err}"),
    }
}

#[test]
fn fit_on_corrupted_sets_never_panics_and_gives_finite_numbers_or_a_located_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let tmp = tempfile::tempdir().unwrap();
    let (mut ok, mut refused) = (0, 0);
    for base in ["table1-medium", "table3-pulsating"] {
        for (k, kind) in KINDS.iter().chain(KINDS.iter()).enumerate() {
            let root = tmp.path().join(format!("{base}-{k}"));
            let set = corrupted_set(base, &root, *kind, &mut rng);
            let out = root.join("fit");
            let what = format!("fit {base} {kind:?} #{k}");
            let a = args![
                "fit",
                &set,
                "--global-evals",
                "60",
                "--starts",
                "1",
                "--no-profiles",
                "--out",
                &out
            ];
            if !no_panic_and_located(a, &set, &what) {
                refused += 1;
                continue;
            }
            ok += 1;
            let fit = read_json(&out.join("fit.json"));
            for k in ["mu_s", "mu_k", "kappa", "xi", "u_tilde", "alpha_t"] {
                assert!(
                    finite(&fit["params"][k]),
                    "{what}: {k} = {}",
                    fit["params"][k]
                );
            }
            let r = &fit["report"];
            assert!(
                finite(&r["ssr"]) && finite(&r["reduced_chi2"]),
                "{what}: {r}"
            );
            for t in r["tests"].as_array().unwrap() {
                assert!(finite(&t["rms"]), "{what}: {t}");
            }
        }
    }
    // Both outcomes occur: the corruptions are neither all harmless nor all fatal.
    assert!(ok >= 4 && refused >= 4, "{ok} fitted, {refused} refused");
}

#[test]
fn diagnose_on_corrupted_sets_never_panics_and_gives_finite_numbers_or_a_located_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let tmp = tempfile::tempdir().unwrap();
    let mut ran = 0;
    for (k, kind) in KINDS.iter().enumerate() {
        let root = tmp.path().join(format!("d{k}"));
        let set = corrupted_set("table1-medium", &root, *kind, &mut rng);
        let out = root.join("diagnosis");
        let what = format!("diagnose {kind:?}");
        if !no_panic_and_located(args!["diagnose", &set, "--out", &out], &set, &what) {
            continue;
        }
        ran += 1;
        let d = read_json(&out.join("diagnosis.json"));
        assert!(
            d["verdict"]["effect"].is_string(),
            "{what}: {}",
            d["verdict"]
        );
        let shrink = &d["verdict"]["held_out_shrink"];
        assert!(
            finite(shrink) && (0.0..=1.0).contains(&shrink.as_f64().unwrap()),
            "{what}: held-out shrink {shrink}"
        );
    }
    assert!(ran >= 2, "only {ran} corrupted sets were diagnosed");
}
