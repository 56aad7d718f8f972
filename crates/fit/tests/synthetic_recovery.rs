//! A synthetic campaign whose true parameters are known and where all five are determined
//! (several rates, holds, cycles): the fit recovers them within 2 %.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use subfric_fit::{calibrate, FitOptions, Method, Param, Space, Status};
use subfric_model::{simulate, Control, Model, Params, Protocol, Scenario, Stage};
use subfric_reading::{typical_rate, FitTest};

fn truth() -> Model {
    Model::base(Params {
        mu_s: 0.62,
        mu_k: 0.41,
        kappa: 2.2,
        xi: 0.004,
        u_tilde: 18.0,
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: None,
    })
    .unwrap()
}

fn campaign(model: &Model, seed: u64) -> Vec<FitTest> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let scenarios = [
        (
            "velocity-steps",
            100.0,
            vec![
                Stage::Slide {
                    rate_mm_s: 0.01,
                    distance_mm: 2.0,
                },
                Stage::Slide {
                    rate_mm_s: 0.1,
                    distance_mm: 1.0,
                },
                Stage::Slide {
                    rate_mm_s: 0.01,
                    distance_mm: 0.8,
                },
                Stage::Slide {
                    rate_mm_s: 0.001,
                    distance_mm: 0.5,
                },
            ],
        ),
        (
            "slide-hold-slide",
            100.0,
            vec![
                Stage::Slide {
                    rate_mm_s: 0.01,
                    distance_mm: 2.0,
                },
                Stage::Hold { duration_s: 100.0 },
                Stage::Slide {
                    rate_mm_s: 0.01,
                    distance_mm: 0.6,
                },
                Stage::Hold { duration_s: 1000.0 },
                Stage::Slide {
                    rate_mm_s: 0.01,
                    distance_mm: 0.6,
                },
            ],
        ),
        (
            "two-way",
            200.0,
            vec![Stage::Cycles {
                amplitude_mm: 1.0,
                rate_mm_s: 0.01,
                count: 2,
            }],
        ),
    ];
    scenarios
        .into_iter()
        .map(|(name, normal, stages)| {
            let sc = Scenario {
                name: name.into(),
                control: Control::Slip,
                normal_stress_kpa: normal,
                dt_s: 1.0,
                stages,
            };
            let rows = sc.rows().unwrap();
            let proto = Protocol {
                control: Control::Slip,
                time: &rows.time,
                imposed: &rows.imposed,
                normal: &rows.normal,
                initial_slip: 0.0,
                initial: Default::default(),
            };
            let clean = simulate(model, &proto).unwrap().shear;
            // 0.2 % of the peak shear as noise.
            let sd = 0.002 * clean.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let noisy = clean
                .iter()
                .map(|v| v + sd * (rng.gen::<f64>() - 0.5) * 12f64.sqrt())
                .collect();
            FitTest::new(
                name,
                Control::Slip,
                rows.time,
                rows.imposed,
                noisy,
                rows.normal,
            )
        })
        .collect()
}

#[test]
fn all_five_parameters_are_recovered_within_two_percent() {
    let truth = truth();
    let tests = campaign(&truth, 11);
    let template = Model::base(Params::sample()).unwrap();
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let r = calibrate(&tests, space, &FitOptions::default(), &|_| {}).unwrap();
    assert!(r.reduced_chi2 < 1.2, "misfit {}", r.reduced_chi2);
    for (key, value) in [
        ("mu_s", truth.params.mu_s),
        ("mu_k", truth.params.mu_k),
        ("kappa", truth.params.kappa),
        ("xi", truth.params.xi),
        ("u_tilde", truth.params.u_tilde),
    ] {
        let p = r.param(key).unwrap();
        assert_eq!(
            p.status,
            Status::Determined,
            "{key} should be determined: {p:?}"
        );
        assert!(
            (p.value - value).abs() / value < 0.02,
            "{key}: {} vs {value}",
            p.value
        );
        let (lo, hi) = p.interval.map(|i| (i.lo, i.hi)).unwrap();
        assert!(
            lo <= value && value <= hi,
            "{key}: {value} outside [{lo}, {hi}]"
        );
    }
    assert!(
        r.optimizer.starts_at_best >= 2,
        "independent starts should agree: {:?}",
        r.optimizer.start_ssr
    );
}

#[test]
fn the_same_seed_gives_the_same_fit() {
    let tests = campaign(&truth(), 3);
    let template = Model::base(Params::sample()).unwrap();
    let opts = FitOptions {
        profiles: false,
        ..FitOptions::default()
    };
    let run = || {
        let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
        calibrate(&tests, space, &opts, &|_| {}).unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a.model, b.model);
    assert_eq!(a.optimizer.start_ssr, b.optimizer.start_ssr);
}

#[test]
fn nelder_mead_reaches_the_noise_level_too() {
    let tests = campaign(&truth(), 5);
    let template = Model::base(Params::sample()).unwrap();
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let opts = FitOptions {
        method: Method::NelderMead,
        profiles: false,
        starts: 4,
        ..FitOptions::default()
    };
    let r = calibrate(&tests, space, &opts, &|_| {}).unwrap();
    assert!(
        r.reduced_chi2 < 1.3,
        "Nelder–Mead misfit {}",
        r.reduced_chi2
    );
}
