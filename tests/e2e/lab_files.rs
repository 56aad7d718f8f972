//! Lab files as they come (issue 43), end to end: a logger's set in MPa with a dilation
//! channel, missing samples and a coarse clock is checked, fitted and diagnosed, and every
//! command says what it made of the columns.

use std::path::Path;
use subfric_e2e::{args, assert_mentions, copy_set, subfric, text};

/// `table1-medium` as an interface lab's logger writes it: stresses in MPa (declared in
/// experiment.json's `units`), a dilation channel, three missing shear samples, and a clock that
/// ticks once a second while the logger samples at 16.7 Hz; the test is described as one of
/// constant normal stiffness.
fn lab_logger_set(tmp: &Path) -> std::path::PathBuf {
    let set = copy_set("table1-medium", &tmp.join("logger"));
    let meta = set.join("experiment.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&meta).unwrap()).unwrap();
    m["units"] = serde_json::json!({"stress": "MPa"});
    m["tests"][0]["normal_stiffness_kpa_per_mm"] = serde_json::json!(500);
    std::fs::write(&meta, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    let csv = set.join("monotonic.csv");
    let (header, rows) = subfric_e2e::read_data_csv(&csv);
    assert_eq!(header, ["time_s", "slip_mm", "shear_kpa"]);
    let mut out = String::from("time_s,slip_mm,shear_kpa,normal_kpa,normal_disp_mm\n");
    for (i, r) in rows.iter().enumerate() {
        let shear = if [100, 101, 300].contains(&i) {
            String::new()
        } else {
            format!("{:.7}", r[2] / 1000.0)
        };
        let dilation = 0.02 * r[1];
        out.push_str(&format!(
            "{},{},{shear},0.0784,{dilation:.5}\n",
            r[0].floor(),
            r[1]
        ));
    }
    std::fs::write(&csv, out).unwrap();
    set
}

#[test]
fn a_logger_set_in_mpa_with_dilation_gaps_and_a_coarse_clock_checks_fits_and_diagnoses_saying_each_choice(
) {
    let tmp = tempfile::tempdir().unwrap();
    let set = lab_logger_set(tmp.path());
    let said = [
        "monotonic: columns read in the set's units: stress MPa → kPa ×1000",
        "monotonic: further channels carried, not used by the model: normal_disp_mm 0..0.06",
        "monotonic: constant normal stiffness 500 kPa/mm (metadata): the model is driven by the normal stress each row carries",
        "3 rows without a value (an empty cell, NaN or NA) read as gaps, left out of the record: lines 102–103 and 302",
        "a clock coarser than the sampling (a tick of 1 s); the rows within a tick are spread evenly over it",
    ];
    let (out, err) = subfric!().ok_both(args!["check", &set]);
    assert_mentions(&format!("{out}{err}"), &said);
    // The fit reads the stresses as kPa: the same parameters as the set written in kPa.
    let fit = |set: &Path, name: &str| {
        let dir = tmp.path().join(name);
        let o = subfric!().run(args!["fit", set, "--no-profiles", "--out", &dir]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("fit.json")).unwrap()).unwrap();
        (j, text(&o.stderr))
    };
    let (logged, err) = fit(&set, "fit-logger");
    assert_mentions(&err, &said);
    let (own, _) = fit(
        &copy_set("table1-medium", &tmp.path().join("own")),
        "fit-own",
    );
    for p in ["mu_s", "mu_k"] {
        let (a, b) = (
            logged["params"][p].as_f64().unwrap(),
            own["params"][p].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() < 0.01, "{p}: {a} against {b} in kPa");
    }
    // The diagnosis says the same choices and writes its report.
    let dout = tmp.path().join("diagnosis");
    let o = subfric!().run(args!["diagnose", &set, "--out", &dout]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_mentions(&text(&o.stderr), &said);
    assert!(dout.join("report.html").exists() && dout.join("diagnosis.json").exists());
}
