//! The forms of each effect family, checked against what each form means physically, and the
//! initial states of tests that do not start from rest.

use subfric_model::{
    simulate, Contact1, Contact3, Control, Extensions, Initial, Model, Params, Protocol,
    RateEffect, RateForm, State1, State3, Target, TermEffect, Terms,
};

/// A slip-controlled history built stage by stage at a fixed slip per row.
struct History {
    t: Vec<f64>,
    u: Vec<f64>,
}

impl History {
    fn new() -> Self {
        History {
            t: vec![0.0],
            u: vec![0.0],
        }
    }
    fn slide(mut self, rate: f64, distance: f64, du: f64) -> Self {
        let (t0, u0) = (*self.t.last().unwrap(), *self.u.last().unwrap());
        let n = (distance.abs() / du).round().max(1.0) as usize;
        for j in 1..=n {
            let f = j as f64 / n as f64;
            self.t.push(t0 + f * distance.abs() / rate);
            self.u.push(u0 + f * distance);
        }
        self
    }
    fn hold(mut self, duration: f64, rows: usize) -> Self {
        let (t0, u0) = (*self.t.last().unwrap(), *self.u.last().unwrap());
        for j in 1..=rows {
            self.t.push(t0 + duration * j as f64 / rows as f64);
            self.u.push(u0);
        }
        self
    }
    fn len(&self) -> usize {
        self.t.len()
    }
}

fn run(model: &Model, h: &History, p: f64, initial: Initial) -> Vec<f64> {
    let normal = vec![p; h.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &h.t,
        imposed: &h.u,
        normal: &normal,
        initial_slip: 0.0,
        initial,
    };
    simulate(model, &proto)
        .expect("the history simulates")
        .shear
        .iter()
        .map(|s| s / p)
        .collect()
}

/// A base model without slip softening or recovery, so that every change of friction comes from
/// the effect under test.
/// `full` run from rest, and its tail from row `c` started as sliding at `rate` [mm/s] under
/// the traction the full run had there.
struct Restart {
    /// Largest difference in friction between the two over the tail.
    worst: f64,
    /// The tail of the history.
    tail: History,
    /// Friction of the full run at row `c`.
    friction_at_cut: f64,
}

fn restart(m: &Model, full: &History, c: usize, rate: f64) -> Restart {
    let f = run(m, full, 100.0, Initial::Rest);
    let cut = History {
        t: full.t[c..].to_vec(),
        u: full.u[c..].to_vec(),
    };
    let g = run(
        m,
        &cut,
        100.0,
        Initial::Sliding {
            shear_kpa: f[c] * 100.0,
            rate_mm_s: rate,
        },
    );
    let worst = g
        .iter()
        .zip(&f[c..])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    Restart {
        worst,
        tail: cut,
        friction_at_cut: f[c],
    }
}

fn flat_base() -> Params {
    Params {
        mu_s: 0.5,
        mu_k: 0.5,
        kappa: 1.0,
        xi: 0.0,
        u_tilde: 200.0,
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: None,
    }
}

fn rate_state(form: RateForm) -> RateEffect {
    RateEffect {
        form,
        a: 0.01,
        v_c: 1e-6,
        b: 0.008,
        d_c: 0.02,
        n: 0.0,
        v_ref: 0.001,
        at_rest: subfric_model::AtRest::Creep,
    }
}

fn locked(form: RateForm) -> RateEffect {
    RateEffect {
        at_rest: subfric_model::AtRest::Locked,
        ..rate_state(form)
    }
}

fn model(params: Params, ext: Extensions) -> Model {
    Model::new(params, ext).expect("valid model")
}

#[test]
fn rate_and_state_velocity_step_jumps_by_a_then_evolves_over_d_c() {
    for form in [RateForm::StateAgeing, RateForm::StateSlip] {
        let rate = rate_state(form);
        let m = model(flat_base(), Extensions::default().with_rate(rate));
        let du = 0.0005;
        let h = History::new().slide(0.001, 1.0, du).slide(0.01, 0.4, du);
        let f = run(&m, &h, 100.0, Initial::Rest);
        let i_step = (1.0 / du).round() as usize;
        let before = f[i_step];
        let peak = f[i_step..].iter().cloned().fold(f64::MIN, f64::max);
        let after = *f.last().unwrap();
        let ln10 = 10f64.ln();
        // Direct effect: a ln(10) within the first rows (the machine is stiff).
        assert!(
            ((peak - before) - rate.a * ln10).abs() < 0.1 * rate.a * ln10,
            "{form:?}: jump {} expected {}",
            peak - before,
            rate.a * ln10
        );
        // Steady state: (a − b) ln(10).
        assert!(
            ((after - before) - (rate.a - rate.b) * ln10).abs() < 0.05 * rate.a * ln10,
            "{form:?}: steady change {} expected {}",
            after - before,
            (rate.a - rate.b) * ln10
        );
        // Evolution over D_c: one D_c after the step the excess over steady has decayed by
        // about e (between e^-0.5 and e^-2 for both laws), and is gone after 10 D_c.
        let excess = |i: usize| f[i] - after;
        let at_dc = i_step + (rate.d_c / du).round() as usize;
        let ratio = excess(at_dc) / (peak - after);
        assert!(
            ratio > (-2.5f64).exp() && ratio < (-0.4f64).exp(),
            "{form:?}: after D_c the excess is {ratio} of the peak's"
        );
        let at_10dc = i_step + (10.0 * rate.d_c / du).round() as usize;
        assert!(excess(at_10dc).abs() < 0.03 * (peak - after), "{form:?}");
    }
}

/// Peak friction on reloading after holds of each duration, minus the friction before the hold.
fn hold_gains(m: &Model, holds: &[f64]) -> Vec<f64> {
    holds
        .iter()
        .map(|&th| {
            let du = 0.0005;
            let h = History::new()
                .slide(0.001, 0.6, du)
                .hold(th, 200)
                .slide(0.001, 0.2, du);
            let f = run(m, &h, 100.0, Initial::Rest);
            let i_hold = (0.6 / du).round() as usize;
            let peak = f[i_hold + 200..].iter().cloned().fold(f64::MIN, f64::max);
            peak - f[i_hold]
        })
        .collect()
}

#[test]
fn ageing_law_heals_at_rest_log_linearly_and_slip_law_heals_less() {
    let ageing = model(
        flat_base(),
        Extensions::default().with_rate(rate_state(RateForm::StateAgeing)),
    );
    let slip = model(
        flat_base(),
        Extensions::default().with_rate(rate_state(RateForm::StateSlip)),
    );
    let g_age = hold_gains(&ageing, &[100.0, 1000.0]);
    let g_slip = hold_gains(&slip, &[100.0, 1000.0]);
    let b = rate_state(RateForm::StateAgeing).b;
    // Ageing law: θ grows like the hold time, the peak like b ln(t_hold) per decade.
    let per_decade = g_age[1] - g_age[0];
    assert!(
        (per_decade - b * 10f64.ln()).abs() < 0.35 * b * 10f64.ln(),
        "ageing: {per_decade} per decade, expected about {}",
        b * 10f64.ln()
    );
    assert!(
        g_slip[1] < 0.5 * g_age[1],
        "slip law gain {} vs ageing {}",
        g_slip[1],
        g_age[1]
    );
}

#[test]
fn locked_rate_forms_hold_the_traction_at_rest_and_heal_at_once_on_reloading() {
    // A stiff contact that slides at v, rests t_h with its slip held, and slides at v again.
    let (v, t_h, p) = (0.001, 500.0, 100.0);
    let du = 0.0005;
    let h = History::new()
        .slide(v, 0.6, du)
        .hold(t_h, 200)
        .slide(v, 0.2, du);
    let i_hold = (0.6 / du).round() as usize;
    let ext = |rate| Extensions::default().with_rate(rate);
    // Creep reading: the held traction relaxes (the direct effect at a vanishing rate).
    let creep = run(
        &model(flat_base(), ext(rate_state(RateForm::StateAgeing))),
        &h,
        p,
        Initial::Rest,
    );
    assert!(
        creep[i_hold + 200] < creep[i_hold] - 0.02,
        "creep: {} after the hold, {} before",
        creep[i_hold + 200],
        creep[i_hold]
    );
    let rate = locked(RateForm::StateAgeing);
    let f = run(&model(flat_base(), ext(rate)), &h, p, Initial::Rest);
    for (k, x) in f[i_hold..=i_hold + 200].iter().enumerate() {
        assert!(
            (x - f[i_hold]).abs() < 1e-12,
            "locked: row {k} of the hold moved from {} to {x}",
            f[i_hold]
        );
    }
    // The ageing law over the hold: θ = θ_ss + t_h with θ_ss = D_c/v, so the state term is
    // b ln(1 + t_h v/D_c) higher on the first sliding row, where the direct term is back at
    // its value before the hold (same rate). The evolution over that first row (du = D_c/40)
    // takes a few per cent of it.
    let expected = rate.b * (1.0 + t_h * v / rate.d_c).ln();
    let jump = f[i_hold + 201] - f[i_hold];
    assert!(
        (jump - expected).abs() < 0.06 * expected,
        "locked ageing: peak {jump} on reloading, expected about {expected}"
    );
    // Slip law: no healing at rest, so no peak either.
    let slip = run(
        &model(flat_base(), ext(locked(RateForm::StateSlip))),
        &h,
        p,
        Initial::Rest,
    );
    let peak = slip[i_hold + 201..]
        .iter()
        .cloned()
        .fold(f64::MIN, f64::max);
    assert!(
        (peak - slip[i_hold]).abs() < 0.05 * expected,
        "locked slip law: {} after the hold, {} before",
        peak,
        slip[i_hold]
    );
}

#[test]
fn time_healing_forms_grow_with_the_hold_as_their_law_says() {
    let base = Params {
        mu_k: 0.35,
        kappa: 20.0,
        ..flat_base()
    };
    for (form, values, expected_ratio) in [
        // Log: b ln(1 + t/t_c) with t_c = 1 s: gain(1000)/gain(100) = ln 1001 / ln 101.
        ("log", [0.005, 1.0], 1001f64.ln() / 101f64.ln()),
        // Power: b t^n with n = 0.3: 10^0.3.
        ("power", [0.005, 0.3], 10f64.powf(0.3)),
    ] {
        let m = model(base, healing(form, &values));
        let g = hold_gains(&m, &[100.0, 1000.0]);
        let ratio = g[1] / g[0];
        assert!(
            (ratio - expected_ratio).abs() < 0.08 * expected_ratio,
            "{form}: ratio {ratio} expected {expected_ratio}"
        );
    }
}

#[test]
fn healing_added_to_the_recovery_is_the_base_model_at_b_zero_and_adds_its_gain() {
    // A slide, holds of 10 s and 1000 s, slides: with b = 0 the form is the base model row for
    // row (it nests it); with b > 0 each hold's peak gain exceeds the base model's recovery.
    let base = Params {
        mu_k: 0.35,
        kappa: 20.0,
        xi: 0.002,
        ..flat_base()
    };
    let healing = |b: f64| model(base, healing("log-added", &[b, 1.0]));
    let plain = model(base, Extensions::default());
    let h = History::new()
        .slide(0.001, 0.6, 0.0005)
        .hold(10.0, 50)
        .slide(0.001, 0.3, 0.0005)
        .hold(1000.0, 50)
        .slide(0.001, 0.3, 0.0005);
    let (f0, fb) = (
        run(&plain, &h, 100.0, Initial::Rest),
        run(&healing(0.0), &h, 100.0, Initial::Rest),
    );
    let worst = f0
        .iter()
        .zip(&fb)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "b = 0 differs from the base model by {worst}"
    );
    let (g0, gb) = (
        hold_gains(&plain, &[10.0, 1000.0]),
        hold_gains(&healing(0.005), &[10.0, 1000.0]),
    );
    for k in 0..2 {
        assert!(g0[k] > 0.0, "the base model recovers in a hold: {g0:?}");
        assert!(gb[k] > g0[k] + 0.002, "hold {k}: {gb:?} vs the base {g0:?}");
    }
}

#[test]
fn healing_of_its_own_peaks_above_mu_s_by_its_law_and_is_erased_over_d_h() {
    // μ_s = μ_k (flat), no recovery: every change after a hold is the healing of its own. A
    // hold of t_h gains b ln(1 + t_h/t_c), which the reload shows as a peak above the sliding
    // level (not capped at μ_s), and slip wipes it out as exp(−s/d_h). (d_h is long against
    // the slip 1/ũ that the reload needs to reach the surface, which erases part of the gain
    // before the peak.)
    let (b, t_c, d_h) = (0.01, 1.0, 0.2);
    let m = |b: f64| model(flat_base(), healing("log-erased", &[b, t_c, d_h]));
    let h = History::new()
        .slide(0.001, 0.5, 0.0005)
        .hold(100.0, 50)
        .slide(0.001, 1.0, 0.0005);
    let (f0, f) = (
        run(
            &model(flat_base(), Extensions::default()),
            &h,
            100.0,
            Initial::Rest,
        ),
        run(&m(b), &h, 100.0, Initial::Rest),
    );
    let b_zero = run(&m(0.0), &h, 100.0, Initial::Rest);
    let worst = f0
        .iter()
        .zip(&b_zero)
        .map(|(a, c)| (a - c).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-12,
        "b = 0 differs from the base model by {worst}"
    );
    let reload = 1001 + 50;
    let (peak_row, peak) =
        f[reload..].iter().enumerate().fold(
            (0, f64::MIN),
            |(i, m), (j, v)| if *v > m { (j, *v) } else { (i, m) },
        );
    let gain = b * (1.0 + 100.0 / t_c).ln();
    let level = f0[reload - 51];
    assert!(level > 0.49 && peak > 0.5, "above μ_s = 0.5: peak {peak}");
    assert!(
        ((peak - level) / gain - 1.0).abs() < 0.1,
        "peak {peak} over the sliding level {level}: {} for a gain of {gain}",
        peak - level
    );
    // Erased by slip: 3 d_h of slip after the peak leaves about e⁻³ of it.
    let later = f[reload + peak_row + (3.0 * d_h / 0.0005) as usize] - level;
    assert!(
        later > 0.0 && later < 0.1 * (peak - level),
        "{later} of {}",
        peak - level
    );
}

#[test]
fn power_law_and_steady_state_rate_forms_change_steady_friction_as_stated() {
    let du = 0.002;
    let h = History::new().slide(0.001, 2.0, du).slide(0.1, 2.0, du);
    let i_step = (2.0 / du).round() as usize;
    // Power law on μ: friction ratio (v2/v1)^n when v ≫ v_c.
    let n = 0.02;
    let m = model(
        flat_base(),
        Extensions::default().with_rate(RateEffect {
            form: RateForm::Power,
            n,
            v_c: 1e-7,
            v_ref: 0.001,
            at_rest: subfric_model::AtRest::Creep,
            ..RateEffect::log_direct(0.0, 1e-7)
        }),
    );
    let f = run(&m, &h, 100.0, Initial::Rest);
    let ratio = f.last().unwrap() / f[i_step];
    assert!((ratio - 100f64.powf(n)).abs() < 1e-3, "power: {ratio}");
    // Steady-state only: μ_k(v) = μ_k + a ln(v/v_ref) reached through κ, with no jump at the
    // step itself.
    let base = Params {
        mu_k: 0.4,
        kappa: 5.0,
        ..flat_base()
    };
    let a = 0.01;
    let m = model(
        base,
        Extensions::default().with_rate(RateEffect {
            form: RateForm::SteadyState,
            a,
            v_c: 1e-7,
            v_ref: 0.001,
            at_rest: subfric_model::AtRest::Creep,
            ..RateEffect::log_direct(0.0, 1e-7)
        }),
    );
    let f = run(&m, &h, 100.0, Initial::Rest);
    let change = f.last().unwrap() - f[i_step];
    assert!((change - a * 100f64.ln()).abs() < 2e-4, "steady: {change}");
    let first = f[i_step + 1] - f[i_step];
    assert!(first.abs() < 0.1 * change.abs(), "no direct jump: {first}");
}

#[test]
fn direction_on_mu_k_weakens_backward_sliding_but_not_the_peak() {
    let base = Params {
        mu_s: 0.6,
        mu_k: 0.4,
        kappa: 3.0,
        xi: 0.0,
        u_tilde: 50.0,
        ..flat_base()
    };
    let d = 0.2;
    let m = model(
        base,
        Extensions {
            terms: Terms::one(TermEffect::named("direction", "mu-k", &[d]).unwrap()),
        },
    );
    let du = 0.002;
    let h = History::new().slide(0.01, 3.0, du).slide(0.01, -6.0, du);
    let f = run(&m, &h, 100.0, Initial::Rest);
    let forward_end = f[(3.0 / du).round() as usize];
    let backward_end = -f.last().unwrap();
    assert!((forward_end - 0.4).abs() < 1e-3, "forward {forward_end}");
    assert!(
        (backward_end - 0.4 * (1.0 - d)).abs() < 1e-3,
        "backward {backward_end}"
    );
    // Forward sliding, peak included, is the base model's.
    let plain = run(
        &model(base, Extensions::default()),
        &h,
        100.0,
        Initial::Rest,
    );
    let i_rev = (3.0 / du).round() as usize;
    assert_eq!(f[..=i_rev], plain[..=i_rev]);
    assert!(f.last() != plain.last());
}

#[test]
fn pressure_on_mu_k_only_keeps_the_peak_and_lowers_residual_friction() {
    let base = Params {
        mu_s: 0.6,
        mu_k: 0.4,
        kappa: 3.0,
        xi: 0.0,
        u_tilde: 50.0,
        ..flat_base()
    };
    for form in ["power-mu-k", "linear-mu-k", "exponential-mu-k"] {
        let eff = TermEffect::named("pressure", form, &[0.1, 100.0]).unwrap();
        let m = model(
            base,
            Extensions {
                terms: Terms::one(eff),
            },
        );
        let h = History::new().slide(0.01, 4.0, 0.002);
        let low = run(&m, &h, 100.0, Initial::Rest);
        let high = run(&m, &h, 400.0, Initial::Rest);
        let peak = |f: &[f64]| f.iter().cloned().fold(f64::MIN, f64::max);
        assert!((peak(&low) - peak(&high)).abs() < 0.02, "{form}");
        let ratio = high.last().unwrap() / low.last().unwrap();
        let factor = eff
            .family()
            .factor_on(eff.form as usize, &eff.p, Target::MuK, 400.0, 1.0);
        assert!(
            (ratio - factor).abs() < 2e-3,
            "{form}: residual ratio {ratio} expected {factor}"
        );
    }
}

/// The general form on the bounds holds μ_s only and μ_k only as special cases (one of its
/// sizes zero), and its two sizes act independently.
#[test]
fn effects_on_both_bounds_reduce_to_one_bound_when_the_other_size_is_zero() {
    let base = Params {
        mu_s: 0.6,
        mu_k: 0.4,
        kappa: 3.0,
        xi: 0.0,
        u_tilde: 50.0,
        ..flat_base()
    };
    let pressure = |beta: f64, target: &str, beta_k: f64| {
        let values = if target == "bounds" {
            vec![beta, beta_k, 100.0]
        } else {
            vec![beta, 100.0]
        };
        let e = TermEffect::named("pressure", &format!("power-{target}"), &values).unwrap();
        model(
            base,
            Extensions {
                terms: Terms::one(e),
            },
        )
    };
    let h = History::new().slide(0.01, 4.0, 0.002);
    let at = |m: &Model| run(m, &h, 400.0, Initial::Rest);
    assert_eq!(
        at(&pressure(0.0, "bounds", 0.15)),
        at(&pressure(0.15, "mu-k", 0.0))
    );
    assert_eq!(
        at(&pressure(0.15, "bounds", 0.0)),
        at(&pressure(0.15, "mu-s", 0.0))
    );
    let both = at(&pressure(0.1, "bounds", 0.2));
    let residual = both.last().unwrap();
    let expected = 0.4 * 4f64.powf(-0.2);
    assert!(
        (residual - expected).abs() < 2e-3,
        "residual friction {residual}, expected μ_k (p/p_ref)^-β_k = {expected}"
    );
    let peak = both.iter().cloned().fold(f64::MIN, f64::max);
    assert!(
        peak < 0.6 * 4f64.powf(-0.1) + 1e-9,
        "peak {peak} above the scaled μ_s"
    );
}

#[test]
fn hyperbolic_slip_hardening_follows_h_s_over_one_plus_s_over_s_h() {
    let m = model(
        flat_base(),
        Extensions {
            terms: Terms::one(
                TermEffect::named("slip-hardening", "hyperbolic", &[0.01, 2.0]).unwrap(),
            ),
        },
    );
    let du = 0.002;
    let h = History::new().slide(0.01, 6.0, du);
    let f = run(&m, &h, 100.0, Initial::Rest);
    for s in [2.0, 6.0] {
        let i = (s / du).round() as usize;
        // Plastic slip lags the imposed slip by the elastic part and the initial loading.
        let expected = 0.5 + 0.01 * s / (1.0 + s / 2.0);
        assert!(
            (f[i] - expected).abs() < 2e-3,
            "s={s}: {} vs {expected}",
            f[i]
        );
    }
}

#[test]
fn sliding_start_continues_a_run_without_a_new_initial_loading() {
    let base = Params::sample();
    for ext in [
        Extensions::default(),
        Extensions::default().with_rate(rate_state(RateForm::StateAgeing)),
    ] {
        let m = model(base, ext);
        let du = 0.002;
        let full = History::new().slide(0.01, 6.0, du).slide(0.003, 1.0, du);
        // Cut the history at 4 mm, well into steady sliding.
        let r = restart(&m, &full, (4.0 / du).round() as usize, 0.01);
        assert!(r.worst < 2e-3, "{ext:?}: largest difference {}", r.worst);
        // From rest the same cut would load from zero: far off at its start.
        let from_rest = run(&m, &r.tail, 100.0, Initial::Rest);
        assert!((from_rest[0] - r.friction_at_cut).abs() > 0.1);
    }
}

#[test]
fn sliding_start_is_steady_for_every_rate_form() {
    // Steady sliding cut mid-run: from the sliding start the friction stays where it was.
    let base = Params {
        mu_s: 0.69,
        mu_k: 0.59,
        kappa: 2.0,
        xi: 0.001,
        u_tilde: 22.0,
        ..flat_base()
    };
    for rate in [
        RateEffect {
            form: RateForm::Power,
            n: -0.03,
            v_c: 1e-5,
            v_ref: 0.01,
            at_rest: subfric_model::AtRest::Creep,
            ..RateEffect::log_direct(0.0, 1e-5)
        },
        RateEffect {
            form: RateForm::Power,
            n: 0.03,
            v_c: 1e-5,
            v_ref: 0.01,
            at_rest: subfric_model::AtRest::Creep,
            ..RateEffect::log_direct(0.0, 1e-5)
        },
        RateEffect::log_direct(0.015, 5e-5),
        rate_state(RateForm::StateSlip),
        locked(RateForm::StateAgeing),
        locked(RateForm::StateSlip),
        RateEffect {
            form: RateForm::SteadyState,
            a: -0.02,
            v_c: 1e-6,
            v_ref: 0.01,
            at_rest: subfric_model::AtRest::Creep,
            ..RateEffect::log_direct(0.0, 1e-6)
        },
    ] {
        sliding_start_matches(base, Extensions::default().with_rate(rate));
    }
    // Slip softening and hardening: the slip accumulated before the cut comes from the traction.
    for h in [-0.01, 0.008] {
        for form in ["capped", "exponential", "hyperbolic"] {
            sliding_start_matches(
                base,
                Extensions {
                    terms: Terms::one(
                        TermEffect::named("slip-hardening", form, &[h, 4.0]).unwrap(),
                    ),
                },
            );
        }
    }
}

/// A run cut after 3 mm of steady sliding and simulated from a sliding start follows the run.
fn sliding_start_matches(base: Params, ext: Extensions) {
    {
        let m = model(base, ext);
        // Cut after 3 mm: 6 decay lengths 1/(κ + ξ/v) into the run, steady to 1e-4.
        let full = History::new().slide(0.01, 4.0, 0.005);
        let worst = restart(&m, &full, (3.0 / 0.005) as usize, 0.01).worst;
        assert!(worst < 1e-3, "{ext:?}: largest difference {worst}");
    }
}

#[test]
fn loaded_start_holds_its_traction_and_reloads_from_it() {
    let m = model(Params::sample(), Extensions::default());
    let h = History::new().hold(100.0, 20).slide(0.01, 1.0, 0.002);
    let tau0 = 0.2 * 100.0;
    let f = run(&m, &h, 100.0, Initial::Loaded { shear_kpa: tau0 });
    for v in &f[..=20] {
        assert!((v - 0.2).abs() < 1e-12, "the hold keeps the traction: {v}");
    }
    // Reloading starts from 0.2, not from zero, and is monotone at first.
    assert!(f[21] >= 0.2 && f[21] < 0.3, "{}", f[21]);
}

/// Each form of each registered family (`subfric_model::terms`), its parameters inside their
/// bounds and away from the values that switch it off.
fn registered_terms() -> Vec<Extensions> {
    let mut out = Vec::new();
    for (i, fam) in subfric_model::terms::FAMILIES.iter().enumerate() {
        for k in 0..fam.forms().len() {
            let mut t = subfric_model::TermEffect::new(i as u8, k as u8);
            for (j, q) in fam.params().iter().enumerate() {
                let (lo, hi) = q.bounds;
                t.p[j] = if q.log_scale {
                    (lo * hi).sqrt()
                } else {
                    0.5 * (lo + hi) + 0.05 * (hi - lo)
                };
            }
            out.push(Extensions {
                terms: Terms::one(t),
            });
        }
    }
    out
}

/// Every form gives the same answer in 1-D and on a collinear 3-D path (two-way, so that the
/// direction effect acts).
#[test]
fn collinear_3d_equals_1d_for_every_form() {
    let mut forms: Vec<Extensions> = vec![
        Extensions::default().with_rate(rate_state(RateForm::StateAgeing)),
        Extensions::default().with_rate(locked(RateForm::StateAgeing)),
        Extensions::default().with_rate(rate_state(RateForm::StateSlip)),
        Extensions {
            terms: Terms::one(TermEffect::named("direction", "kappa", &[0.15]).unwrap()),
        },
        Extensions {
            terms: Terms::one(TermEffect::named("direction", "u-tilde", &[0.15]).unwrap())
                .with(TermEffect::named("pressure", "exponential-mu-s", &[0.1, 50.0]).unwrap())
                .with(TermEffect::named("healing", "power", &[0.01, 0.5]).unwrap()),
        },
    ];
    forms.push(healing("log-erased", &[0.01, 3.0, 0.05]));
    forms.extend(registered_terms());
    for ext in forms {
        let m = model(Params::sample(), ext);
        let h = History::new()
            .slide(0.01, 1.0, 0.005)
            .hold(50.0, 10)
            .slide(0.01, -2.0, 0.005)
            .slide(0.01, 1.0, 0.005);
        let mut c1 = Contact1::new(&m);
        let c3 = Contact3::new(&m, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
        let p = 100.0;
        let mut s1 = State1::virgin_at(&m, 0.0, p);
        let mut s3 = State3::virgin(&m, [0.0; 3]);
        s3.mu = s1.mu;
        for i in 1..h.len() {
            let dt = h.t[i] - h.t[i - 1];
            s1 = c1.step_slip(&s1, h.u[i], p, dt).unwrap();
            s3 = c3.step_slip(&s3, &[h.u[i], 0.0, 0.0], p, dt).unwrap();
            assert!(
                (s1.shear - s3.shear[0]).abs() < 1e-8 * p,
                "{ext:?} row {i}: {} vs {}",
                s1.shear,
                s3.shear[0]
            );
        }
    }
}

/// Time healing in its form `form` (a key of the family's forms) with that form's parameters.
fn healing(form: &str, values: &[f64]) -> Extensions {
    Extensions {
        terms: Terms::one(TermEffect::named("healing", form, values).expect("a healing form")),
    }
}

#[test]
fn sliding_steadily_brings_theta_to_d_c_over_v_under_both_laws() {
    // θ as the state slots carry it from step to step (what the next step and a hold start
    // from): after fifty D_c at a constant rate v, both laws' steady state D_c/v.
    let (v, du, p) = (0.004, 0.0005, 100.0);
    for form in [RateForm::StateAgeing, RateForm::StateSlip] {
        let rate = rate_state(form);
        let m = model(flat_base(), Extensions::default().with_rate(rate));
        let mut c = Contact1::new(&m);
        let mut st = State1::virgin(&m, 0.0);
        for i in 1..=2000 {
            st = c.step_slip(&st, i as f64 * du, p, du / v).unwrap();
        }
        let theta = m.ext.terms.state_value(&st.slots, "theta").unwrap();
        let steady = rate.d_c / v;
        assert!(
            (theta / steady - 1.0).abs() < 1e-3,
            "{form:?}: θ = {theta} after sliding steadily, expected D_c/v = {steady}"
        );
    }
}
