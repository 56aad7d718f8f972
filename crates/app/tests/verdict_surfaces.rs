//! One verdict, the same words on every surface (issue 43): a diagnosis that names two effects
//! reads as "rate + log-healing" in the terminal's lines, the report text, the HTML page and
//! diagnosis.json (whose top-level `verdict` lists every effect, as Python returns it), with
//! the standing its confidence earns.

use std::path::Path;
use subfric_app::diagnose::diagnosis_json;
use subfric_app::render::diagnose_report::{report_text, verdict_lines};
use subfric_app::render::diagnosis_page::diagnosis_page;
use subfric_diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Effect};

#[test]
fn a_two_effect_verdict_reads_the_same_on_every_surface() {
    let set = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/golden/pair-01");
    let loaded = subfric_data::load_set(&set).expect("the golden set loads");
    let d =
        diagnose(&prepare_for_diagnosis(&loaded), &DiagnoseOptions::default()).expect("diagnoses");
    let rate = Effect::from_name("rate").unwrap();
    assert_eq!(d.verdict.named(), [rate], "the golden set's verdict");
    // The same diagnosis with a second effect named after the first, at a confidence that
    // earns "probably".
    let mut two = d.clone();
    let healing = Effect::from_name("log-healing").unwrap();
    let mut second = two.verdict.effects[0].clone();
    second.effect = healing;
    second.form = "log time, b ln(1 + t/t_c) at rest".into();
    two.verdict.effects.push(second);
    two.verdict.confidence = Some(0.8);
    let label = "rate + log-healing";

    let lines = verdict_lines(&set, &two);
    let effect_line = lines
        .iter()
        .find(|l| l.contains("missing effect"))
        .unwrap_or_else(|| panic!("no verdict line names an effect: {lines:?}"));
    assert!(
        effect_line.contains(&format!("probably missing effect: {label} (80 %)")),
        "{effect_line}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("how sure: ")),
        "{lines:?}"
    );
    let next = lines.iter().find(|l| l.starts_with("next: ")).unwrap();
    assert!(next.contains(&format!("the model with {label}")), "{next}");

    let text = report_text("pair-01", &set, &two, None);
    for l in &lines {
        assert!(text.contains(l.as_str()), "report text lacks: {l}");
    }
    let dir = tempfile::tempdir().unwrap();
    let page = diagnosis_page("pair-01", &set, &two, &text, dir.path(), &[]).unwrap();
    assert!(
        page.contains(&format!("probably missing effect: {label} (80 %)")),
        "the page's verdict differs"
    );

    let json = diagnosis_json("pair-01", &two);
    let v = &json["verdict"];
    assert_eq!(v["effects"], serde_json::json!(["rate", "log-healing"]));
    assert_eq!(v["effect"], "rate");
    assert_eq!(v["standing"], "probable");
    assert_eq!(v["confidence"], 0.8);
    let inner: Vec<&str> = json["diagnosis"]["verdict"]["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["effect"].as_str().unwrap())
        .collect();
    assert_eq!(inner, ["rate", "log-healing"]);
}
