//! Development driver: diagnose sets under a folder and compare with an optional truth.json.
use subfric_diagnose::*;
fn main() {
    let root = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let only: Option<String> = std::env::args().nth(2);
    let truth: serde_json::Value = std::fs::read_to_string(root.join("truth.json"))
        .ok()
        .and_then(|s| serde_json::from_str(&s).ok())
        .unwrap_or_default();
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    let mut cases = vec![];
    for d in dirs {
        let name = d.file_name().unwrap().to_string_lossy().to_string();
        if let Some(o) = &only {
            if !name.contains(o.as_str()) {
                continue;
            }
        }
        let set = subfric_data::load_set(&d).unwrap();
        let prepared = subfric_fit::prepare_set(&set, false);
        let diag = diagnose(&prepared, &DiagnoseOptions::default()).unwrap();
        let t = truth[&name]["effect"]
            .as_str()
            .and_then(Effect::from_name)
            .unwrap_or(Effect::None);
        println!(
            "{name}: truth {t} verdict {} shrink {:.2} base chi2 {:.2} ({:.1}s)",
            diag.verdict.effect,
            diag.verdict.held_out_shrink,
            diag.base.reduced_chi2,
            diag.elapsed_s
        );
        if std::env::var("FOLDS").is_ok() {
            for c in diag.candidates.iter().take(1) {
                for f in &c.folds {
                    println!(
                        "      fold {:50} n {:5} base {:7.2} cand {:7.2}",
                        f.fold, f.rows, f.base_rms_over_noise, f.candidate_rms_over_noise
                    );
                }
            }
        }
        println!(
            "    drift alt: shrink {:.3} dBIC {:.1}",
            diag.drift.held_out_shrink, diag.drift.delta_bic
        );
        for c in &diag.candidates {
            println!(
                "    {:15} shrink {:.3} dBIC {:9.1} fit chi2 {:.3} {:?}",
                c.effect.name(),
                c.held_out_shrink,
                c.delta_bic,
                c.fit_reduced_chi2,
                c.extra_parameters
            );
        }
        if std::env::var("LOC").is_ok() {
            let mut g = diag.localisation.by_test_segment.clone();
            g.sort_by(|a, b| b.share_of_gap.total_cmp(&a.share_of_gap));
            for x in g.iter().take(8) {
                println!(
                    "      loc {:50} rows {:5} rms/noise {:6.2} share {:.2}",
                    x.group, x.rows, x.rms_over_noise, x.share_of_gap
                );
            }
            println!("      base {:?}", diag.base.model.params);
        }
        cases.push(selfcheck::Case::new(&name, t, &diag));
    }
    println!("{}", selfcheck::score(&cases));
}
