//! A 95 % interval with ends that may be open (the profile reached the box wall without the
//! cost rising enough: the data set no bound there), shared by parameters and combinations so
//! that both are judged and printed by the same rule.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A quantity counts as determined when its interval is closed and its half-width is at most
/// this fraction of its scale (the value, or a floor for quantities near zero).
pub const DETERMINED_HALF_WIDTH: f64 = 0.10;

/// An interval [lo, hi]; an open end means "at least as far as this": the data allow values
/// beyond it. In `fit.json`: `{"lo": …, "hi": …, "lo_open": …, "hi_open": …}`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
    /// The data set no lower bound: `lo` is where the search stopped (a box wall).
    pub lo_open: bool,
    /// The data set no upper bound: `hi` is where the search stopped (a box wall).
    pub hi_open: bool,
}

impl Interval {
    /// A closed interval.
    pub fn closed(lo: f64, hi: f64) -> Interval {
        Interval {
            lo,
            hi,
            lo_open: false,
            hi_open: false,
        }
    }

    /// The same interval widened to contain `v` (a fitted value always lies in its interval,
    /// even when interpolation of the profile put an end a hair inside it).
    pub fn including(self, v: f64) -> Interval {
        Interval {
            lo: self.lo.min(v),
            hi: self.hi.max(v),
            ..self
        }
    }

    /// Half the width.
    pub fn half_width(&self) -> f64 {
        0.5 * (self.hi - self.lo)
    }

    /// Both ends bounded by the data.
    pub fn is_closed(&self) -> bool {
        !self.lo_open && !self.hi_open
    }

    /// Whether `v` lies inside (ends included).
    pub fn contains(&self, v: f64) -> bool {
        self.lo <= v && v <= self.hi
    }

    /// Closed, and half-width within [`DETERMINED_HALF_WIDTH`] of `scale`.
    pub fn determines(&self, scale: f64) -> bool {
        self.is_closed() && self.half_width() <= DETERMINED_HALF_WIDTH * scale
    }
}

/// A number as the reports print it: 4 decimals, or scientific notation when very large or
/// small.
pub fn short_number(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e4 || v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// `[a, b]`, with an open end written `(≤a` or `b≥)`.
impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}, {}{}",
            if self.lo_open { "(≤" } else { "[" },
            short_number(self.lo),
            short_number(self.hi),
            if self.hi_open { "≥)" } else { "]" }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_marks_open_ends() {
        let i = Interval {
            lo: 0.0,
            hi: 12345.0,
            lo_open: true,
            hi_open: false,
        };
        assert_eq!(i.to_string(), "(≤0, 1.234e4]");
        assert_eq!(Interval::closed(0.25, 0.5).to_string(), "[0.2500, 0.5000]");
    }

    #[test]
    fn determined_needs_closed_and_narrow() {
        let narrow = Interval::closed(0.95, 1.05);
        assert!(narrow.determines(1.0));
        assert!(!Interval::closed(0.85, 1.15).determines(1.0));
        assert!(!Interval {
            hi_open: true,
            ..narrow
        }
        .determines(1.0));
    }

    #[test]
    fn json_shape_is_named_ends() {
        let v = serde_json::to_value(Interval::closed(1.0, 2.0)).unwrap();
        assert_eq!(
            v,
            serde_json::json!({"lo": 1.0, "hi": 2.0, "lo_open": false, "hi_open": false})
        );
    }
}
