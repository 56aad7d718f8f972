//! Axis ranges, tick positions and tick labels.

/// Values whose magnitude exceeds this are treated like NaN (skipped), so
/// that ranges and their padding stay finite.
pub const MAX_ABS_VALUE: f64 = 1e300;

/// Whether a value can be drawn.
pub(crate) fn plottable(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_ABS_VALUE
}

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

    /// The padded axis range: 5 % of the span on each side; an all-equal
    /// extent gets ±5 % of its value (±1 around 0); no data gives 0..1
    /// (−1..1 when zero must be inside).
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
        if span <= magnitude * 1e-12 || span <= f64::MIN_POSITIVE {
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

/// Tick positions and their labels.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ticks {
    pub values: Vec<f64>,
    pub labels: Vec<String>,
}

/// The smallest "nice" step (1, 2, 2.5 or 5 times a power of ten) that is
/// at least `raw`.
pub(crate) fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let mag = 10f64.powf(raw.log10().floor());
    let norm = raw / mag;
    let m = if norm <= 1.0 + 1e-9 {
        1.0
    } else if norm <= 2.0 + 1e-9 {
        2.0
    } else if norm <= 2.5 + 1e-9 {
        2.5
    } else if norm <= 5.0 + 1e-9 {
        5.0
    } else {
        10.0
    };
    m * mag
}

/// The "nice" step (1, 2, 2.5 or 5 times a power of ten, 2.5 only when
/// clearly better) giving the number of intervals closest to `target`,
/// never more than `target` + 2.
fn step_near(span: f64, target: usize) -> f64 {
    let raw = span / target as f64;
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let k = raw.log10().floor();
    let target = target as f64;
    let mut best = (f64::INFINITY, nice_step(raw));
    for e in [k - 1.0, k, k + 1.0] {
        let mag = 10f64.powf(e);
        for (m, penalty) in [(1.0, 0.0), (2.0, 0.0), (2.5, 0.6), (5.0, 0.0)] {
            let step = m * mag;
            let n = span / step;
            if !step.is_finite() || step <= 0.0 || n > target + 2.0 {
                continue;
            }
            let cost = (n - target).abs() + penalty;
            if cost < best.0 {
                best = (cost, step);
            }
        }
    }
    best.1
}

/// Ticks inside `range` with about `target` intervals.
pub(crate) fn ticks(range: AxisRange, target: usize) -> Ticks {
    let target = target.clamp(1, 20);
    let span = range.span();
    let mut step = step_near(span, target);
    // Guard against float trouble: never more than 50 ticks.
    while span / step > 50.0 {
        step = nice_step(step * 1.01);
    }
    let first = (range.min / step).ceil();
    let mut values = Vec::new();
    let mut k = first;
    loop {
        let mut v = k * step;
        if v > range.max + step * 1e-9 || values.len() > 60 {
            break;
        }
        if v.abs() < step * 1e-9 {
            v = 0.0;
        }
        values.push(v);
        k += 1.0;
    }
    let labels = format_ticks(&values, step);
    Ticks { values, labels }
}

/// Number of decimals needed to print multiples of `step` exactly.
fn decimals_for(step: f64) -> usize {
    if !(step.is_finite() && step > 0.0) {
        return 0;
    }
    let mut d = (-step.log10()).ceil().max(0.0) as usize;
    while d < 12 {
        let scaled = step * 10f64.powi(d as i32);
        if (scaled - scaled.round()).abs() <= 1e-6 * scaled.max(1.0) {
            break;
        }
        d += 1;
    }
    d.min(12)
}

/// Uses a typographic minus sign (U+2212) for negative numbers.
pub(crate) fn typographic_minus(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) => format!("\u{2212}{rest}"),
        None => s,
    }
}

/// Labels for tick values that are multiples of `step`: plain decimals, or
/// scientific notation for very large or very small magnitudes; negative
/// values get a typographic minus sign.
pub(crate) fn format_ticks(values: &[f64], step: f64) -> Vec<String> {
    format_ticks_ascii(values, step)
        .into_iter()
        .map(typographic_minus)
        .collect()
}

fn format_ticks_ascii(values: &[f64], step: f64) -> Vec<String> {
    let max_abs = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let scientific = max_abs >= 1e5 || (max_abs > 0.0 && max_abs < 1e-3);
    if !scientific {
        let d = decimals_for(step);
        return values.iter().map(|v| format!("{v:.d$}")).collect();
    }
    // Same number of mantissa decimals for all labels, enough to tell
    // neighbouring ticks apart.
    let step_exp = step.log10().floor();
    let max_exp = values
        .iter()
        .filter(|v| **v != 0.0)
        .map(|v| v.abs().log10().floor())
        .fold(f64::NEG_INFINITY, f64::max);
    let mut d = if max_exp.is_finite() {
        (max_exp - step_exp).max(0.0) as usize
    } else {
        0
    };
    let norm = step / 10f64.powf(step_exp);
    if (norm - 2.5).abs() < 1e-6 {
        d += 1;
    }
    let d = d.min(12);
    values
        .iter()
        .map(|v| {
            if *v == 0.0 {
                "0".to_string()
            } else {
                format!("{v:.d$e}")
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range(lo: f64, hi: f64) -> AxisRange {
        AxisRange { min: lo, max: hi }
    }

    #[test]
    fn padded_ranges() {
        let mut e = Extent::default();
        assert_eq!(e.padded(false), range(0.0, 1.0));
        assert_eq!(e.padded(true), range(-1.0, 1.0));
        e.add(f64::NAN);
        e.add(f64::INFINITY);
        e.add(1e308);
        assert_eq!(e.padded(false), range(0.0, 1.0));
        e.add(5.0);
        let r = e.padded(false);
        assert!(r.min < 5.0 && r.max > 5.0 && r.span() > 0.1);
        e.add(0.0);
        e.add(10.0);
        assert_eq!(e.padded(false), range(-0.5, 10.5));
        let mut z = Extent::default();
        z.add(0.0);
        assert_eq!(z.padded(false), range(-1.0, 1.0));
        let mut pos = Extent::default();
        pos.add(2.0);
        pos.add(4.0);
        assert_eq!(pos.padded(true), range(-0.2, 4.2));
        let mut huge = Extent::default();
        huge.add(-1e300);
        huge.add(1e300);
        let r = huge.padded(false);
        assert!(r.min.is_finite() && r.max.is_finite() && r.span().is_finite());
    }

    #[test]
    fn nice_ticks() {
        let t = ticks(range(-0.5, 10.5), 5);
        assert_eq!(t.values, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        let t = ticks(range(-88.0, 88.0), 7);
        assert_eq!(t.labels[0], "\u{2212}75");
        let t = ticks(range(-0.5, 10.5), 4);
        assert_eq!(t.labels, vec!["0.0", "2.5", "5.0", "7.5", "10.0"]);
        let t = ticks(range(-0.5, 10.5), 6);
        assert_eq!(t.labels, vec!["0", "2", "4", "6", "8", "10"]);
        let t = ticks(range(-0.13, 0.13), 5);
        assert!(t.labels.contains(&"0.00".to_string()) || t.labels.contains(&"0.0".to_string()));
        assert!(t.labels[0].starts_with('\u{2212}'), "{:?}", t.labels);
        // No negative zero.
        assert!(!t
            .labels
            .iter()
            .any(|l| l.starts_with('\u{2212}') && l.chars().skip(1).all(|c| c == '0' || c == '.')));
        let t = ticks(range(0.0, 2.5e-4), 5);
        assert!(
            t.labels.iter().all(|l| l == "0" || l.contains('e')),
            "{:?}",
            t.labels
        );
        let t = ticks(range(0.0, 2e6), 4);
        assert!(t.labels.iter().any(|l| l.contains("e6")), "{:?}", t.labels);
        let t = ticks(range(4.75, 5.25), 5);
        assert!(t.values.len() >= 3);
        let t = ticks(range(-1e300, 1e300), 5);
        assert!(!t.values.is_empty() && t.values.len() < 60);
        let t = ticks(range(1.0, 1.0 + 1e-9), 8);
        assert!(!t.values.is_empty() && t.values.len() < 60);
    }

    #[test]
    fn step_rounding() {
        assert_eq!(nice_step(0.3), 0.5);
        assert_eq!(nice_step(2.2), 2.5);
        assert_eq!(nice_step(7.0), 10.0);
        assert_eq!(nice_step(f64::NAN), 1.0);
        assert_eq!(decimals_for(0.25), 2);
        assert_eq!(decimals_for(2.5), 1);
        assert_eq!(decimals_for(20.0), 0);
    }
}
