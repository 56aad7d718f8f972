// Scratch probe (not committed): fit a set with a template model and chosen free parameters.
use subfric_fit::{calibrate, FitOptions, FitTest, Param, Space};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let set = subfric_data::load_set(std::path::Path::new(&a[1])).unwrap();
    let text = std::fs::read_to_string(&a[2]).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let m: subfric_model::Model = serde_json::from_value(v["model"].clone()).unwrap();
    let free: Vec<Param> = a[3]
        .split(',')
        .map(|k| Param::from_key(k).unwrap())
        .collect();
    let evals: usize = a.get(4).map(|s| s.parse().unwrap()).unwrap_or(2000);
    let prepared = subfric_diagnose::prepare_for_diagnosis(&set);
    let tests: Vec<FitTest> = prepared.iter().map(|p| p.fit.clone()).collect();
    let space = Space::with_rate(m, &free, &[], subfric_fit::typical_rate(&tests));
    let opts = FitOptions {
        global_evaluations: evals,
        starts: 6,
        profiles: false,
        ..FitOptions::default()
    };
    let r = calibrate(&tests, space, &opts, &|_| {}).unwrap();
    println!(
        "chi2 {:.3} term {:?}",
        r.reduced_chi2, r.optimizer.termination
    );
    for p in &r.parameters {
        println!("  {} = {:.5e}", p.name, p.value);
    }
    for t in &r.tests {
        println!("  {:25} rms/noise {:.3}", t.name, t.rms_over_noise);
    }
}
