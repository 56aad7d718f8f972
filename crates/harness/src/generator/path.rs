//! Loading paths of slip-controlled tests and the instants a logger samples them at, and the
//! run of a contact through them.

use super::forward::{Contact, GenError};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// One stretch of a slip-controlled test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    /// The load point moves `distance` mm (signed) at `rate` mm/s.
    Slide {
        /// Rate [mm/s], > 0.
        rate: f64,
        /// Distance [mm], signed.
        distance: f64,
    },
    /// The load point holds still.
    Hold {
        /// Duration [s].
        duration: f64,
    },
    /// The load point backs off until the shear has fallen to `fraction` of its value at the
    /// start of the unload (elastic unloading through the rig's stiffness), over `duration` s.
    Unload {
        /// Shear left, as a fraction of the shear at the start.
        fraction: f64,
        /// Duration [s].
        duration: f64,
    },
}

/// How a logger picks its instants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// A fixed interval [s] everywhere.
    Uniform {
        /// Interval [s].
        dt: f64,
    },
    /// A fixed slip per row while sliding (so faster sliding samples faster), within
    /// [`min_dt`, `max_dt`]; holds sampled from `min_hold_dt` on, each interval `hold_growth`
    /// times the last, up to `max_dt` (growth 1: a fixed interval).
    RateAdaptive {
        /// Slip per row while sliding [mm].
        slip_per_row: f64,
        /// Shortest interval [s].
        min_dt: f64,
        /// Longest interval [s].
        max_dt: f64,
        /// First interval of a hold [s].
        min_hold_dt: f64,
        /// Growth of the intervals in a hold.
        hold_growth: f64,
    },
}

/// The sampled response of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Run {
    /// Sample instants [s].
    pub t: Vec<f64>,
    /// Recorded displacement [mm].
    pub u: Vec<f64>,
    /// Shear [kPa].
    pub f: Vec<f64>,
    /// Normal stress [kPa].
    pub p: Vec<f64>,
    /// Rate of the load point at each sample (0 in holds and unloads) [mm/s].
    pub rate: Vec<f64>,
}

impl Run {
    fn push(&mut self, c: &Contact, rate: f64) {
        let s = c.state();
        self.t.push(s.t);
        self.u.push(s.u);
        self.f.push(s.f);
        self.p.push(s.p);
        self.rate.push(rate);
    }
}

/// Nominal instants inside a segment of `duration` s (relative to its start, the last at its
/// end) for a logger sampling at `sampling` while the load point moves at `rate` (0: a hold).
fn instants(sampling: &Sampling, duration: f64, rate: f64) -> Vec<f64> {
    match *sampling {
        Sampling::Uniform { dt } => {
            let n = (duration / dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
            (1..=n).map(|i| i as f64 * duration / n as f64).collect()
        }
        Sampling::RateAdaptive {
            slip_per_row,
            min_dt,
            max_dt,
            min_hold_dt,
            hold_growth,
        } => {
            if rate > 0.0 {
                let dt = (slip_per_row / rate).clamp(min_dt, max_dt);
                let n = (duration / dt * (1.0 - 1e-12)).ceil().max(1.0) as usize;
                (1..=n).map(|i| i as f64 * duration / n as f64).collect()
            } else {
                let mut out = Vec::new();
                let (mut t, mut dt) = (0.0, min_hold_dt);
                while t + dt < duration {
                    t += dt;
                    out.push(t);
                    dt = (dt * hold_growth.max(1.0)).min(max_dt);
                }
                out.push(duration);
                out
            }
        }
    }
}

/// Shifts every instant but a segment's last earlier by up to `jitter` of its interval (a
/// logger's clock that jitters; the order is kept since each instant stays in its own slot).
fn jittered(nominal: Vec<f64>, jitter: f64, rng: &mut ChaCha8Rng) -> Vec<f64> {
    if jitter <= 0.0 {
        return nominal;
    }
    let mut out = nominal.clone();
    for i in 0..nominal.len().saturating_sub(1) {
        let before = if i == 0 { 0.0 } else { nominal[i - 1] };
        out[i] = nominal[i] - jitter * rng.gen::<f64>() * (nominal[i] - before);
    }
    out
}

/// Drives `contact` (at rest, time 0, displacement 0) through `segments` at normal stress `p`,
/// sampling as `sampling` says (instants jittered by `jitter` of their interval). The first
/// row is the state at time 0.
pub fn run(
    contact: &mut Contact,
    segments: &[Segment],
    p: f64,
    sampling: &Sampling,
    jitter: f64,
    rng: &mut ChaCha8Rng,
) -> Result<Run, GenError> {
    let mut out = Run::default();
    out.push(contact, 0.0);
    for seg in segments {
        let (t0, u0) = (contact.state().t, contact.state().u);
        let (duration, distance, rate) = match *seg {
            Segment::Slide { rate, distance } => (distance.abs() / rate, distance, rate),
            Segment::Hold { duration } => (duration, 0.0, 0.0),
            Segment::Unload { fraction, duration } => {
                let f = contact.state().f;
                let back = -(1.0 - fraction) * f / contact.series_stiffness();
                (duration, back, 0.0)
            }
        };
        if duration <= 0.0 {
            continue;
        }
        let times = jittered(instants(sampling, duration, rate), jitter, rng);
        for dt in times {
            contact.slide_to(t0 + dt, u0 + distance * dt / duration, p)?;
            out.push(contact, rate);
        }
    }
    Ok(out)
}

/// Drives `contact` under shear control through the rows (`time`, `shear`) at normal stress
/// `p`, sampling at the rows.
pub fn run_shear(
    contact: &mut Contact,
    time: &[f64],
    shear: &[f64],
    p: f64,
) -> Result<Run, GenError> {
    let mut out = Run::default();
    out.push(contact, 0.0);
    for (t, f) in time.iter().zip(shear).skip(1) {
        contact.load_to(*t, *f, p)?;
        out.push(contact, 0.0);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn adaptive_sampling_is_dense_when_fast_and_sparse_in_holds() {
        let s = Sampling::RateAdaptive {
            slip_per_row: 0.005,
            min_dt: 0.01,
            max_dt: 20.0,
            min_hold_dt: 0.5,
            hold_growth: 1.5,
        };
        assert_eq!(instants(&s, 10.0, 0.1).len(), 200);
        assert_eq!(instants(&s, 100.0, 0.01).len(), 200);
        let hold = instants(&s, 1000.0, 0.0);
        assert!(hold.len() < 70, "{} rows in a 1000-s hold", hold.len());
        assert!(hold[0] == 0.5 && (hold[hold.len() - 1] - 1000.0).abs() < 1e-12);
        let gaps: Vec<f64> = hold.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(gaps.iter().all(|&g| g <= 20.0 + 1e-9));
    }

    #[test]
    fn jitter_keeps_the_order_and_stays_within_its_fraction() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let nominal: Vec<f64> = (1..=1000).map(|i| i as f64).collect();
        let j = jittered(nominal.clone(), 0.3, &mut rng);
        assert_eq!(j[999], 1000.0);
        let mut moved = 0;
        for i in 0..999 {
            let shift = nominal[i] - j[i];
            assert!((0.0..=0.3 + 1e-12).contains(&shift), "{i}: {shift}");
            moved += (shift > 0.15) as usize;
            if i > 0 {
                assert!(j[i] > j[i - 1]);
            }
        }
        assert!(moved > 300, "the clock hardly jitters: {moved}");
    }
}
