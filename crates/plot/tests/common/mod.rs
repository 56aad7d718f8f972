//! Synthetic sand–metal interface curves shared by the tests and the demo.
#![allow(dead_code)]

use subfric_plot::{BarFigure, Figure, Panel, Series, Style};

/// A small deterministic pseudo-random generator (no extra dependency).
pub struct Lcg(u64);

impl Lcg {
    pub fn new(seed: u64) -> Self {
        Lcg(seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407))
    }
    /// Uniform in [-1, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// Cyclic interface shear: displacement (mm), shear stress (kPa), cycle.
/// A Bouc–Wen-like hysteresis with a peak stress growing per cycle.
pub fn cyclic(
    n: usize,
    cycles: u32,
    tau_max: f64,
    growth: f64,
    noise: f64,
    seed: u64,
) -> (Vec<f64>, Vec<f64>, Vec<u32>) {
    let mut rng = Lcg::new(seed);
    let amp = 1.5;
    let k = 120.0;
    let mut tau = 0.0f64;
    let mut prev = 0.0f64;
    let (mut xs, mut ys, mut cs) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    for i in 0..n {
        let t = i as f64 / (n - 1) as f64 * f64::from(cycles);
        let cycle = (t.floor() as u32 + 1).min(cycles);
        let d = amp * (2.0 * std::f64::consts::PI * t).sin();
        let dd = d - prev;
        let tm = tau_max * (1.0 + growth * f64::from(cycle - 1));
        tau += k * dd * (1.0 - dd.signum() * tau / tm);
        prev = d;
        xs.push(d);
        ys.push(tau + noise * rng.next());
        cs.push(cycle);
    }
    (xs, ys, cs)
}

/// Monotonic interface shear curve with a peak and softening.
pub fn monotonic(x: &[f64], peak: f64, residual: f64, d0: f64) -> Vec<f64> {
    x.iter()
        .map(|&d| {
            let rise = 1.0 - (-d / d0).exp();
            let soft = (-d / (6.0 * d0)).exp();
            (residual + (peak - residual) * soft) * rise
        })
        .collect()
}

/// The figure the tests check: measured (cycle coloured), published,
/// fitted, and a residual panel.
pub fn cyclic_figure(n: usize) -> Figure {
    let (xm, ym, cm) = cyclic(n, 5, 60.0, 0.08, 2.5, 7);
    let (xf, yf, _) = cyclic(n, 5, 58.0, 0.085, 0.0, 7);
    let xp: Vec<f64> = (0..40).map(|i| i as f64 / 39.0 * 1.5).collect();
    let yp: Vec<f64> = monotonic(&xp, 70.0, 55.0, 0.12);
    let resid: Vec<f64> = yf.iter().zip(&ym).map(|(f, m)| f - m).collect();
    let main = Panel::new(
        "shear stress τ (kPa)",
        vec![
            Series::new("measured", xm.clone(), ym, Style::Measured).with_cycles(cm.clone()),
            Series::new("published (digitised)", xp, yp, Style::Published),
            Series::new("fitted model", xf, yf, Style::Fitted),
        ],
    );
    let residual = Panel::new(
        "residual (kPa)",
        vec![Series::new("fitted − measured", xm, resid, Style::Fitted)],
    )
    .with_zero_line();
    Figure::new(
        "Cyclic interface shear, dense sand on steel (σn = 100 kPa)",
        "tangential displacement δ (mm)",
        main,
    )
    .with_residual(residual)
}

/// A monotonic test with few measured points (markers) and NaN gaps.
pub fn monotonic_figure() -> Figure {
    let xm: Vec<f64> = (0..30).map(|i| i as f64 * 0.25).collect();
    let mut rng = Lcg::new(3);
    let mut ym: Vec<f64> = monotonic(&xm, 85.0, 62.0, 0.4)
        .into_iter()
        .map(|v| v + 2.0 * rng.next())
        .collect();
    ym[12] = f64::NAN;
    let xf: Vec<f64> = (0..3000).map(|i| i as f64 * 7.5 / 2999.0).collect();
    let yf = monotonic(&xf, 84.0, 61.0, 0.42);
    let xp: Vec<f64> = (0..60).map(|i| i as f64 * 0.125).collect();
    let yp = monotonic(&xp, 90.0, 65.0, 0.35);
    let ymf = monotonic(&xm, 84.0, 61.0, 0.42);
    let resid: Vec<f64> = ymf.iter().zip(&ym).map(|(f, m)| f - m).collect();
    let main = Panel::new(
        "shear stress τ (kPa)",
        vec![
            Series::new("measured", xm.clone(), ym, Style::Measured),
            Series::new("Uesugi & Kishida (1986)", xp, yp, Style::Published),
            Series::new("fitted", xf, yf, Style::Fitted),
        ],
    );
    let residual = Panel::new(
        "Δτ (kPa)",
        vec![Series::new("residual", xm, resid, Style::Measured)],
    )
    .with_zero_line();
    Figure::new(
        "Monotonic interface shear, loose sand",
        "displacement (mm)",
        main,
    )
    .with_residual(residual)
}

/// Grouped bars: error of the base model and of the model with an effect.
pub fn bar_figure() -> BarFigure {
    let cats: Vec<String> = [
        "dense, smooth steel",
        "dense, rough steel",
        "loose, smooth",
        "loose, rough",
        "cyclic 50 kPa",
        "cyclic 200 kPa",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    BarFigure::new("Fit error per test", "RMSE (kPa)", cats)
        .with_group("base model", vec![4.2, 6.1, 3.3, 5.0, 7.9, 9.4])
        .with_group("with dilatancy effect", vec![2.9, 3.8, 3.1, 3.6, 4.4, 5.2])
        .with_reference_line("noise level", 2.5)
}
