//! Steady state, convergence with the step size, traction control, 3-D and invalid input.

use subfric_model::contact3::Vec3;
use subfric_model::scenario::PlanarPath;
use subfric_model::{
    simulate, Contact1, Contact3, Control, Model, Params, Protocol, Scenario, SimError, Stage,
    State1, State3,
};

fn slide(params: Params, rate: f64, distance: f64, dt: f64) -> (Vec<f64>, Vec<f64>) {
    let sc = Scenario {
        name: "slide".into(),
        control: Control::Slip,
        normal_stress_kpa: 100.0,
        dt_s: dt,
        stages: vec![Stage::Slide {
            rate_mm_s: rate,
            distance_mm: distance,
        }],
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
    let out = simulate(&Model::base(params).unwrap(), &proto).unwrap();
    (out.shear, out.mu)
}

#[test]
fn steady_sliding_reaches_mu_ss() {
    let p = Params::sample();
    for &v in &[0.0005, 0.01, 0.2] {
        // Slide far enough for μ and r to settle (several 1/(κ + ξ/v)).
        let distance = 12.0 / (p.kappa + p.xi / v);
        let (shear, mu) = slide(p, v, distance, distance / v / 4000.0);
        let expected = p.steady_mu(v);
        let mu_end = *mu.last().unwrap();
        assert!(
            (mu_end - expected).abs() < 1e-4,
            "v={v}: μ={mu_end} expected {expected}"
        );
        let friction = shear.last().unwrap() / 100.0;
        assert!(
            (friction - expected).abs() < 2e-4,
            "v={v}: friction {friction} expected {expected}"
        );
    }
}

fn two_way(steps_per_quarter: usize) -> (Vec<f64>, Vec<f64>) {
    let rate = 0.01;
    let sc = Scenario {
        name: "two-way".into(),
        control: Control::Slip,
        normal_stress_kpa: 100.0,
        dt_s: 1.0 / rate / steps_per_quarter as f64,
        stages: vec![Stage::Cycles {
            amplitude_mm: 1.0,
            rate_mm_s: rate,
            count: 3,
        }],
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
    let out = simulate(&Model::base(Params::sample()).unwrap(), &proto).unwrap();
    (rows.time, out.shear.iter().map(|s| s / 100.0).collect())
}

/// Largest difference of friction at the coarse rows between a coarse and a fine run.
fn max_error(coarse: usize, fine: usize) -> f64 {
    let (tc, fc) = two_way(coarse);
    let (_, ff) = two_way(fine);
    let ratio = fine / coarse;
    (0..tc.len())
        .map(|i| (fc[i] - ff[i * ratio]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn two_way_cycles_converge_as_the_step_shrinks() {
    let reference = 6400;
    let errors: Vec<f64> = [25, 50, 100, 200]
        .iter()
        .map(|&n| max_error(n, reference))
        .collect();
    assert!(
        errors[0] <= 1e-3,
        "25 steps per quarter cycle: error {:.2e}",
        errors[0]
    );
    for w in errors.windows(2) {
        assert!(w[1] < w[0], "errors do not decrease: {errors:?}");
    }
}

#[test]
fn traction_above_capacity_is_runaway_at_its_row() {
    let p = Params::sample();
    let time: Vec<f64> = (0..200).map(|i| i as f64).collect();
    // Ramp the shear past μ_s f_n = 45 kPa.
    let shear: Vec<f64> = time.iter().map(|t| 0.5 * t).collect();
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Shear,
        time: &time,
        imposed: &shear,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    match simulate(&Model::base(p).unwrap(), &proto) {
        Err(SimError::Runaway {
            row, capacity_kpa, ..
        }) => {
            assert!(row > 60 && row <= 91, "row {row}");
            assert!(capacity_kpa <= 45.0 + 1e-9);
        }
        other => panic!("expected runaway, got {other:?}"),
    }
}

#[test]
fn invalid_parameters_are_reported_together_by_name() {
    let mut p = Params::sample();
    p.mu_k = 0.6;
    p.kappa = -1.0;
    p.alpha_t = 0.0;
    p.xi = f64::NAN;
    let err = Model::base(p).unwrap_err();
    let names: Vec<&str> = err.0.iter().map(|i| i.name).collect();
    assert_eq!(names, vec!["mu_k", "kappa", "xi", "alpha_t"]);
    let text = err.to_string();
    assert!(text.contains("mu_k = 0.6") && text.contains("expected"));
}

#[test]
fn non_increasing_time_is_an_input_error_with_its_row() {
    let time = [0.0, 1.0, 1.0];
    let slip = [0.0, 0.01, 0.02];
    let normal = [100.0; 3];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let err = simulate(&Model::base(Params::sample()).unwrap(), &proto).unwrap_err();
    assert!(
        matches!(
            err,
            SimError::Input {
                row: 2,
                field: "time_s",
                ..
            }
        ),
        "{err}"
    );
}

fn rotate(q: &[[f64; 3]; 3], v: &Vec3) -> Vec3 {
    [
        q[0][0] * v[0] + q[0][1] * v[1] + q[0][2] * v[2],
        q[1][0] * v[0] + q[1][1] * v[1] + q[1][2] * v[2],
        q[2][0] * v[0] + q[2][1] * v[1] + q[2][2] * v[2],
    ]
}

#[test]
fn collinear_3d_path_gives_the_1d_answer() {
    let model = Model::base(Params::sample()).unwrap();
    let sc = Scenario {
        name: "c".into(),
        control: Control::Slip,
        normal_stress_kpa: 100.0,
        dt_s: 2.0,
        stages: vec![Stage::Cycles {
            amplitude_mm: 1.0,
            rate_mm_s: 0.01,
            count: 2,
        }],
    };
    let rows = sc.rows().unwrap();
    let mut c1 = Contact1::new(&model);
    let c3 = Contact3::new(&model, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let dir = [0.6, 0.8, 0.0];
    let mut s1 = State1::virgin(&model, 0.0);
    let mut s3 = State3::virgin(&model, [0.0; 3]);
    for i in 1..rows.time.len() {
        let dt = rows.time[i] - rows.time[i - 1];
        let u = rows.imposed[i];
        s1 = c1.step_slip(&s1, u, 100.0, dt).unwrap();
        s3 = c3
            .step_slip(&s3, &[u * dir[0], u * dir[1], 0.0], 100.0, dt)
            .unwrap();
        let proj = s3.shear[0] * dir[0] + s3.shear[1] * dir[1];
        assert!(
            (proj - s1.shear).abs() < 1e-6 * (1.0 + s1.shear.abs()),
            "row {i}: {proj} vs {}",
            s1.shear
        );
        assert!((s3.mu - s1.mu).abs() < 1e-12 && (s3.r - s1.r).abs() < 1e-9);
    }
}

#[test]
fn circular_path_mobilises_friction_along_the_slip_direction() {
    let model = Model::base(Params::sample()).unwrap();
    let c3 = Contact3::new(&model, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let path =
        PlanarPath::Circle { radius_mm: 1.0 }.sample(400, 3, ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
    let mut s = State3::virgin(&model, [0.0; 3]);
    for w in path.windows(2) {
        s = c3.step_slip(&s, &w[1], 100.0, 1.0).unwrap();
    }
    // After sustained sliding the traction is tangent to the circle and near steady friction.
    let u = path.last().unwrap();
    let tangent = [-u[1], u[0], 0.0];
    let ft = (s.shear[0].powi(2) + s.shear[1].powi(2)).sqrt();
    let cos = (s.shear[0] * tangent[0] + s.shear[1] * tangent[1]) / ft;
    assert!(cos > 0.99, "cos {cos}");
    let v = 2.0 * std::f64::consts::PI / 400.0; // mm per 1 s step
    let mu_ss = model.params.steady_mu(v);
    assert!(
        (ft / 100.0 - mu_ss).abs() < 0.01,
        "{} vs {mu_ss}",
        ft / 100.0
    );
}

mod props {
    use super::*;
    use proptest::prelude::*;

    fn params() -> impl Strategy<Value = Params> {
        (
            0.2f64..1.2,
            0.1f64..0.95,
            0.1f64..50.0,
            1e-4f64..0.1,
            1.0f64..500.0,
            1.0f64..1e4,
        )
            .prop_map(|(mu_s, frac, kappa, xi, u_tilde, alpha)| Params {
                mu_s,
                mu_k: mu_s * frac,
                kappa,
                xi,
                u_tilde,
                alpha_t: alpha,
                alpha_n: alpha,
                mu_0: None,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn mu_and_r_stay_in_bounds(p in params(), moves in prop::collection::vec(-0.05f64..0.05, 50..200), dt in 0.01f64..20.0) {
            let model = Model::base(p).unwrap();
            let mut c = Contact1::new(&model);
            let mut s = State1::virgin(&model, 0.0);
            let mut u = 0.0;
            for m in moves {
                u += m;
                s = c.step_slip(&s, u, 100.0, dt).unwrap();
                prop_assert!(s.mu >= p.mu_k - 1e-12 && s.mu <= p.mu_s + 1e-12, "mu {}", s.mu);
                prop_assert!(s.r >= -1e-12 && s.r <= 1.0 + 1e-12, "r {}", s.r);
                prop_assert!(s.shear.abs() <= s.r * s.mu * 100.0 + 1e-6 * (1.0 + s.shear.abs()));
            }
        }

        #[test]
        fn elastic_closed_traction_cycle_dissipates_nothing(p in params(), amp in 0.01f64..0.2) {
            // Slide until μ has decayed well below μ_s, unload, then reload slowly enough that μ
            // recovers: the reload stays inside the subloading surface, so the whole closed
            // traction cycle is elastic and must return the slip and dissipate no work.
            prop_assume!(p.mu_k <= 0.7 * p.mu_s);
            let model = Model::base(p).unwrap();
            let mut c = Contact1::new(&model);
            let mut s = State1::virgin(&model, 0.0);
            let v = 100.0 * p.xi / p.kappa;
            let distance = 8.0 / p.kappa;
            for j in 1..=400 {
                s = c.step_slip(&s, distance * j as f64 / 400.0, 100.0, distance / v / 400.0).unwrap();
            }
            let start = s;
            let top = s.shear;
            let mut work = 0.0;
            let mut all_elastic = true;
            for (f, dt) in [(top * (1.0 - amp), 1.0), (top, 50.0 / p.xi)] {
                let next = c.step_shear(&s, f, 100.0, dt).unwrap();
                work += 0.5 * (next.shear + s.shear) * (next.slip - s.slip);
                all_elastic &= next.last_plastic == 0.0;
                s = next;
            }
            prop_assert!(all_elastic);
            prop_assert!((s.slip - start.slip).abs() < 1e-12 * (1.0 + start.slip.abs()));
            prop_assert!(work.abs() < 1e-9);
        }

        #[test]
        fn rotating_the_3d_input_rotates_the_output(p in params(), a in 0.0f64..std::f64::consts::TAU, b in 0.0f64..std::f64::consts::PI) {
            let model = Model::base(p).unwrap();
            let (ca, sa, cb, sb) = (a.cos(), a.sin(), b.cos(), b.sin());
            // Rotation about z by a, then about x by b.
            let rz = [[ca, -sa, 0.0], [sa, ca, 0.0], [0.0, 0.0, 1.0]];
            let rx = [[1.0, 0.0, 0.0], [0.0, cb, -sb], [0.0, sb, cb]];
            let q = |v: &Vec3| rotate(&rx, &rotate(&rz, v));
            let path = PlanarPath::FigureEight { amplitude_mm: 0.5 }.sample(60, 1, ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
            let c = Contact3::new(&model, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
            let cr = Contact3::new(&model, q(&[0.0, 0.0, 1.0]), q(&[1.0, 0.0, 0.0]));
            let mut s = State3::virgin(&model, [0.0; 3]);
            let mut sr = State3::virgin(&model, [0.0; 3]);
            for w in path.windows(2) {
                s = c.step_slip(&s, &w[1], 80.0, 1.0).unwrap();
                sr = cr.step_slip(&sr, &q(&w[1]), 80.0, 1.0).unwrap();
                let expect = q(&s.shear);
                for ((got, want), orig) in sr.shear.iter().zip(&expect).zip(&s.shear) {
                    prop_assert!((got - want).abs() < 1e-6 * (1.0 + orig.abs()));
                }
                prop_assert!((sr.mu - s.mu).abs() < 1e-9);
            }
        }
    }
}
