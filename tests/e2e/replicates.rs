//! `diagnose --replicates N` on the built program: the verdict again at the seeds after its own,
//! each replicate the diagnosis a user gets at that seed, and whether the verdict moves.

use subfric_e2e::{args, copy_set, read_json, subfric};

#[test]
fn replicates_say_whether_the_verdict_moves_with_the_seed_and_each_is_the_diagnosis_at_its_seed() {
    // Table 4's set: diagnosed in a second, and its base fit, and so the confidence stated,
    // moves in the fifth digit from seed 1 to seed 2 (a replicate run at the wrong seed shows).
    let tmp = tempfile::tempdir().unwrap();
    copy_set("table4-two-way", tmp.path());
    let run = subfric!().cwd(tmp.path());
    let stdout = run.ok(args![
        "diagnose",
        "table4-two-way",
        "--replicates",
        "2",
        "--out",
        "replicated"
    ]);
    // What the seeds say stands with the verdict, before the next step.
    let lines: Vec<&str> = stdout.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.starts_with("replicates: "))
        .unwrap_or_else(|| panic!("no replicates line:\n{stdout}"));
    assert!(lines[..at].iter().any(|l| l.starts_with("how sure: ")));
    assert!(lines[at + 1].starts_with("next: "), "{stdout}");

    let json = read_json(&tmp.path().join("replicated/diagnosis.json"));
    let r = &json["verdict"]["replicates"];
    let runs = r["runs"].as_array().expect("the runs of every seed");
    let seeds: Vec<u64> = runs.iter().map(|x| x["seed"].as_u64().unwrap()).collect();
    assert_eq!(seeds, [1, 2]);
    // The first run is the diagnosis itself ...
    assert_eq!(runs[0]["effects"], json["verdict"]["effects"]);
    assert_eq!(runs[0]["confidence"], json["verdict"]["confidence"]);
    // ... and the second the diagnosis a user gets with --seed 2, to the last digit.
    run.ok(args![
        "diagnose",
        "table4-two-way",
        "--seed",
        "2",
        "--out",
        "seed-2"
    ]);
    let seed_2 = read_json(&tmp.path().join("seed-2/diagnosis.json"));
    assert_eq!(runs[1]["effects"], seed_2["verdict"]["effects"]);
    assert_eq!(runs[1]["confidence"], seed_2["verdict"]["confidence"]);
    assert!(seed_2["verdict"].get("replicates").is_none());
    // Stable exactly when the two seeds named the same effects, and the line says which.
    let same = runs[0]["effects"] == runs[1]["effects"];
    assert_eq!(r["stable"].as_bool(), Some(same));
    assert_eq!(
        r["readings"].as_array().unwrap().len(),
        if same { 1 } else { 2 }
    );
    let line = lines[at];
    assert_eq!(
        line.contains("the same verdict at all 2 seeds"),
        same,
        "{line}"
    );
    assert_eq!(line.contains("uncertain between"), !same, "{line}");

    // `selfcheck --sets DIR --seed 2` diagnoses at that seed too, so a folder of sets with a
    // truth can be scored at two seeds and its moving verdicts counted.
    let scored = tmp.path().join("scored");
    copy_set("table4-two-way", &scored);
    std::fs::write(
        scored.join("truth.json"),
        r#"{"table4-two-way": {"effect": "none"}}"#,
    )
    .unwrap();
    run.ok(args![
        "selfcheck",
        "--sets",
        &scored,
        "--seed",
        "2",
        "--json",
        "scores.json"
    ]);
    let scores = read_json(&tmp.path().join("scores.json"));
    assert_eq!(
        scores["cases"][0]["confidence"],
        seed_2["verdict"]["confidence"]
    );
}
