//! Axes: ranges padded around the data, tick values and their labels.

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{plottable, text_width};

/// A closed axis range with `min < max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct AxisRange {
    pub min: f64,
    pub max: f64,
}

impl AxisRange {
    pub fn span(&self) -> f64 {
        self.max - self.min
    }

    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// Running minimum and maximum of plottable values.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Extent {
    pub bounds: Option<(f64, f64)>,
}

impl Extent {
    pub fn add(&mut self, v: f64) {
        if !plottable(v) {
            return;
        }
        self.bounds = Some(match self.bounds {
            None => (v, v),
            Some((lo, hi)) => (lo.min(v), hi.max(v)),
        });
    }

    /// The padded axis range: 5 % of the span on each side; an all-equal extent gets ±5 % of
    /// its value (±1 around 0); no data gives 0..1 (−1..1 when zero must be inside).
    pub fn padded(&self, include_zero: bool) -> AxisRange {
        let Some((mut lo, mut hi)) = self.bounds else {
            let min = if include_zero { -1.0 } else { 0.0 };
            return AxisRange { min, max: 1.0 };
        };
        if include_zero {
            lo = lo.min(0.0);
            hi = hi.max(0.0);
        }
        let span = hi - lo;
        let magnitude = lo.abs().max(hi.abs());
        if span <= magnitude * 1e-9 || span <= f64::MIN_POSITIVE {
            let c = 0.5 * (lo + hi);
            let half = if c.abs() > 1e-290 {
                c.abs() * 0.05
            } else {
                1.0
            };
            return AxisRange {
                min: c - half,
                max: c + half,
            };
        }
        let pad = 0.05 * span;
        AxisRange {
            min: lo - pad,
            max: hi + pad,
        }
    }
}

/// Tick values of `range`, at most `max` of them, as plotters' mesh chooses them (steps of 1,
/// 2 or 5 times a power of ten); on an axis of whole numbers (`integer`) no tick falls between
/// two of them.
pub(crate) fn tick_values(range: AxisRange, max: usize, integer: bool) -> Vec<f64> {
    if integer {
        return whole_tick_values(range, max);
    }
    let coord: RangedCoordf64 = (range.min..range.max).into();
    coord.key_points(max.max(1))
}

/// Whole-number ticks within `range`, at most `max` of them (at least one where the range
/// holds a whole number): the smallest step of 1, 2 or 5 times a power of ten that keeps
/// their count within `max`.
fn whole_tick_values(range: AxisRange, max: usize) -> Vec<f64> {
    let max = max.max(1);
    let mut unit = 1.0f64;
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = m * unit;
            let first = (range.min / step).ceil() * step;
            let count = ((range.max - first) / step).floor() + 1.0;
            if count <= max as f64 || step >= range.span().max(1.0) {
                let n = count.max(0.0) as usize;
                return (0..n).map(|k| first + k as f64 * step).collect();
            }
        }
        unit *= 10.0;
    }
}

/// Labels of tick values: plain decimals, as many as the step needs, or scientific notation
/// for very large or very small magnitudes; a typographic minus sign.
pub(crate) fn tick_labels(values: &[f64]) -> Vec<String> {
    let step = values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(f64::INFINITY, f64::min);
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scientific = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-3);
    let decimals = |scale: f64| -> usize {
        if !(step.is_finite() && step > 0.0) {
            return if scale == 1.0 { 2 } else { 1 };
        }
        let mut d = 0usize;
        while d < 12 {
            let s = step / scale * 10f64.powi(d as i32);
            if (s - s.round()).abs() <= 1e-6 * s.max(1.0) {
                break;
            }
            d += 1;
        }
        d
    };
    values
        .iter()
        .map(|&v| {
            let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
            let s = if v == 0.0 && scientific {
                "0".to_string()
            } else if scientific {
                let e = max_abs.log10().floor();
                let d = decimals(10f64.powf(e));
                format!("{:.d$}e{}", v / 10f64.powf(e), e as i32)
            } else {
                let d = decimals(1.0);
                format!("{v:.d$}")
            };
            typographic_minus(s)
        })
        .collect()
}

/// Uses a typographic minus sign (U+2212) for negative numbers.
pub(crate) fn typographic_minus(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => s,
    }
}

/// The tick label of `v` among `values` and their `labels` (empty off the ticks).
pub(crate) fn label_of(values: &[f64], labels: &[String], v: f64) -> String {
    values
        .iter()
        .position(|t| (t - v).abs() <= 1e-9 * (t.abs() + v.abs()).max(1e-300))
        .map(|i| labels[i].clone())
        .unwrap_or_default()
}

/// Ticks of an axis: values and labels.
#[derive(Debug, Clone)]
pub(crate) struct Ticks {
    pub values: Vec<f64>,
    pub labels: Vec<String>,
}

impl Ticks {
    /// About `target` ticks: plotters' steps (1, 2 or 5 times a power of ten) can give half
    /// as many as asked for, so the count nearest `target` of those up to `target` + 3 is taken
    /// (the larger one of two as near).
    pub fn new(range: AxisRange, target: usize, integer: bool) -> Self {
        let values = (target..=target + 3)
            .map(|max| tick_values(range, max, integer))
            .min_by_key(|v| ((v.len() as i64 - target as i64).abs(), -(v.len() as i64)))
            .unwrap_or_default();
        let labels = tick_labels(&values);
        Ticks { values, labels }
    }

    pub fn widest(&self, size: f64) -> i32 {
        self.labels
            .iter()
            .map(|l| text_width(l, size))
            .max()
            .unwrap_or(0)
    }

    pub fn label(&self, v: f64) -> String {
        label_of(&self.values, &self.labels, v)
    }

    /// X ticks: as many as fit `width` pixels without overlapping labels.
    pub fn fitting(range: AxisRange, width: i32, size: f64, most: usize, integer: bool) -> Self {
        let mut target = most;
        loop {
            let t = Ticks::new(range, target, integer);
            let spacing = match t.values[..] {
                [a, b, ..] => (b - a) / range.span() * f64::from(width),
                _ => f64::INFINITY,
            };
            if f64::from(t.widest(size)) + 0.7 * size <= spacing || target <= 2 {
                return t;
            }
            target -= 1;
        }
    }
}

/// Whether every finite x of `xs` is a whole number and they span at least one.
pub(crate) fn whole_numbers<'a>(xs: impl Iterator<Item = &'a f64>) -> bool {
    let mut e = Extent::default();
    let mut all = true;
    for &x in xs.filter(|x| plottable(**x)) {
        all &= x.fract() == 0.0;
        e.add(x);
    }
    all && e.bounds.is_some_and(|(a, b)| b - a >= 1.0)
}
