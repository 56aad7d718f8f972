//! `subfric plan <set>` end to end: ranked proposals in plan.json, a scenario per proposal that
//! `subfric simulate --scenario` runs, the top proposal checked by a simulated joint fit, and a
//! decodable figure of its predicted band.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_subfric"))
}

fn experiments() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments")
}

#[test]
fn plan_writes_ranked_runnable_proposals_a_check_and_a_band_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("plan");
    let set = experiments().join("table1-smooth");
    let o = bin()
        .arg("plan")
        .arg(&set)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("not determined now:"), "{stdout}");

    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("plan.json")).unwrap()).unwrap();
    let plan = &v["plan"];
    let undetermined: Vec<&str> = plan["undetermined"]
        .as_array()
        .unwrap()
        .iter()
        .map(|k| k.as_str().unwrap())
        .collect();
    assert!(undetermined.contains(&"xi"), "{undetermined:?}");
    let proposals = plan["proposals"].as_array().unwrap();
    assert!(proposals.len() >= 8, "{} proposals", proposals.len());
    let scores: Vec<f64> = proposals
        .iter()
        .map(|p| p["score"].as_f64().unwrap())
        .collect();
    assert!(
        scores.windows(2).all(|w| w[0] >= w[1]),
        "not ranked: {scores:?}"
    );
    let top = &proposals[0];
    assert!(top["determines_share"].as_f64().unwrap() > 0.0);

    // The check: simulated at the planning point, fitted jointly; ξ's achieved interval beside
    // the predicted one.
    let check = &top["check"];
    let xi = check["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "xi")
        .expect("ξ checked");
    let ratio = xi["width_ratio"].as_f64().expect("both intervals closed");
    assert!((0.5..=2.0).contains(&ratio), "{xi}");

    // Each proposal's scenario runs through `subfric simulate --scenario`.
    let name = top["name"].as_str().unwrap();
    let scenario = out.join("scenarios").join(format!("{name}.json"));
    let sim = tmp.path().join("sim");
    let o = bin()
        .args(["simulate", "--scenario"])
        .arg(&scenario)
        .arg("--params")
        .arg(set.join("experiment.json"))
        .arg("--out")
        .arg(&sim)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(sim.join(format!("{name}.csv"))).unwrap();
    let rows = csv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .count()
        .saturating_sub(1);
    assert_eq!(rows as u64, top["rows"].as_u64().unwrap());

    let png = subfric_plot::inspect_png(&out.join("top-proposal.png")).expect("a valid PNG");
    assert_eq!((png.width, png.height), (1000, 750));
    assert!(
        png.inked_fraction > 0.02 && png.inked_fraction < 0.6,
        "{png:?}"
    );
}
