//! `subfric plan <set>` end to end (issue 15): ranked proposals in plan.json, a scenario per
//! proposal that `subfric simulate --scenario` runs, the top proposal checked by a simulated
//! joint fit, a decodable figure of its predicted band, and the folder protected like every
//! results folder.

use subfric_e2e::{args, copy_set, read_data_csv, read_json, subfric, text};

#[test]
fn plan_writes_ranked_runnable_proposals_a_check_and_a_band_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let set = copy_set("table1-smooth", tmp.path());
    let out = tmp.path().join("plan");
    let stdout = subfric!().ok(args!["plan", &set, "--out", &out]);
    assert!(stdout.contains("not determined now:"), "{stdout}");

    let v = read_json(&out.join("plan.json"));
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
    let xi = top["check"]["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "xi")
        .expect("ξ checked")
        .clone();
    let ratio = xi["width_ratio"].as_f64().expect("both intervals closed");
    assert!((0.5..=2.0).contains(&ratio), "{xi}");

    // The top proposal's scenario runs through `subfric simulate --scenario`.
    let name = top["name"].as_str().unwrap();
    let scenario = out.join("scenarios").join(format!("{name}.json"));
    let sim = tmp.path().join("sim");
    subfric!().ok(args![
        "simulate",
        "--scenario",
        &scenario,
        "--params",
        &set.join("experiment.json"),
        "--out",
        &sim
    ]);
    let (_, rows) = read_data_csv(&sim.join(format!("{name}.csv")));
    assert_eq!(rows.len() as u64, top["rows"].as_u64().unwrap());

    let png = subfric_plot::inspect_png(&out.join("top-proposal.png")).expect("a valid PNG");
    assert_eq!((png.width, png.height), (1000, 750));
    assert!(
        png.inked_fraction > 0.02 && png.inked_fraction < 0.6,
        "{png:?}"
    );

    // The report: one page, the verdict first, the ranking, the figure, the legend.
    let page = subfric_e2e::html::check_report(&out.join("report.html"), &out);
    assert_eq!(page.images.len(), 1);
    assert!(page.text.contains("the base model describes these data"));
    assert!(page
        .text
        .contains("planning point (the middle of the values the data allow"));

    // Planned again into the same folder, a scenario the new plan does not propose is gone
    // (a stale one would be read as a proposal).
    let stale = out
        .join("scenarios")
        .join("proposed-by-an-earlier-plan.json");
    std::fs::copy(&scenario, &stale).unwrap();
    subfric!().ok(args!["plan", &set, "--out", &out, "--check", "0"]);
    assert!(!stale.exists());
    assert!(scenario.exists());

    // A folder holding another set's plan is not overwritten without --force.
    let other = copy_set("table1-medium", tmp.path());
    let o = subfric!().run(args!["plan", &other, "--out", &out, "--check", "0"]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stdout));
    assert!(text(&o.stderr).contains("--force"), "{}", text(&o.stderr));
}
