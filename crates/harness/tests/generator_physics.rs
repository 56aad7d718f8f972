//! The generator's forward model checked on its own terms: against the model crate's base model
//! (the one bridge between the two, and only here), against halved substeps, and against
//! closed-form results of rate and state, ageing, a compliant rig and a seating toe.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use subfric_harness::generator::effects::{
    Effects, HealShape, Healing, Rate, RateForm, Reading, StateLaw,
};
use subfric_harness::generator::forward::{Base, Contact, Rig, Toe};
use subfric_harness::generator::path::{run, Run, Sampling, Segment};
use subfric_model::{simulate, Control, Initial, Model, Params, Protocol};

fn base(mu_s: f64, mu_k: f64, kappa: f64, xi: f64, u_tilde: f64, alpha_t: f64) -> Base {
    Base {
        mu_s,
        mu_k,
        kappa,
        xi,
        u_tilde,
        alpha_t,
    }
}

fn drive(b: Base, fx: Effects, rig: Rig, segs: &[Segment], p: f64, s: Sampling, acc: f64) -> Run {
    let mut c = Contact::new(b, fx, rig, p, acc);
    run(&mut c, segs, p, &s, 0.0, &mut ChaCha8Rng::seed_from_u64(0)).expect("the run resolves")
}

fn slide(rate: f64, distance: f64) -> Segment {
    Segment::Slide { rate, distance }
}

fn hold(duration: f64) -> Segment {
    Segment::Hold { duration }
}

/// The model crate's base model on the generator's rows (slip control).
fn model_shear(b: Base, r: &Run) -> Vec<f64> {
    let params = Params {
        mu_s: b.mu_s,
        mu_k: b.mu_k,
        kappa: b.kappa,
        xi: b.xi,
        u_tilde: b.u_tilde,
        alpha_t: b.alpha_t,
        alpha_n: b.alpha_t,
        mu_0: None,
    };
    let model = Model::base(params).expect("valid parameters");
    let proto = Protocol {
        control: Control::Slip,
        time: &r.t,
        imposed: &r.u,
        normal: &r.p,
        initial_slip: 0.0,
        initial: Initial::Rest,
    };
    simulate(&model, &proto).expect("the model runs").shear
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn fine(dt: f64) -> Sampling {
    Sampling::Uniform { dt }
}

#[test]
fn the_base_model_matches_the_model_crate_on_the_papers_protocols() {
    // Parameters of Table 2 (ring torsion), Table 4 (two-way cycles) and a sand–steel set, on a
    // monotonic test, slide–hold–slide with velocity steps, and two-way cycles. The model crate
    // takes one implicit step per row; the rows are fine enough that both resolve the curves.
    let cases = [
        (
            base(0.33, 0.17, 0.59, 0.003, 12.0, 10000.0),
            vec![slide(0.01, 4.0)],
            105.0,
        ),
        (
            base(1.1, 0.5, 1.2, 0.00091, 2.0, 50000.0),
            vec![
                slide(0.02, 1.5),
                slide(0.02, -3.0),
                slide(0.02, 3.0),
                slide(0.02, -3.0),
            ],
            98.0,
        ),
        (
            base(0.55, 0.40, 2.0, 0.004, 20.0, 1000.0),
            vec![
                slide(0.01, 1.5),
                hold(100.0),
                slide(0.01, 0.5),
                slide(0.1, 0.5),
                slide(0.001, 0.3),
                hold(1000.0),
                slide(0.01, 0.6),
            ],
            150.0,
        ),
    ];
    for (k, (b, segs, p)) in cases.into_iter().enumerate() {
        let r = drive(
            b,
            Effects::default(),
            Rig::default(),
            &segs,
            p,
            fine(0.1),
            1.0,
        );
        let model = model_shear(b, &r);
        let peak = r.f.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
        let worst = max_abs_diff(&r.f, &model);
        eprintln!(
            "case {k}: {} rows, peak {peak:.2} kPa, largest difference {worst:.4} kPa",
            r.t.len()
        );
        assert!(
            worst < 0.003 * peak,
            "case {k}: the generator and the model crate differ by {worst} kPa (peak {peak})"
        );
    }
}

fn rsf(law: StateLaw, a: f64, b: f64, dc: f64, v_star: f64, reading: Reading) -> Effects {
    Effects {
        rate: Some(Rate {
            form: RateForm::State { law, a, b, dc },
            v_star,
            v_min: 1e-9,
            reading,
        }),
        ..Effects::default()
    }
}

/// A base that is rate-neutral (no time recovery) and on its residual after 3 mm.
fn neutral() -> Base {
    base(0.6, 0.45, 5.0, 1e-12, 3000.0, 1000.0)
}

/// The shear just before `t` (the last row at or before it).
fn shear_at(r: &Run, t: f64) -> f64 {
    let i = r.t.iter().rposition(|&x| x <= t).expect("a row before");
    r.f[i]
}

#[test]
fn a_rigid_velocity_step_jumps_by_a_ln_ratio_and_settles_at_a_minus_b_ln_ratio() {
    let (a, b, dc, p, v0) = (0.008, 0.012, 0.02, 100.0, 0.01);
    for (law, reading) in [
        (StateLaw::Ageing, Reading::Locked),
        (StateLaw::Slip, Reading::Locked),
        (StateLaw::Ageing, Reading::Creep),
        (StateLaw::Slip, Reading::Creep),
    ] {
        for ratio in [10.0, 0.1] {
            let v1 = v0 * ratio;
            let segs = [slide(v0, 3.0), slide(v1, 1.0)];
            let s = Sampling::RateAdaptive {
                slip_per_row: 0.00005,
                min_dt: 1e-4,
                max_dt: 10.0,
                min_hold_dt: 1.0,
                hold_growth: 1.5,
            };
            let r = drive(
                neutral(),
                rsf(law, a, b, dc, v0, reading),
                Rig::default(),
                &segs,
                p,
                s,
                1.0,
            );
            let t_step = 3.0 / v0;
            let before = shear_at(&r, t_step);
            // The direct effect, at the first row after the step (0.0025 D_c on).
            let first =
                r.t.iter()
                    .position(|&t| t > t_step + 1e-9)
                    .expect("rows after");
            let jump = r.f[first] - before;
            let settled = r.f[r.f.len() - 1] - before;
            let (want_jump, want_settled) = (a * ratio.ln() * p, (a - b) * ratio.ln() * p);
            eprintln!("{law:?} {reading:?} x{ratio}: jump {jump:.4} (want {want_jump:.4}), settled {settled:.4} (want {want_settled:.4})");
            assert!(
                (jump - want_jump).abs() < 0.03 * want_jump.abs(),
                "{law:?} {reading:?} x{ratio}: jump {jump} kPa, expected a ln(v1/v0) p = {want_jump}"
            );
            assert!(
                (settled - want_settled).abs() < 0.02 * want_settled.abs(),
                "{law:?} {reading:?} x{ratio}: settled {settled} kPa, expected (a - b) ln(v1/v0) p = {want_settled}"
            );
        }
    }
}

/// The largest shear after `t` within `slip` mm of reloading at `v`.
fn peak_after(r: &Run, t: f64, v: f64, slip: f64) -> f64 {
    r.t.iter()
        .zip(&r.f)
        .filter(|(x, _)| **x > t && (**x - t) * v <= slip)
        .map(|(_, f)| *f)
        .fold(f64::MIN, f64::max)
}

#[test]
fn the_ageing_laws_reloading_peak_grows_by_b_ln10_per_decade_of_hold() {
    // Locked reading, rigid rig, holds of 10, 100, 1000 and 10 000 s at v0 D_c⁻¹ = 1 s⁻¹: the
    // peak over the steady shear is b ln(1 + t_h v0/D_c) p, so it grows by b ln(10) p per
    // decade once t_h v0 ≫ D_c.
    let (a, b, dc, p, v0) = (0.006, 0.01, 0.01, 200.0, 0.01);
    let holds = [10.0, 100.0, 1000.0, 10_000.0];
    let mut segs = vec![slide(v0, 3.0)];
    for h in holds {
        segs.push(hold(h));
        segs.push(slide(v0, 0.3));
    }
    let s = Sampling::RateAdaptive {
        slip_per_row: 0.00005,
        min_dt: 1e-3,
        max_dt: 50.0,
        min_hold_dt: 1.0,
        hold_growth: 1.5,
    };
    let fx = rsf(StateLaw::Ageing, a, b, dc, v0, Reading::Locked);
    let r = drive(neutral(), fx, Rig::default(), &segs, p, s, 1.0);
    let mut t = 3.0 / v0;
    let mut peaks = Vec::new();
    for h in holds {
        let steady = shear_at(&r, t);
        t += h;
        peaks.push(peak_after(&r, t, v0, 0.1) - steady);
        t += 0.3 / v0;
    }
    let per_decade = b * 10f64.ln() * p;
    for (k, w) in peaks.windows(2).enumerate() {
        let grew = w[1] - w[0];
        eprintln!("decade {k}: peak grew {grew:.3} kPa (b ln10 p = {per_decade:.3})");
        assert!(
            (grew - per_decade).abs() < 0.06 * per_decade,
            "decade {k}: the peak grew by {grew} kPa, expected about b ln(10) p = {per_decade}"
        );
    }
    // The slip law does not heal in stationary contact: no peak after a hold.
    let fx = rsf(StateLaw::Slip, a, b, dc, v0, Reading::Locked);
    let r = drive(neutral(), fx, Rig::default(), &segs, p, s, 1.0);
    let t = 3.0 / v0 + 10.0 + 0.3 / v0 + 100.0;
    let rise = peak_after(&r, t, v0, 0.1) - shear_at(&r, t);
    assert!(
        rise.abs() < 0.02 * per_decade,
        "slip law healed by {rise} kPa at rest"
    );
}

#[test]
fn a_compliant_rig_loads_with_the_series_stiffness() {
    // α_t = 0.02 kN/mm³ (an interface as soft as in some of the paper's fits) in series with a
    // machine of 0.005 kN/mm³: the first loading rises at 1/(1/k_m + 1/α) = 4000 kPa/mm.
    let b = base(0.55, 0.40, 2.0, 0.004, 20.0, 0.02);
    let rig = Rig {
        machine_kn_mm3: Some(0.005),
        toe: None,
    };
    let r = drive(
        b,
        Effects::default(),
        rig,
        &[slide(0.01, 1.0)],
        100.0,
        fine(0.0001),
        1.0,
    );
    let series = 1e6 / (1.0 / 0.005 + 1.0 / 0.02);
    // The tangent at the first rows, where r ≈ 0 and the plastic slip rate vanishes.
    let slope = (r.f[5] - r.f[0]) / (r.u[5] - r.u[0]);
    assert!(
        (slope / series - 1.0).abs() < 0.01,
        "loading slope {slope} kPa/mm, series stiffness {series}"
    );
    // The recorded displacement at the peak holds the elastic part f/k of both springs.
    let rigid = drive(
        b,
        Effects::default(),
        Rig::default(),
        &[slide(0.01, 1.0)],
        100.0,
        fine(0.0001),
        1.0,
    );
    let peak = r.f.iter().cloned().fold(0.0, f64::max);
    let i = r.f.iter().position(|f| *f >= 0.8 * peak).unwrap();
    let j = rigid.f.iter().position(|f| *f >= r.f[i]).unwrap();
    let shift = r.u[i] - rigid.u[j];
    let elastic = r.f[i] * 1e-6 / 0.005;
    assert!(
        (shift / elastic - 1.0).abs() < 0.05,
        "shift {shift} mm, machine's f/k_m {elastic} mm"
    );
}

#[test]
fn a_seating_toe_keeps_the_shear_low_over_its_travel() {
    let b = base(0.55, 0.40, 2.0, 0.004, 20.0, 1000.0);
    let p = 200.0;
    let gap = 0.3;
    let rig = Rig {
        machine_kn_mm3: None,
        toe: Some(Toe {
            gap_mm: gap,
            force_kpa: 0.005 * b.mu_s * p,
        }),
    };
    let r = drive(
        b,
        Effects::default(),
        rig,
        &[slide(0.01, 3.0)],
        p,
        fine(0.2),
        1.0,
    );
    let peak = r.f.iter().cloned().fold(0.0, f64::max);
    let in_toe: Vec<f64> =
        r.u.iter()
            .zip(&r.f)
            .filter(|(u, _)| **u <= 0.9 * gap)
            .map(|(_, f)| *f)
            .collect();
    let top = in_toe.iter().cloned().fold(0.0, f64::max);
    assert!(in_toe.len() > 20, "the toe spans {} rows", in_toe.len());
    assert!(
        top < 0.03 * peak,
        "shear {top} kPa within the toe, peak {peak}"
    );
    // After the toe the curve is the toe-free one shifted by the gap.
    let plain = drive(
        b,
        Effects::default(),
        Rig::default(),
        &[slide(0.01, 3.0)],
        p,
        fine(0.2),
        1.0,
    );
    let plain_peak = plain.f.iter().cloned().fold(0.0, f64::max);
    assert!(
        (peak / plain_peak - 1.0).abs() < 0.01,
        "peak {peak} vs {plain_peak} without the toe"
    );
    let reach = |run: &Run| run.u[run.f.iter().position(|f| *f >= 0.5 * plain_peak).unwrap()];
    let shift = reach(&r) - reach(&plain);
    assert!(
        (shift / gap - 1.0).abs() < 0.05,
        "the toe shifted the curve by {shift} mm, gap {gap}"
    );
}

#[test]
fn halving_the_substep_limits_changes_nothing_that_matters() {
    // Every effect at once through a compliant rig: rate and state in the creep reading
    // (relaxation in holds), log healing, slip softening, a seating toe.
    use subfric_harness::generator::effects::{Combine, Slip, SlipShape};
    let b = base(0.5, 0.38, 1.5, 0.003, 15.0, 1000.0);
    let mut fx = rsf(StateLaw::Ageing, 0.01, 0.014, 0.02, 0.01, Reading::Creep);
    fx.healing = Some(Healing {
        shape: HealShape::Log { per_decade: 0.01 },
        tau: 1.0,
        d_h: 0.05,
    });
    fx.slip = Some(Slip {
        shape: SlipShape::Hyperbolic,
        combine: Combine::Additive,
        amount: -0.05,
        length: 2.0,
    });
    fx.rate.as_mut().unwrap().v_min = 1e-6;
    let rig = Rig {
        machine_kn_mm3: Some(0.005),
        toe: Some(Toe {
            gap_mm: 0.1,
            force_kpa: 0.5,
        }),
    };
    let segs = [
        slide(0.01, 1.5),
        hold(300.0),
        slide(0.01, 0.5),
        slide(0.1, 0.5),
        slide(0.001, 0.2),
        Segment::Unload {
            fraction: 0.1,
            duration: 20.0,
        },
        hold(30.0),
        slide(0.01, 0.5),
        slide(0.01, -1.5),
    ];
    let one = drive(b, fx, rig, &segs, 150.0, fine(0.5), 1.0);
    let half = drive(b, fx, rig, &segs, 150.0, fine(0.5), 0.5);
    let peak = one.f.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
    let worst = max_abs_diff(&one.f, &half.f);
    eprintln!(
        "{} rows, peak {peak:.2} kPa, largest change on halving {worst:.4} kPa",
        one.t.len()
    );
    assert!(
        worst < 0.002 * peak,
        "halving the substeps moved the shear by {worst} kPa (peak {peak})"
    );
}
