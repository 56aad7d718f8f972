//! Unit tests of `steps.rs` (kept beside it to keep that file short).

use super::*;

/// A step from 1 to 3 µm/s with no change of steady friction, under noise that is white
/// plus a slow AR(1) part (correlation over `corr` rows, as a real record's residuals
/// wander), drawn from `seed`.
fn unchanged_step(seed: u64, corr: f64) -> Window {
    let (v0, v1, sigma) = (1e-3, 3e-3, 2e-4);
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut normal = || -> f64 { StandardNormal.sample(&mut rng) };
    let phi = (-1.0 / corr).exp();
    let mut slow = 0.0;
    let (pre_rows, post_rows) = (400usize, 300usize);
    let mut w = Window {
        time: Vec::new(),
        travel: Vec::new(),
        v_lp: Vec::new(),
        mu: Vec::new(),
        step: pre_rows - 1,
        v0,
        v1,
        sigma,
        first_row: 0,
        normal: 1e4,
    };
    for i in 0..pre_rows + post_rows {
        let t = i as f64 - (pre_rows - 1) as f64;
        let v = if i < pre_rows { v0 } else { v1 };
        slow = phi * slow + (1.0 - phi * phi).sqrt() * 2.0 * sigma * normal();
        w.time.push(t);
        w.travel.push(if t <= 0.0 { v0 * t } else { v1 * t });
        w.v_lp.push(v);
        w.mu.push(0.6 + slow + sigma * normal());
    }
    w
}

/// A step from 1 to 3 µm/s of a rigid slider (slip law, a = 0.008, D_c = 0.02 mm) whose
/// steady friction changes by `a_minus_b` per e-fold, under white noise and a slow AR(1)
/// wander of twice its SD correlated over 30 rows, drawn from `seed`.
fn rsf_step(seed: u64, a_minus_b: f64) -> Window {
    let mut w = unchanged_step(seed, 30.0);
    let slider = Slider {
        law: StateLaw::Slip,
        a: 0.008,
        b: 0.008 - a_minus_b,
        d_c: 0.02,
        k: f64::INFINITY,
        v0: w.v0,
        mu0: 0.6,
    };
    let clean = slider
        .friction(&w.time, &w.v_lp)
        .expect("a rigid slider integrates");
    for (m, c) in w.mu.iter_mut().zip(clean) {
        *m += c - 0.6;
    }
    w
}

#[test]
fn intervals_of_a_minus_b_hold_the_truth_under_a_slow_wander() {
    // Fitted with its trend free, the slope over the new rate traded against a − b (a
    // wander after the transient reads as a trend or as a level): 48 of 60 intervals held
    // the truth ±0.001. With the trend read off the sliding before the step alone (its
    // uncertainty carried in): 42 of 60. Each interval covering both readings: 58 of 60,
    // and the sign of a − b agrees with 40 of the 41 changes measured on the record beyond
    // their uncertainty.
    let n = 30;
    let (mut covered, mut wrong, mut measured, mut agree) = (0, 0, 0, 0);
    for seed in 0..n {
        for truth in [1e-3, -1e-3] {
            let fit = fit_step("t", &rsf_step(seed, truth), None).expect("a fit");
            let amb = fit.a_minus_b;
            if amb.lo <= truth && truth <= amb.hi {
                covered += 1;
            }
            if amb.excludes_zero() && amb.value.signum() != truth.signum() {
                wrong += 1;
            }
            let m = fit.measured_steady_change;
            if m.excludes_zero() {
                measured += 1;
                agree += usize::from(amb.value.signum() == m.value.signum());
            }
        }
    }
    assert!(
        covered >= 2 * n * 85 / 100,
        "{covered} of {} intervals",
        2 * n
    );
    assert!(wrong <= 1, "{wrong} signs claimed against the truth");
    assert!(
        agree + 2 >= measured,
        "{agree} of {measured} measured changes"
    );
}

/// How many of `n` unchanged steps have a "measured" change (interval clear of zero).
fn false_changes(n: u64, corr: f64) -> usize {
    (0..n)
        .filter(|&seed| {
            let c = measured_change(&unchanged_step(seed, corr));
            c.value.abs() > c.half_width()
        })
        .count()
}

#[test]
fn an_unchanged_step_under_slowly_wandering_noise_is_rarely_called_a_change() {
    // A 95 % interval should call about 5 % of unchanged steps changed. Counting the rows
    // as independent called 34 %, 56 % and 70 % of them changed under a wander correlated
    // over 3, 10 and 30 rows (200 steps each); with the correlation time counted, 6 %,
    // 13 % and 30 %: the correlation time of a window only a few times longer than it is
    // estimated short.
    let n = 200;
    let near = false_changes(n, 3.0);
    assert!(near <= n as usize / 10, "{near} of {n}");
    let far = false_changes(n, 10.0);
    assert!(far <= n as usize / 5, "{far} of {n}");
    // White noise alone: the interval is not made needlessly wide either.
    let white = false_changes(n, 1e-6);
    assert!((2..=n as usize / 10).contains(&white), "{white} of {n}");
}

#[test]
fn a_step_faster_than_its_rows_counts_neither_for_nor_against_a_direct_effect() {
    // Friction that jumps to its new steady level at the step (3 µm of travel a row): the best
    // fit without a direct effect moves within a row, where a direct jump and an evolution
    // that fast look the same, so the step resolves no transient (its evidence D ≈ 10 speaks
    // of the evolution, not of a direct effect). Friction that moves to the same level over
    // about seven rows with no jump resolves it: a step that shows no direct effect.
    for seed in 0..5 {
        let fast = fit_step("t", &moving_to_a_new_level(seed, 0.0), None).expect("a fit");
        assert!(
            !fast.resolves_transient(),
            "seed {seed}: without a direct effect over {} mm, {} mm a row, evidence {}",
            fast.null_length_mm,
            fast.row_travel_mm,
            fast.evidence
        );
        assert!(fast.a_minus_b.value > 0.0, "{:?}", fast.a_minus_b);
        let gradual = fit_step("t", &moving_to_a_new_level(seed, 0.02), None).expect("a fit");
        assert!(
            gradual.resolves_transient() && !gradual.significant(),
            "seed {seed}: without a direct effect over {} mm, {} mm a row, evidence {}",
            gradual.null_length_mm,
            gradual.row_travel_mm,
            gradual.evidence
        );
    }
}

/// The unchanged step of `seed` under white noise, its friction moving up by 0.004 after the
/// step over an e-folding slip of `slip_mm` (0: at once), with no direct effect.
fn moving_to_a_new_level(seed: u64, slip_mm: f64) -> Window {
    let mut w = unchanged_step(seed, 1e-6);
    for (m, u) in w.mu.iter_mut().zip(&w.travel) {
        if *u > 0.0 {
            *m += 0.004 * (1.0 - (-u / slip_mm.max(1e-12)).exp());
        }
    }
    w
}

#[test]
fn steps_too_fast_for_their_rows_leave_the_consensus_to_the_steps_that_resolve_theirs() {
    // Two steps that show a direct effect (friction jumps by 0.008 and falls back by 0.007
    // over about seven rows, white noise): beside two steps too fast for their rows, the
    // steps agree on rate and state; beside two that move gradually with no jump, they do
    // not (two of four).
    let shown = |seed: u64| {
        let mut w = unchanged_step(seed, 1e-6);
        for (m, u) in w.mu.iter_mut().zip(&w.travel) {
            if *u > 0.0 {
                *m += 0.008 - 0.007 * (1.0 - (-u / 0.02).exp());
            }
        }
        let fit = fit_step("t", &w, None).expect("a fit");
        assert!(
            fit.significant(),
            "evidence {}, a {:?}",
            fit.evidence,
            fit.a
        );
        fit
    };
    let fit = |seed: u64, slip_mm: f64| {
        fit_step("t", &moving_to_a_new_level(seed, slip_mm), None).expect("a fit")
    };
    let with_fast = [shown(1), shown(2), fit(3, 0.0), fit(4, 0.0)];
    let r = super::super::consensus(&with_fast).expect("steps read");
    assert_eq!((r.significant, r.resolved), (2, 2));
    assert!(r.consistent);
    let with_gradual = [shown(1), shown(2), fit(3, 0.02), fit(4, 0.02)];
    let r = super::super::consensus(&with_gradual).expect("steps read");
    assert_eq!((r.significant, r.resolved), (2, 4));
    assert!(!r.consistent);
}
