//! End-to-end tests of `subfric bench` on the built program: the parts asked for and only
//! those (a whole run takes minutes), the step against a peer script, the diagnoses of named
//! records, and the errors that name what failed.

use std::ffi::OsStr;
use std::process::Output;

use serde_json::Value;
use subfric_e2e::{args, assert_mentions, copy_set, subfric, text};

fn run(a: &[&OsStr]) -> Output {
    subfric!().run(a)
}

fn run_ok(a: &[&OsStr]) -> String {
    subfric!().ok(a)
}

#[test]
fn bench_runs_the_parts_asked_for_and_only_those() {
    let tmp = tempfile::tempdir().unwrap();
    let experiments = tmp.path().join("experiments");
    copy_set("table1-medium", &experiments);
    let json: Value = serde_json::from_str(&run_ok(args![
        "bench",
        "--experiments",
        &experiments,
        "--only",
        "step,fits",
        "--json"
    ]))
    .unwrap();
    let sps = json["steps_per_second"].as_f64().unwrap();
    assert!(sps > 1e5, "{json}");
    assert_eq!(json["identical_to_simulate"], true, "{json}");
    let fits = json["fit_seconds"].as_array().unwrap();
    assert_eq!(fits.len(), 1, "{json}");
    assert_eq!(fits[0][0], "table1-medium");
    assert!(fits[0][1].as_f64().unwrap() > 0.0);
    for absent in ["multistart", "many_tests", "diagnoses", "sampler"] {
        assert!(
            json.get(absent).is_none(),
            "{absent} was not asked for: {json}"
        );
    }
    // The step alone reads no set: a folder that does not exist is no error then.
    let step = run_ok(args![
        "bench",
        "--experiments",
        &tmp.path().join("nosuch"),
        "--only",
        "step"
    ]);
    assert!(step.starts_with("model step: "), "{step}");
    assert_eq!(step.lines().count(), 2, "{step}");
    // A part that does not exist is a usage error naming the parts there are.
    let o = run(args!["bench", "--only", "steps"]);
    assert_eq!(o.status.code(), Some(2));
    assert_mentions(&text(&o.stderr), &["step", "many-tests", "diagnoses"]);
}

#[test]
fn bench_times_the_step_against_a_peer_and_says_which_peer_failed() {
    let tmp = tempfile::tempdir().unwrap();
    // A peer that prints its rate as the numba peer does, at a known 1.5 million steps/s.
    let peer = tmp.path().join("peer.py");
    std::fs::write(&peer, "print('fake peer: 1.500e+06 steps/s')\n").unwrap();
    let json: Value = serde_json::from_str(&run_ok(args![
        "bench", "--only", "step", "--peer", &peer, "--json"
    ]))
    .unwrap();
    let p = &json["peer"];
    assert_eq!(p["peer_steps_per_second"].as_f64(), Some(1.5e6), "{json}");
    let (ours, ratio) = (
        p["steps_per_second"].as_f64().unwrap(),
        p["ratio"].as_f64().unwrap(),
    );
    assert!(ours > 1e5, "{json}");
    assert!((ratio - ours / 1.5e6).abs() < 1e-9 * ratio, "{json}");
    let text_out = run_ok(args!["bench", "--only", "step", "--peer", &peer]);
    assert!(text_out.contains("× the peer"), "{text_out}");
    // A peer that fails, or prints no rate, is an error naming it (never a ratio of nothing).
    let broken = tmp.path().join("broken.py");
    std::fs::write(&broken, "import no_such_module_here\n").unwrap();
    let o = run(args!["bench", "--only", "step", "--peer", &broken]);
    assert_ne!(o.status.code(), Some(0));
    assert_mentions(&text(&o.stderr), &["broken.py", "no_such_module_here"]);
    let silent = tmp.path().join("silent.py");
    std::fs::write(&silent, "print('done')\n").unwrap();
    let o = run(args!["bench", "--only", "step", "--peer", &silent]);
    assert_ne!(o.status.code(), Some(0));
    assert_mentions(&text(&o.stderr), &["silent.py", "steps/s"]);
    // A record that is not there is an error naming the folder.
    let missing = tmp.path().join("no-such-record");
    let o = run(args!["bench", "--only", "step", "--record", &missing]);
    assert_ne!(o.status.code(), Some(0));
    assert_mentions(&text(&o.stderr), &["no-such-record"]);
}
