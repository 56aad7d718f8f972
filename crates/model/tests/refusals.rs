//! What the model refuses rather than compute a wrong or unbounded answer: a stiffness whose
//! elastic slip is below the floating-point resolution, and scenarios too large for memory.

use std::time::{Duration, Instant};
use subfric_model::{simulate, Control, Model, Params, Protocol, Scenario, MAX_ALPHA};

fn two_way(model: &Model) -> Vec<f64> {
    let time: Vec<f64> = (0..=400).map(|i| i as f64).collect();
    let slip: Vec<f64> = time
        .iter()
        .map(|t| 1.5 * (2.0 * std::f64::consts::PI * t / 200.0).sin())
        .collect();
    let normal = vec![100.0; time.len()];
    let p = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    simulate(model, &p).unwrap().shear
}

#[test]
fn a_stiffness_whose_elastic_slip_is_lost_in_rounding_is_refused() {
    let mut p = Params::sample();
    p.alpha_t = 1e15;
    p.alpha_n = 1e15;
    let e = Model::base(p).unwrap_err().to_string();
    assert!(
        e.contains("alpha_t = 1e15") && e.contains("floating-point"),
        "{e}"
    );
    // At the limit the shear is still the one of a realistic stiffness (the elastic slip is
    // negligible at both), so the limit refuses nothing that computes right.
    let soft = Model::base(Params::sample()).unwrap();
    p.alpha_t = MAX_ALPHA;
    p.alpha_n = MAX_ALPHA;
    let stiff = Model::base(p).unwrap();
    let (a, b) = (two_way(&soft), two_way(&stiff));
    let peak = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = a
        .iter()
        .zip(&b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    eprintln!("at the limit: largest difference {worst:.3e} kPa of a peak of {peak:.2} kPa");
    assert!(
        peak > 10.0 && worst < 1e-3 * peak,
        "peak {peak}, worst {worst}"
    );
}

#[test]
fn scenarios_are_counted_before_any_row_is_generated() {
    let t0 = Instant::now();
    let sc = |dt: &str, stage: &str| -> Scenario {
        serde_json::from_str(&format!(
            r#"{{"name": "s", "control": "slip", "normal_stress_kpa": 100, "dt_s": {dt}, "stages": [{stage}]}}"#
        ))
        .unwrap()
    };
    let long = sc(
        "1e-9",
        r#"{"type": "slide", "rate_mm_s": 1, "distance_mm": 1000}"#,
    );
    let e = long.rows().unwrap_err();
    assert!(e.message.contains("1000000000001 rows"), "{e}");
    assert!(e.location.contains("dt_s"), "{e}");
    // Billions of cycles are counted, not looped over.
    let cycles = sc(
        "1",
        r#"{"type": "cycles", "amplitude_mm": 1, "rate_mm_s": 0.5, "count": 4294967295}"#,
    );
    assert_eq!(cycles.row_count().unwrap(), 1.0 + 8.0 * 4294967295.0);
    assert!(cycles.rows().is_err());
    let pulses = sc("1", r#"{"type": "hold", "duration_s": 1}"#);
    assert_eq!(pulses.row_count().unwrap(), 2.0);
    assert!(t0.elapsed() < Duration::from_secs(5));
    // The count is exact: it is the number of rows generated.
    let shear: Scenario = serde_json::from_str(
        r#"{"name": "p", "control": "shear", "normal_stress_kpa": 100, "dt_s": 0.7, "stages": [
            {"type": "shear-ramp", "to_kpa": 20, "rate_kpa_s": 1},
            {"type": "pulsating", "max_kpa": 40, "period_s": 9, "count": 3},
            {"type": "shear-cycles", "amplitude_kpa": 30, "period_s": 10, "count": 2}]}"#,
    )
    .unwrap();
    let n = shear.row_count().unwrap();
    assert_eq!(shear.rows().unwrap().time.len() as f64, n);
    assert!(shear.rows_with_limit(n as usize - 1).is_err());
}
