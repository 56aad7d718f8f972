//! A value read off a record with its 95 % interval.

use serde::Serialize;

/// A value with its 95 % interval (ends infinite where open).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Best value.
    pub value: f64,
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

impl Estimate {
    /// value ± half.
    pub fn symmetric(value: f64, half: f64) -> Estimate {
        let half = if half.is_finite() {
            half
        } else {
            f64::INFINITY
        };
        Estimate {
            value,
            lo: value - half,
            hi: value + half,
        }
    }

    /// A value with no interval.
    pub fn open(value: f64) -> Estimate {
        Estimate::symmetric(value, f64::INFINITY)
    }

    /// Half the width of the interval.
    pub fn half_width(&self) -> f64 {
        0.5 * (self.hi - self.lo)
    }

    /// True when the interval excludes zero.
    pub fn excludes_zero(&self) -> bool {
        self.lo > 0.0 || self.hi < 0.0
    }

    /// This estimate with its interval widened to cover `other`'s (another reading of the
    /// same quantity); the value stays this one's.
    pub fn covering(&self, other: &Estimate) -> Estimate {
        Estimate {
            value: self.value,
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }
}
