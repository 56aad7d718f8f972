//! A calibration of a curve with a spike (one shear value fifty times the plateau, one row of
//! the normal stress at 1 kPa) runs to its end and reports (issue 13).

use subfric_fit::{calibrate, FitOptions, Param, Space};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::FitTest;

/// A slide at 0.01 mm/s from the sample parameters (peak, softening, plateau), a hold of
/// 200 s and a reload: every feature the guesses read.
fn slide_hold_slide() -> FitTest {
    let truth = Model::base(Params::sample()).unwrap();
    let mut time = Vec::new();
    let mut slip = Vec::new();
    for i in 0..=300 {
        time.push(i as f64);
        slip.push(0.01 * i as f64);
    }
    for i in 1..=200 {
        time.push(300.0 + i as f64);
        slip.push(3.0);
    }
    for i in 1..=100 {
        time.push(500.0 + i as f64);
        slip.push(3.0 + 0.01 * i as f64);
    }
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let shear = simulate(&truth, &proto).unwrap().shear;
    FitTest::new("shs", Control::Slip, time, slip, shear, normal)
}

#[test]
fn a_calibration_of_a_curve_with_a_spike_runs_to_the_end() {
    let mut t = slide_hold_slide();
    t.measured[150] *= 50.0;
    t.normal[200] = 1.0;
    let template = Model::base(Params::sample()).unwrap();
    let space = Space::with_rate(template, &Param::BASE, &[], 0.01);
    let opts = FitOptions {
        global_evaluations: 200,
        starts: 2,
        ..FitOptions::default()
    };
    let r = calibrate(&[t], space, &opts, &|_| {}).expect("a report, not a panic");
    assert!(r.ssr.is_finite());
}
