//! One sliding rate determines μ_s, ũ, the steady friction μ_ss and the decay rate
//! λ = κ + ξ/v, and leaves the recovery share ψ flat (the paper's remark that κ and ξ cannot
//! both be found from one rate). What the flat ψ leaves of each parameter follows from the
//! chart, whichever point of the valley the optimiser ends at: μ_k ∈ [0, μ_ss] and
//! ξ ∈ [0, (μ_ss/μ_s) λ v] only from above (the box, not the data, stops them at 0 through ψ's
//! lower wall), κ ∈ [(1 − μ_ss/μ_s) λ, λ] closed (μ_k ≥ 0 and ξ ≥ 0 bound it).

use subfric_fit::{calibrate, FitOptions, Param, Space, Status};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::FitTest;

#[test]
fn a_single_rate_bounds_kappa_xi_and_mu_k_as_the_chart_says() {
    let truth = Model::base(Params::sample()).unwrap();
    let time: Vec<f64> = (0..=400).map(|i| i as f64).collect();
    let slip: Vec<f64> = time.iter().map(|t| 0.005 * t).collect();
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let clean = simulate(&truth, &proto).unwrap().shear;
    // A deterministic scatter of 0.3 % of the peak.
    let peak = clean.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let shear: Vec<f64> = clean
        .iter()
        .enumerate()
        .map(|(i, v)| v + 0.003 * peak * (1.7 * i as f64).sin())
        .collect();
    let test = FitTest::new("monotonic", Control::Slip, time, slip, shear, normal);
    let space = Space::with_rate(truth, &Param::BASE, &[], 0.005);
    let opts = FitOptions {
        global_evaluations: 1000,
        starts: 3,
        ..FitOptions::default()
    };
    let r = calibrate(&[test], space, &opts, &|_| {}).unwrap();
    assert!(r.reduced_chi2 < 1.5, "misfit {}", r.reduced_chi2);
    let status = |k: &str| r.param(k).unwrap().status;
    let interval = |k: &str| r.param(k).unwrap().interval.unwrap();
    assert_eq!(status("mu_s"), Status::Determined);
    let psi = r
        .combinations
        .iter()
        .find(|c| c.name.starts_with("recovery"))
        .unwrap();
    let psi = psi.interval.unwrap();
    assert!(psi.lo_open && psi.hi_open, "ψ should be flat: {psi:?}");
    assert_eq!(
        status("mu_k"),
        Status::UpperBoundOnly,
        "{:?}",
        interval("mu_k")
    );
    assert_eq!(status("xi"), Status::UpperBoundOnly, "{:?}", interval("xi"));
    let kappa = interval("kappa");
    assert!(kappa.is_closed(), "κ is bounded on both sides: {kappa:?}");
    for key in ["mu_k", "kappa", "xi"] {
        assert_ne!(status(key), Status::Determined, "{key}");
    }
}
