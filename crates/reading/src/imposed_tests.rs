//! Unit tests of `events.rs` (kept beside it to keep that file short).

use super::*;

/// A slow slide to 2.3 mm, a slow unload backing the load point off by `back` mm over
/// `unload_rows` rows sampled as sparsely as the hold, a hold, a reload; a 0.1 µm encoder
/// with noise of a fifth of a quantum.
fn unload_record(back: f64, unload_rows: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut t, mut x) = (vec![0.0], vec![0.0]);
    let push = |dt: f64, dx: f64, t: &mut Vec<f64>, x: &mut Vec<f64>| {
        let (tl, xl) = (*t.last().unwrap(), *x.last().unwrap());
        t.push(tl + dt);
        x.push(xl + dx);
    };
    for _ in 0..800 {
        push(0.2, 0.0028, &mut t, &mut x);
    }
    for _ in 0..unload_rows {
        push(4.0, -back / unload_rows as f64, &mut t, &mut x);
    }
    for _ in 0..10 {
        push(1.0, 0.0, &mut t, &mut x);
    }
    for _ in 0..300 {
        push(0.2, 0.0028, &mut t, &mut x);
    }
    // Deterministic jitter within ±0.2 quantum, then the encoder's rounding.
    let x = x
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let jitter = 2e-5 * ((i as f64 * 1.7).sin());
            ((v + jitter) / 1e-4).round() * 1e-4
        })
        .collect();
    (t, x)
}

#[test]
fn an_unload_smaller_than_the_band_and_slow_as_a_hold_stays_a_reversal() {
    // 2.4 µm back over 8 sparse rows (the unload of 20 kPa through a compliant machine)
    // and 6 µm over 3: both are reversals into the hold, and the reload reverses again.
    for (back, rows) in [(0.0024, 8), (0.006, 3)] {
        let (t, x) = unload_record(back, rows);
        let ev = detect(&t, &x, &SegmentOptions::default());
        assert_eq!(
            ev.reversals.len(),
            2,
            "{back} mm over {rows} rows: {:?}, holds {:?}",
            ev.reversals,
            ev.holds
        );
        assert!(
            (ev.reversals[0] as i64 - 800).abs() <= 1,
            "{:?}",
            ev.reversals
        );
        let (s, e) = ev.holds[0];
        assert!(
            s >= 800 + rows - 1 && e <= 800 + rows + 11,
            "hold {:?}",
            ev.holds
        );
        assert!(
            ev.reversals[1] + 1 >= e - 1,
            "{:?} {:?}",
            ev.reversals,
            ev.holds
        );
    }
    // A hold without an unload stays a hold between forward motions: no reversal.
    let (t, x) = unload_record(0.0, 8);
    let ev = detect(&t, &x, &SegmentOptions::default());
    assert!(ev.reversals.is_empty(), "{:?}", ev.reversals);
    assert_eq!(ev.holds.len(), 1, "{:?}", ev.holds);
}

#[test]
fn a_slowly_sampled_unload_beyond_the_band_is_no_hold() {
    // Sliding at 12 µm/s logged every 0.34 s, then the load point backs off 18 µm over 6 rows
    // 3.6 s apart (an unload of 80 kPa through a soft machine, logged as sparsely as a hold),
    // holds for two rows and reloads; a 10 nm encoder with 12 nm of noise. The median of three flattens the turning
    // point into a still-looking stretch: the unload must stay motion, with a reversal at the
    // turning point, no hold before the unload has ended, and a reversal at the reload.
    let (mut t, mut x) = (vec![0.0], vec![0.0]);
    let mut push = |dt: f64, dx: f64| {
        let (tl, xl) = (*t.last().unwrap(), *x.last().unwrap());
        t.push(tl + dt);
        x.push(xl + dx);
    };
    for _ in 0..600 {
        push(0.34, 0.0041);
    }
    for _ in 0..6 {
        push(3.6, -0.003);
    }
    push(3.6, 0.0);
    push(2.9, 0.0);
    for _ in 0..300 {
        push(0.34, 0.0041);
    }
    let mut rng = <rand::rngs::StdRng as rand::SeedableRng>::seed_from_u64(16);
    let x: Vec<f64> = x
        .iter()
        .map(|v| {
            let noise: f64 =
                rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
            ((v + 1.2e-5 * noise) / 1e-5).round() * 1e-5
        })
        .collect();
    let ev = detect(&t, &x, &SegmentOptions::default());
    assert_eq!(
        ev.reversals.len(),
        2,
        "{:?}, holds {:?}",
        ev.reversals,
        ev.holds
    );
    assert!(
        (ev.reversals[0] as i64 - 600).abs() <= 1,
        "{:?}",
        ev.reversals
    );
    assert!(
        ev.holds.iter().all(|&(s, _)| s >= 605),
        "a hold inside the unload: {:?}",
        ev.holds
    );
    assert!(ev.reversals[1] > 605, "{:?}", ev.reversals);
}

#[test]
fn hysteresis_ignores_small_wiggles() {
    let x = [0.0, 1.0, 2.0, 1.9, 2.1, 3.0, 2.0, 1.0, 1.05, 0.0, 1.0];
    assert_eq!(reversals_hysteresis(&x, 0.5), vec![5, 9]);
}

#[test]
fn hysteresis_with_initial_fall() {
    let x = [0.0, -1.0, -2.0, -1.0, 0.0];
    assert_eq!(reversals_hysteresis(&x, 0.5), vec![2]);
}

#[test]
fn chunks_cover_the_rows_and_move_the_travel() {
    let t: Vec<f64> = (0..101).map(|i| i as f64).collect();
    let y: Vec<f64> = t.iter().map(|t| 0.1 * t).collect();
    let c = chunks(&t, &y, 0, 100, 1.0);
    assert_eq!(c.first().unwrap().start, 0);
    assert_eq!(c.last().unwrap().end, 100);
    assert!(c.windows(2).all(|w| w[0].end == w[1].start));
    assert!(c.iter().all(|c| c.travel >= 1.0 - 1e-9));
}

#[test]
fn a_ramp_of_rates_is_no_velocity_step() {
    // The rate doubles every 100 s, smoothly: no sharp change anywhere.
    let t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.1).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 0.01 * 100.0 / 2f64.ln() * ((2f64.ln() * t / 100.0).exp() - 1.0))
        .collect();
    let s = velocity_steps(&t, &y, 0, 2999, 0.01, &SegmentOptions::default());
    assert!(s.is_empty(), "{s:?}");
}

#[test]
fn holds_of_a_slide_hold_slide_are_found() {
    let mut t = vec![0.0];
    let mut y = vec![0.0];
    let mut add = |dt: f64, rate: f64, rows: usize| {
        for _ in 0..rows {
            let (lt, ly) = (*t.last().unwrap(), *y.last().unwrap());
            t.push(lt + dt);
            y.push(ly + rate * dt);
        }
    };
    add(0.5, 0.01, 400);
    add(1.0, 0.0, 30);
    add(0.5, 0.01, 160);
    add(10.0, 0.0, 30);
    add(0.5, 0.01, 160);
    let h = holds(&t, &y, 1e-12, 0.0, 1.5);
    assert_eq!(h, vec![(401, 431), (591, 621)], "{h:?}");
}

#[test]
fn a_sharp_tenfold_step_is_found_at_its_row() {
    let mut t = vec![0.0];
    let mut y = vec![0.0];
    for i in 1..=600 {
        let (rate, dt) = if i <= 300 { (0.01, 1.0) } else { (0.1, 0.1) };
        t.push(t[i - 1] + dt);
        y.push(y[i - 1] + rate * dt);
    }
    let s = velocity_steps(&t, &y, 0, 600, 0.05, &SegmentOptions::default());
    assert_eq!(s, vec![300]);
}
