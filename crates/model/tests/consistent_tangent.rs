//! The consistent tangent of the 3-D slip step (`Contact3::step_slip_with_tangent`) against
//! finite differences of `step_slip` itself: elastic steps, plastic loading, plastic steps after
//! a reversal (collinear, and a sharp turn whose elastic path passes beside the origin), on a
//! circle on a tilted plane, with and without extensions.

use subfric_model::{
    Contact3, Extensions, Model, Params, RateEffect, RateForm, State3, TermEffect, Terms, Vec3,
};

/// Acceptance: ‖K − K_fd‖/‖K‖ (Frobenius) and the same for ∂f_t/∂p.
const TOLERANCE: f64 = 1e-6;

fn add(a: &Vec3, s: f64, b: &Vec3) -> Vec3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

fn norm(a: &Vec3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// Which branch a step from `st` took: a plastic step accumulates plastic slip.
fn plastic(st: &State3, next: &State3) -> bool {
    next.slip_path > st.slip_path
}

/// Fourth-order central difference of the end-of-step shear, `step(m)` being the step with its
/// input moved by m·delta; `None` if a perturbed step changes branch (the tangent is one-sided
/// there).
fn fd4(
    st: &State3,
    step: impl Fn(f64) -> Option<State3>,
    delta: f64,
    branch: bool,
) -> Option<Vec3> {
    let mut f = [[0.0; 3]; 4];
    for (k, m) in [-2.0, -1.0, 1.0, 2.0].iter().enumerate() {
        let next = step(*m)?;
        if plastic(st, &next) != branch {
            return None;
        }
        f[k] = next.shear;
    }
    Some(std::array::from_fn(|i| {
        (f[0][i] - 8.0 * f[1][i] + 8.0 * f[2][i] - f[3][i]) / (12.0 * delta)
    }))
}

#[derive(Default, Debug)]
struct Tally {
    elastic: usize,
    plastic: usize,
    skipped: usize,
    worst_slip: f64,
    worst_pressure: f64,
}

/// Steps through `slips` (total slip after each step) and checks every step's tangent.
fn check_path(c: &Contact3, st0: State3, slips: &[Vec3], p: f64, dts: &[f64]) -> (Tally, State3) {
    let mut st = st0;
    let mut tally = Tally::default();
    for (slip, &dt) in slips.iter().zip(dts) {
        let (next, tan) = c.step_slip_with_tangent(&st, slip, p, dt).unwrap();
        assert_eq!(
            next,
            c.step_slip(&st, slip, p, dt).unwrap(),
            "the state is step_slip's"
        );
        // Every state the model writes passes the check of a state handed back to it.
        c.check_state(&next)
            .unwrap_or_else(|e| panic!("the model's own state is refused: {e}"));
        let branch = plastic(&st, &next);
        let du = norm(&add(slip, -1.0, &st.slip));
        // A perturbation small against the step (the tangent varies on the scale of the step)
        // and large against the round-off of the slip (α ulp(u) in the traction).
        let delta = if du > 0.0 { 0.005 * du } else { 1e-9 };
        // Columns of ∂f_t/∂u, then ∂f_t/∂p.
        let columns: Vec<Option<Vec3>> = (0..3)
            .map(|j| {
                let e: Vec3 = std::array::from_fn(|i| f64::from(u8::from(i == j)));
                let step = |m: f64| c.step_slip(&st, &add(slip, m * delta, &e), p, dt).ok();
                fd4(&st, step, delta, branch)
            })
            .collect();
        let dp = fd4(
            &st,
            |m| c.step_slip(&st, slip, p + m * 1e-3 * p, dt).ok(),
            1e-3 * p,
            branch,
        );
        if columns.iter().any(Option::is_none) || dp.is_none() {
            tally.skipped += 1;
            st = next;
            continue;
        }
        let fd: Vec<Vec3> = columns.into_iter().map(Option::unwrap).collect();
        // fd[j][i] = ∂f_i/∂u_j.
        let (mut err, mut size) = (0.0, 0.0);
        for (j, col) in fd.iter().enumerate() {
            for (i, x) in col.iter().enumerate() {
                err += (tan.d_slip[i][j] - x).powi(2);
                size += tan.d_slip[i][j].powi(2);
            }
        }
        let rel = (err / size).sqrt();
        let dp = dp.unwrap();
        let dp_err = norm(&add(&tan.d_pressure, -1.0, &dp));
        let rel_p = if branch {
            dp_err / norm(&tan.d_pressure)
        } else {
            assert_eq!(tan.d_pressure, [0.0; 3]);
            assert_eq!(tan.plastic_slip, [0.0; 3]);
            dp_err
        };
        assert!(
            rel <= TOLERANCE && rel_p <= TOLERANCE,
            "step {}: slip tangent rel. error {rel:.2e}, pressure {rel_p:.2e}\n{:?}\n{:?}",
            tally.elastic + tally.plastic + tally.skipped,
            tan.d_slip,
            fd
        );
        if branch {
            tally.plastic += 1;
            let lam = norm(&tan.plastic_slip);
            assert!((lam - (next.slip_path - st.slip_path)).abs() <= 1e-9 * (1.0 + lam));
        } else {
            tally.elastic += 1;
        }
        tally.worst_slip = tally.worst_slip.max(rel);
        tally.worst_pressure = tally.worst_pressure.max(rel_p);
        st = next;
    }
    (tally, st)
}

/// A two-way cycle along `dir`: `n` steps per quarter of amplitude `amp`, and at each reversal
/// `elastic` steps of `unload`, small enough to unload elastically.
fn two_way(dir: &Vec3, amp: f64, n: usize, elastic: usize, unload: f64) -> Vec<Vec3> {
    let mut u = Vec::new();
    let mut x = 0.0;
    let du = amp / n as f64;
    for (sign, count, small) in [(1.0, n, 0), (-1.0, 2 * n, elastic), (1.0, 2 * n, elastic)] {
        for k in 0..count {
            x += sign * if k < small { unload } else { du };
            u.push([x * dir[0], x * dir[1], x * dir[2]]);
        }
    }
    u
}

fn circle(normal: &Vec3, radius: f64, per_turn: usize, turns: usize) -> Vec<Vec3> {
    let l = norm(normal);
    let n = [normal[0] / l, normal[1] / l, normal[2] / l];
    // Two unit vectors in the plane.
    let a = {
        let t = add(&[1.0, 0.0, 0.0], -n[0], &n);
        let tl = norm(&t);
        [t[0] / tl, t[1] / tl, t[2] / tl]
    };
    let b = [
        n[1] * a[2] - n[2] * a[1],
        n[2] * a[0] - n[0] * a[2],
        n[0] * a[1] - n[1] * a[0],
    ];
    (1..=per_turn * turns)
        .map(|k| {
            let phi = 2.0 * std::f64::consts::PI * k as f64 / per_turn as f64;
            // Starts at the centre's edge: u(0) = 0.
            add(
                &add(&[0.0; 3], radius * phi.sin(), &a),
                radius * (1.0 - phi.cos()),
                &b,
            )
        })
        .collect()
}

fn penalty_params() -> Params {
    // A finite-element penalty stiffness: 1 kN/mm³ = 10⁶ kPa/mm.
    Params {
        alpha_t: 1.0,
        alpha_n: 1.0,
        ..Params::sample()
    }
}

fn rate_and_state() -> Extensions {
    Extensions::default().with_rate(RateEffect {
        form: RateForm::StateAgeing,
        a: 0.01,
        v_c: 1e-6,
        b: 0.008,
        d_c: 0.02,
        n: 0.0,
        v_ref: 0.001,
        at_rest: subfric_model::AtRest::Creep,
    })
}

#[test]
fn two_way_cycle_base_model_paper_stiffness() {
    let m = Model::base(Params::sample()).unwrap();
    let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    // α = 10⁹ kPa/mm: 45 kPa unload elastically within 4.5e-8 mm.
    let u = two_way(&[0.6, 0.8, 0.0], 0.5, 50, 3, 1e-8);
    let dts = vec![1.0; u.len()];
    let (t, _) = check_path(&c, State3::virgin(&m, [0.0; 3]), &u, 100.0, &dts);
    eprintln!("base, paper stiffness: {t:?}");
    assert!(
        t.elastic >= 6 && t.plastic >= 240 && t.skipped == 0,
        "{t:?}"
    );
}

/// The ageing law read as locked at rest: the rate terms of the last slide hold while the
/// contact rests.
fn locked_rate_and_state() -> Extensions {
    let ext = rate_and_state();
    let mut law = ext.rate().expect("rate and state");
    law.at_rest = subfric_model::AtRest::Locked;
    ext.with_rate(law)
}

#[test]
fn two_way_cycle_penalty_stiffness_with_and_without_rate_and_state() {
    for ext in [Extensions::default(), rate_and_state()] {
        let m = Model::new(penalty_params(), ext).unwrap();
        let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let u = two_way(&[1.0, 0.0, 0.0], 0.5, 50, 4, 1e-5);
        let dts = vec![0.5; u.len()];
        let (t, _) = check_path(&c, State3::virgin(&m, [0.0; 3]), &u, 150.0, &dts);
        eprintln!("penalty, rate {:?}: {t:?}", ext.rate().is_some());
        // Under rate and state some of the small unloading steps creep (the surface at rest
        // is lower than while sliding).
        let elastic = if ext.rate().is_some() { 4 } else { 8 };
        assert!(
            t.elastic >= elastic && t.plastic >= 240 && t.skipped == 0,
            "{t:?}"
        );
    }
}

#[test]
fn circle_on_a_tilted_plane_with_and_without_rate_and_state() {
    let normal = [0.3, -0.2, 0.9];
    for (params, ext) in [
        (Params::sample(), Extensions::default()),
        (penalty_params(), Extensions::default()),
        (penalty_params(), rate_and_state()),
        (penalty_params(), locked_rate_and_state()),
    ] {
        let m = Model::new(params, ext).unwrap();
        let c = Contact3::new(&m, normal, [1.0, 0.0, 0.0]);
        let u = circle(&normal, 1.0, 100, 2);
        let dts = vec![2.0; u.len()];
        let (t, _) = check_path(&c, State3::virgin(&m, [0.0; 3]), &u, 100.0, &dts);
        eprintln!("circle α_t {}: {t:?}", params.alpha_t);
        assert!(t.plastic == 200 && t.skipped == 0, "{t:?}");
    }
}

#[test]
fn sharp_turn_restarts_from_the_closest_point_beside_the_origin() {
    // After sliding along x, a step back and sideways whose elastic path passes at a distance
    // from the origin: the step restarts from r₀ = |f_min|/(μ p) < r, which depends on the
    // step, and the tangent must carry that dependence.
    for ext in [Extensions::default(), rate_and_state()] {
        let m = Model::new(penalty_params(), ext).unwrap();
        let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let mut st = State3::virgin(&m, [0.0; 3]);
        for k in 1..=20 {
            st = c
                .step_slip(&st, &[0.01 * k as f64, 0.0, 0.0], 100.0, 1.0)
                .unwrap();
        }
        let f = st.shear[0];
        let turn = [st.slip[0] - 1.6 * f / 1e6, 0.6 * f / 1e6, 0.0];
        let (t, next) = check_path(&c, st, &[turn], 100.0, &[1.0]);
        eprintln!("sharp turn: {t:?}, r {} -> {}", st.r, next.r);
        assert_eq!(t.plastic, 1, "{t:?}");
        // Without the r₀ term the tangent would be off by far more than the tolerance.
        let (_, tan) = c.step_slip_with_tangent(&st, &turn, 100.0, 1.0).unwrap();
        assert!(tan.d_slip[0][1].abs() > 1e-3 * tan.d_slip[1][1].abs());
    }
}

#[test]
fn direction_pressure_and_slip_extensions() {
    let exts = [
        Extensions {
            terms: Terms::one(TermEffect::named("direction", "friction", &[0.2]).unwrap())
                .with(TermEffect::named("pressure", "power-friction", &[0.1, 100.0]).unwrap()),
        },
        Extensions {
            terms: rate_and_state()
                .terms
                .with(TermEffect::named("direction", "mu-k", &[0.15]).unwrap())
                .with(TermEffect::named("slip-hardening", "hyperbolic", &[0.02, 0.5]).unwrap())
                .with(TermEffect::named("pressure", "exponential-mu-s", &[0.2, 100.0]).unwrap()),
        },
    ];
    for ext in exts {
        let m = Model::new(penalty_params(), ext).unwrap();
        let normal = [0.0, 0.0, 1.0];
        let c = Contact3::new(&m, normal, [1.0, 0.0, 0.0]);
        let u = circle(&normal, 0.5, 80, 2);
        let dts = vec![1.0; u.len()];
        let (t, st) = check_path(&c, State3::virgin(&m, [0.0; 3]), &u, 120.0, &dts);
        eprintln!("extensions, circle: {t:?}");
        assert!(t.plastic == 160 && t.skipped == 0, "{t:?}");
        let f = norm(&st.shear);
        let g = [st.shear[0] / f, st.shear[1] / f];
        let turn = [
            st.slip[0] - (1.6 * g[0] + 0.6 * g[1]) * f / 1e6,
            st.slip[1] - (1.6 * g[1] - 0.6 * g[0]) * f / 1e6,
            0.0,
        ];
        let (t, _) = check_path(&c, st, &[turn], 120.0, &[1.0]);
        eprintln!("extensions, sharp turn: {t:?}");
        assert_eq!(t.plastic, 1, "{t:?}");
    }
}

#[test]
fn a_reload_after_a_hold_under_healing_of_its_own() {
    // The gain of its own decays with the plastic slip inside the return: the tangent of the
    // reload's steps must carry that slope.
    let ext = Extensions {
        terms: subfric_model::Terms::one(
            subfric_model::TermEffect::named("healing", "log-erased", &[0.02, 1.0, 0.01]).unwrap(),
        ),
    };
    let m = Model::new(penalty_params(), ext).unwrap();
    let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let mut u: Vec<Vec3> = (1..=10).map(|k| [0.02 * k as f64, 0.0, 0.0]).collect();
    let mut dts = vec![1.0; u.len()];
    u.push([0.2, 0.0, 0.0]);
    dts.push(300.0);
    for k in 1..=20 {
        u.push([0.2 + 0.002 * k as f64, 0.0005 * k as f64, 0.0]);
        dts.push(1.0);
    }
    let (t, st) = check_path(&c, State3::virgin(&m, [0.0; 3]), &u, 100.0, &dts);
    assert!(t.plastic >= 25 && t.skipped == 0, "{t:?}");
    assert!(
        m.ext.terms.state_value(&st.slots, "healed").unwrap() > 0.0,
        "the slip since the hold leaves part of the gain"
    );
}

#[test]
fn elastic_steps_and_a_hold() {
    for ext in [Extensions::default(), rate_and_state()] {
        let m = Model::new(penalty_params(), ext).unwrap();
        let c = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let mut st = State3::virgin(&m, [0.0; 3]);
        for k in 1..=10 {
            st = c
                .step_slip(&st, &[0.02 * k as f64, 0.0, 0.0], 100.0, 1.0)
                .unwrap();
        }
        // Unloading by 10 kPa, a sideways step that stays inside the subloading surface (any
        // step beyond it slides), a hold.
        let s = st.slip;
        let u = [
            [s[0] - 5e-6, s[1], 0.0],
            [s[0] - 1e-5, s[1], 0.0],
            [s[0] - 1.2e-5, s[1] + 5e-6, 0.0],
            [s[0] - 1.2e-5, s[1] + 5e-6, 0.0],
        ];
        let (t, _) = check_path(&c, st, &u, 100.0, &[1.0, 1.0, 1.0, 100.0]);
        if ext.rate().is_none() {
            assert_eq!((t.elastic, t.plastic, t.skipped), (4, 0, 0), "{t:?}");
            let (_, tan) = c.step_slip_with_tangent(&st, &u[0], 100.0, 1.0).unwrap();
            let alpha = 1e6;
            assert_eq!(
                tan.d_slip,
                [[alpha, 0.0, 0.0], [0.0, alpha, 0.0], [0.0, 0.0, 0.0]]
            );
        } else {
            // At rest the rate-and-state surface drops below the traction: the contact creeps
            // and the hold is a plastic step (checked above all the same).
            assert_eq!(t.elastic + t.plastic, 4, "{t:?}");
            assert!(t.plastic >= 1, "{t:?}");
        }
    }
}
