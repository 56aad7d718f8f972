//! Dev probe: residuals of the generating model (truth.json) on a generated set, per test.
fn main() {
    if std::env::args().nth(2).as_deref() == Some("noreweight") {
        let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
        let set = subfric_data::load_set(&dir).unwrap();
        let prepared = subfric_diagnose::prepare_for_diagnosis(&set);
        for chi in [10.0, 1e9] {
            let mut opts = subfric_diagnose::DiagnoseOptions::default();
            opts.thresholds.model_error_chi2 = chi;
            let d = subfric_diagnose::diagnose(&prepared, &opts).unwrap();
            let f = d
                .forms
                .iter()
                .find(|f| f.form.starts_with("direct"))
                .unwrap();
            if chi > 1e8 {
                let truth: serde_json::Value = serde_json::from_str(
                    &std::fs::read_to_string(dir.parent().unwrap().join("truth.json")).unwrap(),
                )
                .unwrap();
                let name = dir.file_name().unwrap().to_string_lossy().to_string();
                let tm: subfric_model::Model =
                    serde_json::from_value(truth[&name]["model"].clone()).unwrap();
                let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
                let w: Vec<Vec<f64>> = tests
                    .iter()
                    .map(|t| (0..t.len()).map(|i| t.weight_of(i)).collect())
                    .collect();
                let pieces = subfric_diagnose::folds::pieces(&prepared);
                let rb = subfric_diagnose::fits::residuals(&tests, &d.base.model, None);
                let rt = subfric_diagnose::fits::residuals(&tests, &tm, None);
                let rf = subfric_diagnose::fits::residuals(&tests, &f.model, None);
                eprintln!("--- truth vs base");
                let c = subfric_diagnose::score::compare(&pieces, &w, &rb, &rt);
                eprintln!(
                    "truth score {:.1} shape {:.1} level {:.1}",
                    c.score, c.shape_score, c.level_score
                );
                eprintln!("--- fitted direct vs base");
                let c = subfric_diagnose::score::compare(&pieces, &w, &rb, &rf);
                eprintln!(
                    "fit score {:.1} shape {:.1} level {:.1}",
                    c.score, c.shape_score, c.level_score
                );
            }
            println!("model_error_chi2 {chi}: verdict {} ; direct form score {:.1} params {:?}\n  model {:?}", d.verdict.effect, f.in_sample_score, f.parameters, f.model.params);
        }
        return;
    }
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.parent().unwrap().join("truth.json")).unwrap(),
    )
    .unwrap();
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let model: subfric_model::Model =
        serde_json::from_value(truth[&name]["model"].clone()).unwrap();
    let set = subfric_data::load_set(&dir).unwrap();
    for (label, prepared) in [
        (
            "diagnosis rows",
            subfric_diagnose::prepare_for_diagnosis(&set),
        ),
        (
            "all rows",
            subfric_fit::prepare_set_with(
                &set,
                false,
                &subfric_fit::PrepareOptions {
                    budget_rows: 0,
                    ..Default::default()
                },
            ),
        ),
    ] {
        let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
        let res = subfric_diagnose::fits::residuals(&tests, &model, None);
        for (t, r) in tests.iter().zip(&res) {
            let ssr: f64 = r.iter().map(|v| v * v).sum();
            println!(
                "{label:<15} {:<20} rows {:5} chi2 {:8.3} start {:?}",
                t.name,
                t.len(),
                ssr / t.len() as f64,
                t.initial
            );
        }
    }
}

#[allow(dead_code)]
fn unused() {}
