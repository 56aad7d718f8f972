//! Trust under bad input, at the data layer: files that are not what they claim (links out of
//! the set, folders, FIFOs), contradictory columns, implausible values, and writes that never
//! leave a half-written file or write through a link.

use std::path::Path;
use subfric_data::{import, load_set, plausibility, write_set, ImportSpec};

fn small_set(dir: &Path, header: &str, rows: &[String]) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(
        dir.join("experiment.json"),
        r#"{"name": "s", "title": "t", "source": "test",
            "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}]}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("a.csv"),
        format!("{header}\n{}\n", rows.join("\n")),
    )
    .unwrap();
}

fn error_of(dir: &Path) -> String {
    load_set(dir).unwrap_err().to_string()
}

#[test]
fn friction_and_shear_must_agree_within_their_rounding() {
    let tmp = tempfile::tempdir().unwrap();
    let rows: Vec<String> = (0..20)
        .map(|i| {
            let shear = 30.0 * (1.0 - (-(i as f64) / 4.0).exp());
            format!("{i},{},{shear:.3},{:.4}", 0.01 * i as f64, shear / 100.0)
        })
        .collect();
    small_set(tmp.path(), "time_s,slip_mm,shear_kpa,friction", &rows);
    let set = load_set(tmp.path()).unwrap();
    assert!(!set.tests[0].friction_given);
    // One row off by more than the rounding of its digits.
    let mut bad = rows.clone();
    bad[7] = "7,0.07,25.000,0.2700".into();
    small_set(tmp.path(), "time_s,slip_mm,shear_kpa,friction", &bad);
    let e = error_of(tmp.path());
    assert!(e.contains("a.csv:9: field `friction`"), "{e}");
    assert!(e.contains("27 kPa, but shear_kpa is 25"), "{e}");
    // With a normal column, that column is the normal stress of the row.
    let with_normal: Vec<String> = (0..5)
        .map(|i| format!("{i},{},50,0.25,200", 0.01 * i as f64))
        .collect();
    small_set(
        tmp.path(),
        "time_s,slip_mm,shear_kpa,friction,normal_kpa",
        &with_normal,
    );
    load_set(tmp.path()).unwrap();
}

#[test]
fn a_value_no_measurement_can_have_is_an_error_at_its_line() {
    let tmp = tempfile::tempdir().unwrap();
    let mut rows: Vec<String> = (0..10)
        .map(|i| format!("{i},{},20", 0.01 * i as f64))
        .collect();
    rows[4] = "4,1e300,20".into();
    small_set(tmp.path(), "time_s,slip_mm,shear_kpa", &rows);
    let e = error_of(tmp.path());
    assert!(
        e.contains("a.csv:6: field `slip_mm`: value 1e300 is beyond"),
        "{e}"
    );
    // Large but possible values pass.
    rows[4] = "4,1e9,20".into();
    small_set(tmp.path(), "time_s,slip_mm,shear_kpa", &rows);
    load_set(tmp.path()).unwrap();
}

#[cfg(unix)]
#[test]
fn files_are_named_for_what_they_are_and_links_stay_inside_the_set() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let rows: Vec<String> = (0..5).map(|i| format!("{i},{},1", i)).collect();
    small_set(&dir, "time_s,slip_mm,shear_kpa", &rows);
    let secret = tmp.path().join("secret");
    std::fs::write(&secret, "never-read-me,x\n").unwrap();
    std::fs::remove_file(dir.join("a.csv")).unwrap();
    std::os::unix::fs::symlink(&secret, dir.join("a.csv")).unwrap();
    let e = error_of(&dir);
    assert!(
        e.contains("symbolic link") && !e.contains("never-read-me"),
        "{e}"
    );
    std::fs::remove_file(dir.join("a.csv")).unwrap();
    std::fs::create_dir(dir.join("a.csv")).unwrap();
    let e = error_of(&dir);
    assert!(e.contains("is a folder") && !e.contains("absent"), "{e}");
    std::fs::remove_dir(dir.join("a.csv")).unwrap();
    let ok = std::process::Command::new("mkfifo")
        .arg(dir.join("a.csv"))
        .status()
        .unwrap();
    assert!(ok.success());
    let e = error_of(&dir);
    assert!(e.contains("not a regular file"), "{e}");
    // experiment.json itself as a link out of the set.
    let elsewhere = tmp.path().join("elsewhere.json");
    std::fs::rename(dir.join("experiment.json"), &elsewhere).unwrap();
    std::os::unix::fs::symlink(&elsewhere, dir.join("experiment.json")).unwrap();
    let e = error_of(&dir);
    assert!(
        e.contains("experiment.json") && e.contains("outside the set folder"),
        "{e}"
    );
}

#[test]
fn implausible_but_valid_data_are_warned_about() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&str, Vec<String>, &str); 5] = [
        (
            "pa",
            (0..20)
                .map(|i| format!("{i},{},{}", 0.01 * i as f64, 30000 + i))
                .collect(),
            "Pa rather than kPa",
        ),
        (
            "mpa",
            (0..20)
                .map(|i| format!("{i},{},0.03", 0.01 * i as f64))
                .collect(),
            "MPa rather than kPa",
        ),
        (
            "zero",
            (0..20)
                .map(|i| format!("{i},{},0", 0.01 * i as f64))
                .collect(),
            "0 on every row",
        ),
        (
            "um",
            (0..20)
                .map(|i| format!("{i},{},30", 1000.0 * i as f64))
                .collect(),
            "µm rather than mm",
        ),
        ("one", vec!["0,0,30".to_string()], "only 1 row"),
    ];
    for (name, rows, words) in cases {
        let dir = tmp.path().join(name);
        small_set(&dir, "time_s,slip_mm,shear_kpa", &rows);
        let w = plausibility(&load_set(&dir).unwrap());
        let text: Vec<String> = w.iter().map(|w| w.to_string()).collect();
        assert!(
            text.iter()
                .any(|t| t.contains("a.csv") && t.contains(words)),
            "{name}: {text:?}"
        );
    }
    // The bundled sets and the golden set raise none.
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for e in std::fs::read_dir(root.join("experiments")).unwrap() {
        let set = load_set(&e.unwrap().path()).unwrap();
        assert!(plausibility(&set).is_empty(), "{}", set.meta.name);
    }
    let golden = load_set(&root.join("tests/golden/pair-01")).unwrap();
    assert!(plausibility(&golden).is_empty());
}

#[cfg(unix)]
#[test]
fn writes_replace_links_and_never_write_through_them() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("src");
    let rows: Vec<String> = (0..5)
        .map(|i| format!("{i},{},1", 0.01 * i as f64))
        .collect();
    small_set(&src, "time_s,slip_mm,shear_kpa", &rows);
    let set = load_set(&src).unwrap();
    let out = tmp.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    let victim = tmp.path().join("victim");
    std::fs::write(&victim, "precious").unwrap();
    std::os::unix::fs::symlink(&victim, out.join("a.csv")).unwrap();
    std::os::unix::fs::symlink(&victim, out.join("experiment.json")).unwrap();
    write_set(&set, &out).unwrap();
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    load_set(&out).unwrap();
    // import refuses a dangling link where its CSV would go, and leaves nothing.
    let lab = tmp.path().join("lab.csv");
    std::fs::write(&lab, "time_s,slip_mm,shear_kpa\n0,0,0\n1,0.01,20\n").unwrap();
    let fresh = tmp.path().join("fresh");
    std::fs::create_dir_all(&fresh).unwrap();
    let target = tmp.path().join("through-link.csv");
    std::os::unix::fs::symlink(&target, fresh.join("t.csv")).unwrap();
    let spec = ImportSpec {
        normal_stress_kpa: Some(100.0),
        test_name: "t".into(),
        ..ImportSpec::default()
    };
    let e = import(&lab, &spec, &fresh).unwrap_err().to_string();
    assert!(e.contains("already exists"), "{e}");
    assert!(!target.exists() && !fresh.join("experiment.json").exists());
}
