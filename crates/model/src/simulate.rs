//! Driving the model through a test: rows of (time, imposed slip or shear, normal stress).

use crate::contact1::{Contact1, State1};
use crate::integrator::{Consts, StepError};
use crate::Model;
use serde::{Deserialize, Serialize};

/// Which quantity the apparatus imposed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Control {
    /// Slip history imposed, shear measured (displacement control).
    Slip,
    /// Shear traction imposed, slip measured (stress control).
    Shear,
}

/// How a test starts.
///
/// ```
/// use subfric_model::Initial;
/// let i: Initial = serde_json::from_str(r#"{"kind": "sliding", "shear_kpa": 60, "rate_mm_s": 0.01}"#).unwrap();
/// assert_eq!(i, Initial::Sliding { shear_kpa: 60.0, rate_mm_s: 0.01 });
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Initial {
    /// An interface at rest: under slip control unloaded (zero traction, r = 0, μ = μ₀), under
    /// traction control at the imposed traction, inside the surface.
    #[default]
    Rest,
    /// At rest under a traction (a file that starts in a hold, e.g. while the normal stress is
    /// raised): elastic, r = |τ|/(μ_eff p) with μ = μ₀. Under traction control the imposed
    /// first value is used instead of `shear_kpa`.
    Loaded {
        /// Traction at the first row [kPa], signed.
        shear_kpa: f64,
    },
    /// Already sliding at the first row (a segment cut out of a longer run): on the loading
    /// surface (r = 1) at the traction, steady at that slip rate (the rate-and-state variable
    /// too). With slip hardening, μ is steady and the traction gives the slip accumulated
    /// before the file began; otherwise μ is taken from the traction (within [μ_k, μ_s]).
    Sliding {
        /// Traction at the first row [kPa], signed.
        shear_kpa: f64,
        /// Slip rate at the first row [mm/s].
        rate_mm_s: f64,
    },
}

/// A test as the model sees it: one row per instant.
#[derive(Clone, Copy, Debug)]
pub struct Protocol<'a> {
    /// Which column is imposed.
    pub control: Control,
    /// Time [s], strictly increasing.
    pub time: &'a [f64],
    /// The imposed column: slip [mm] or shear [kPa].
    pub imposed: &'a [f64],
    /// Normal stress per row [kPa], > 0.
    pub normal: &'a [f64],
    /// Slip at the first row for traction control [mm] (ignored under slip control).
    pub initial_slip: f64,
    /// How the test starts.
    pub initial: Initial,
}

/// Why a simulation failed, with the row where it happened.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimError {
    /// The protocol itself is unusable.
    #[error("row {row}: field `{field}`: {message}")]
    Input {
        /// 0-based row index.
        row: usize,
        /// Column name.
        field: &'static str,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Under traction control the imposed shear exceeded the friction capacity.
    #[error("row {row} (t = {time} s): runaway sliding: imposed shear {target_kpa:.3} kPa exceeds the friction capacity {capacity_kpa:.3} kPa")]
    Runaway {
        /// 0-based row index.
        row: usize,
        /// Time of that row [s].
        time: f64,
        /// Imposed shear magnitude [kPa].
        target_kpa: f64,
        /// Capacity [kPa].
        capacity_kpa: f64,
    },
    /// A step failed even when split into substeps.
    #[error("row {row} (t = {time} s): {source}")]
    Step {
        /// 0-based row index.
        row: usize,
        /// Time of that row [s].
        time: f64,
        /// The failure of the last substep tried.
        source: StepError,
    },
}

/// The model's response along a protocol.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Trajectory {
    /// Slip [mm] (imposed or predicted).
    pub slip: Vec<f64>,
    /// Shear [kPa] (imposed or predicted).
    pub shear: Vec<f64>,
    /// Friction coefficient μ.
    pub mu: Vec<f64>,
    /// Normal-yield ratio r.
    pub r: Vec<f64>,
    /// Plastic slip increment of each step [mm], signed.
    pub plastic_increment: Vec<f64>,
}

impl Trajectory {
    /// The predicted (non-imposed) column for `control`.
    pub fn predicted(&self, control: Control) -> &[f64] {
        match control {
            Control::Slip => &self.shear,
            Control::Shear => &self.slip,
        }
    }
}

/// Most substeps a failing step is split into before giving up.
pub const MAX_SUBSTEPS: usize = 64;

/// Largest share of the friction capacity μ_s p that the spacing of doubles at a slip may
/// reach once α_t turns it into shear: 0.1 %, below the noise of any shear measurement.
pub const SLIP_RESOLUTION_SHARE: f64 = 1e-3;

/// The model's view of a slip's floating-point resolution. The step adds α_t Δu to the
/// traction, and a slip u is only known to the spacing of doubles near it (2.2·10⁻¹⁶ |u|), so
/// a slip-controlled traction is only known to α_t times that spacing: at u = 10¹¹ mm and
/// α_t = 2000 kN/mm³, 3·10⁴ kPa — the elastic slip is lost and the shear is noise. The model
/// depends on slip differences only, so such a record is refused with the advice to subtract
/// a constant from its slip.
struct SlipResolution {
    /// α_t [kPa/mm].
    alpha: f64,
    /// α_t [kN/mm³], for messages.
    alpha_t: f64,
    /// μ_s × [`SLIP_RESOLUTION_SHARE`].
    share_of_mu_s: f64,
}

impl SlipResolution {
    fn new(model: &Model) -> Self {
        SlipResolution {
            alpha: model.params.alpha_t_kpa_per_mm(),
            alpha_t: model.params.alpha_t,
            share_of_mu_s: SLIP_RESOLUTION_SHARE * model.params.mu_s,
        }
    }

    /// Refuses slip `u` at normal stress `p` where it is not resolved (row and field named).
    #[inline]
    fn check(&self, u: f64, p: f64, row: usize, field: &'static str) -> Result<(), SimError> {
        let a = u.abs();
        // The next double above a finite a ≥ 0 (infinite above f64::MAX: refused).
        let spacing = f64::from_bits(a.to_bits() + 1) - a;
        let allowed = self.share_of_mu_s * p;
        if self.alpha * spacing <= allowed {
            return Ok(());
        }
        // Doubles in [2^e, 2^(e+1)) are 2^(e−52) apart: the largest resolved binade.
        let largest = 2f64.powf((allowed / self.alpha).log2().floor() + 53.0);
        // The normal stress at which this slip would be resolved: the other way to read it (a
        // normal stress of 1e-9 kPa, a unit mistake, makes every ordinary slip unresolved).
        let least_p = self.alpha * spacing / self.share_of_mu_s;
        Err(SimError::Input {
            row,
            field,
            message: format!(
                "slip {u:e} mm at a normal stress of {p:e} kPa is beyond what this model \
                 resolves: doubles near the slip are {spacing:.2e} mm apart, which α_t = {} \
                 kN/mm³ turns into steps of {:.3e} kPa in the shear, more than {}% of the \
                 friction capacity μ_s p = {:.4e} kPa (expected |slip| < {largest:.3e} mm at \
                 this normal stress, or a normal stress above {least_p:.3e} kPa for this slip: \
                 check the normal stress's value and unit; the model depends only on slip \
                 differences: subtract a constant from the slip)",
                self.alpha_t,
                self.alpha * spacing,
                100.0 * SLIP_RESOLUTION_SHARE,
                allowed / SLIP_RESOLUTION_SHARE,
            ),
        })
    }
}

impl Initial {
    /// Checks the numbers of a start: a finite traction, and a finite slip rate ≥ 0 (a speed:
    /// the direction of sliding is the sign of the traction).
    fn check_numbers(&self) -> Result<(), SimError> {
        let input = |field, message: String| {
            Err(SimError::Input {
                row: 0,
                field,
                message,
            })
        };
        let (shear, rate) = match *self {
            Initial::Rest => return Ok(()),
            Initial::Loaded { shear_kpa } => (shear_kpa, None),
            Initial::Sliding {
                shear_kpa,
                rate_mm_s,
            } => (shear_kpa, Some(rate_mm_s)),
        };
        if !shear.is_finite() {
            return input(
                "initial.shear_kpa",
                format!("expected a finite traction at the first row [kPa], got {shear}"),
            );
        }
        match rate {
            Some(v) if !(v.is_finite() && v >= 0.0) => input(
                "initial.rate_mm_s",
                format!(
                    "expected a finite slip rate >= 0 [mm/s] (a speed: the direction of \
                     sliding is the sign of shear_kpa), got {v}"
                ),
            ),
            _ => Ok(()),
        }
    }
}

fn check_protocol(model: &Model, p: &Protocol) -> Result<(), SimError> {
    if !p.initial_slip.is_finite() {
        return Err(SimError::Input {
            row: 0,
            field: "initial_slip",
            message: format!(
                "expected a finite slip at the first row [mm], got {}",
                p.initial_slip
            ),
        });
    }
    p.initial.check_numbers()?;
    let n = p.time.len();
    for (field, len) in [("imposed", p.imposed.len()), ("normal_kpa", p.normal.len())] {
        if len != n {
            return Err(SimError::Input {
                row: len.min(n),
                field,
                message: format!("column has {len} rows but time_s has {n}"),
            });
        }
    }
    // The largest slip and the least normal stress, for the resolution check below.
    let (mut largest, mut least) = (0.0f64, f64::INFINITY);
    for i in 0..n {
        largest = largest.max(p.imposed[i].abs());
        least = least.min(p.normal[i]);
        if !p.time[i].is_finite() || (i > 0 && p.time[i] <= p.time[i - 1]) {
            return Err(SimError::Input {
                row: i,
                field: "time_s",
                message: format!(
                    "expected a finite time greater than the previous row, got {}",
                    p.time[i]
                ),
            });
        }
        if !p.imposed[i].is_finite() {
            return Err(SimError::Input {
                row: i,
                field: "imposed",
                message: format!("expected a finite number, got {}", p.imposed[i]),
            });
        }
        if !(p.normal[i] > 0.0 && p.normal[i].is_finite()) {
            return Err(SimError::Input {
                row: i,
                field: "normal_kpa",
                message: format!(
                    "expected a finite normal stress > 0 kPa, got {}",
                    p.normal[i]
                ),
            });
        }
    }
    let resolution = SlipResolution::new(model);
    match p.control {
        // The spacing grows with |u| and the allowance with p: the largest slip at the least
        // normal stress decides for every row, and only a refusal needs the row.
        Control::Slip if n > 0 => {
            if resolution.check(largest, least, 0, "imposed").is_err() {
                for (i, (&u, &normal)) in p.imposed.iter().zip(p.normal).enumerate() {
                    resolution.check(u, normal, i, "imposed")?;
                }
            }
        }
        Control::Slip => {}
        Control::Shear => {
            if let Some(&normal) = p.normal.first() {
                resolution.check(p.initial_slip, normal, 0, "initial_slip")?;
            }
        }
    }
    Ok(())
}

/// One row's step, split into substeps when the return mapping fails.
#[inline]
#[allow(clippy::too_many_arguments)]
fn advance(
    c: &mut Contact1,
    st: &State1,
    control: Control,
    target: f64,
    prev_target: f64,
    p: f64,
    prev_p: f64,
    dt: f64,
) -> Result<State1, StepError> {
    let step = |c: &mut Contact1, st: &State1, x: f64, p: f64, dt: f64| match control {
        Control::Slip => c.step_slip(st, x, p, dt),
        Control::Shear => c.step_shear(st, x, p, dt),
    };
    let err = match step(c, st, target, p, dt) {
        Ok(s) => return Ok(s),
        Err(e @ StepError::Runaway { .. }) => return Err(e),
        Err(e) => e,
    };
    let mut last = err;
    let mut n = 2;
    while n <= MAX_SUBSTEPS {
        let mut s = *st;
        let mut ok = true;
        for j in 1..=n {
            let f = j as f64 / n as f64;
            let x = prev_target + f * (target - prev_target);
            let pj = prev_p + f * (p - prev_p);
            match step(c, &s, x, pj, dt / n as f64) {
                Ok(next) => s = next,
                Err(e @ StepError::Runaway { .. }) => return Err(e),
                Err(e) => {
                    last = e;
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            return Ok(s);
        }
        n *= 2;
    }
    Err(last)
}

fn initial_state(model: &Model, proto: &Protocol) -> Result<State1, SimError> {
    start(model, proto).map(|(st, _)| st)
}

/// The state at the first row, and the traction it starts under with the most the model
/// carries there (`None` for an unloaded start): at rest, the surface at μ₀; sliding, the
/// surface of a contact sliding at the given rate.
fn start(model: &Model, proto: &Protocol) -> Result<(State1, Option<(f64, f64)>), SimError> {
    let p = proto.normal[0];
    let mut st = State1::virgin_at(model, proto.imposed[0], p);
    let control = proto.control;
    if control == Control::Shear {
        st.slip = proto.initial_slip;
    }
    let shear = match (control, proto.initial) {
        (Control::Shear, _) => proto.imposed[0],
        (Control::Slip, Initial::Rest) => return Ok((st, None)),
        (Control::Slip, Initial::Loaded { shear_kpa })
        | (Control::Slip, Initial::Sliding { shear_kpa, .. }) => shear_kpa,
    };
    if !shear.is_finite() {
        return Err(SimError::Input {
            row: 0,
            field: "initial",
            message: format!("expected a finite initial traction, got {shear}"),
        });
    }
    let k = Consts::new(&model.params, &model.ext);
    let sign = if shear < 0.0 { -1.0 } else { 1.0 };
    let l = k.local(p, sign);
    st.shear = shear;
    let (r, cap) = match proto.initial {
        Initial::Sliding { rate_mm_s, .. } => {
            let v = rate_mm_s.abs();
            // A segment of a long run: steady at its rate. With slip hardening the traction
            // then tells the slip accumulated before the file began; otherwise μ is taken from
            // the traction.
            match k.steady_history(&l, shear.abs() / p, v) {
                Some((mu, slip_path)) => {
                    st.mu = mu;
                    st.slip_path = slip_path;
                }
                None => st.mu = k.sliding_mu(&l, shear.abs() / p, v),
            }
            // The families' state too (θ at its steady state, the rate terms of the slide).
            k.steady_state(&mut st.slots, v);
            // The surface of a contact sliding at that rate (not the one at rest, which a
            // velocity-weakening form puts higher).
            let cap = k.sliding_mu_eff(&l, st.mu, v, st.slip_path, st.time) * p;
            // On the surface; above it, the first step returns the traction onto it.
            let r = if shear.abs() >= 0.999 * cap {
                1.0
            } else {
                shear.abs() / cap
            };
            (r, cap)
        }
        _ => {
            let cap = k.elastic_mu_eff::<true>(&l, st.mu, &st.slots, 0.0, st.time) * p;
            if shear.abs() > cap {
                if control == Control::Shear {
                    return Err(SimError::Runaway {
                        row: 0,
                        time: proto.time[0],
                        target_kpa: shear.abs(),
                        capacity_kpa: cap,
                    });
                }
                (1.0, cap)
            } else {
                (shear.abs() / cap, cap)
            }
        }
    };
    st.r = r;
    (st.sin_r, st.cos_r) = (std::f64::consts::FRAC_PI_2 * r).sin_cos();
    Ok((st, Some((shear, cap))))
}

/// Relative slack of [`check_start`] on the capacity (round-off of μ_eff p).
const CAPACITY_SLACK: f64 = 1e-9;

/// Checks a start given by hand (not read off a record) against the model: a traction at
/// rest within the friction capacity at μ₀, a sliding traction within what a contact of this
/// model carries when sliding at the given rate. [`simulate`] itself accepts a start above
/// the capacity — a record's first row may lie above the surface of parameters a fit is
/// trying, and the first step returns the traction onto it — but a start given by hand above
/// it is a mistake, not a state: its answer would be the model's, not the one asked for.
///
/// ```
/// use subfric_model::{check_start, Control, Initial, Model, Params, Protocol};
/// let model = Model::base(Params::sample()).unwrap(); // μ_s = 0.45: 45 kPa at 100 kPa
/// let (t, u, n) = ([0.0, 1.0], [0.0, 0.01], [100.0, 100.0]);
/// let proto = |initial| Protocol { control: Control::Slip, time: &t, imposed: &u, normal: &n, initial_slip: 0.0, initial };
/// assert!(check_start(&model, &proto(Initial::Loaded { shear_kpa: 40.0 })).is_ok());
/// let e = check_start(&model, &proto(Initial::Loaded { shear_kpa: 1000.0 })).unwrap_err();
/// assert!(e.to_string().contains("capacity 45"), "{e}");
/// ```
pub fn check_start(model: &Model, proto: &Protocol) -> Result<(), SimError> {
    check_protocol(model, proto)?;
    if proto.time.is_empty() {
        return Ok(());
    }
    let Some((shear, cap)) = start(model, proto)?.1 else {
        return Ok(());
    };
    if shear.abs() <= cap * (1.0 + CAPACITY_SLACK) {
        return Ok(());
    }
    let p = proto.normal[0];
    let (field, what) = match (proto.control, proto.initial) {
        (Control::Shear, _) => ("imposed", format!("the first imposed shear {shear} kPa")),
        (_, Initial::Sliding { rate_mm_s, .. }) => (
            "initial.shear_kpa",
            format!("a start sliding at {rate_mm_s} mm/s under {shear} kPa"),
        ),
        _ => (
            "initial.shear_kpa",
            format!("a start at rest under {shear} kPa"),
        ),
    };
    let state = match proto.initial {
        Initial::Sliding { .. } => "sliding at that rate",
        _ => "at rest",
    };
    Err(SimError::Input {
        row: 0,
        field,
        message: format!(
            "{what} exceeds the friction capacity {cap:.4} kPa of this model {state} under \
             {p} kPa (expected |shear_kpa| <= {cap:.4}: a contact cannot hold more)"
        ),
    })
}

/// Runs `proto` row by row, handing each row's state to `sink`; stops where `sink` answers
/// false (`Ok(false)`), else `Ok(true)` after the last row.
fn run<F: FnMut(usize, &State1) -> bool>(
    model: &Model,
    proto: &Protocol,
    mut sink: F,
) -> Result<bool, SimError> {
    check_protocol(model, proto)?;
    if proto.time.is_empty() {
        return Ok(true);
    }
    let resolution = SlipResolution::new(model);
    let mut c = Contact1::new(model);
    let mut st = initial_state(model, proto)?;
    if !sink(0, &st) {
        return Ok(false);
    }
    for i in 1..proto.time.len() {
        let dt = proto.time[i] - proto.time[i - 1];
        st = advance(
            &mut c,
            &st,
            proto.control,
            proto.imposed[i],
            proto.imposed[i - 1],
            proto.normal[i],
            proto.normal[i - 1],
            dt,
        )
        .map_err(|e| match e {
            StepError::Runaway {
                target_kpa,
                capacity_kpa,
            } => SimError::Runaway {
                row: i,
                time: proto.time[i],
                target_kpa,
                capacity_kpa,
            },
            source => SimError::Step {
                row: i,
                time: proto.time[i],
                source,
            },
        })?;
        // Under traction control the slip is the model's: it must stay where it is resolved.
        if proto.control == Control::Shear {
            resolution.check(st.slip, proto.normal[i], i, "slip")?;
        }
        if !sink(i, &st) {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Simulates a whole protocol and returns every state variable per row.
///
/// ```
/// use subfric_model::{simulate, Control, Model, Params, Protocol};
/// let model = Model::base(Params::sample()).unwrap();
/// let time: Vec<f64> = (0..=300).map(|i| i as f64).collect();
/// let slip: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
/// let normal = vec![100.0; time.len()];
/// let proto = Protocol { control: Control::Slip, time: &time, imposed: &slip, normal: &normal, initial_slip: 0.0, initial: Default::default() };
/// let out = simulate(&model, &proto).unwrap();
/// let peak = out.shear.iter().cloned().fold(0.0, f64::max);
/// assert!(peak > 40.0 && peak <= 45.0); // below μ_s f_n = 45 kPa
/// ```
pub fn simulate(model: &Model, proto: &Protocol) -> Result<Trajectory, SimError> {
    let n = proto.time.len();
    let mut out = Trajectory {
        slip: Vec::with_capacity(n),
        shear: Vec::with_capacity(n),
        mu: Vec::with_capacity(n),
        r: Vec::with_capacity(n),
        plastic_increment: Vec::with_capacity(n),
    };
    run(model, proto, |_, st| {
        out.slip.push(st.slip);
        out.shear.push(st.shear);
        out.mu.push(st.mu);
        out.r.push(st.r);
        out.plastic_increment.push(st.last_plastic);
        true
    })?;
    Ok(out)
}

/// Simulates a protocol writing only the predicted column (shear under slip control, slip
/// under traction control) into `out`, resized to the number of rows. The fast path of fitting.
pub fn simulate_predicted_into(
    model: &Model,
    proto: &Protocol,
    out: &mut Vec<f64>,
) -> Result<(), SimError> {
    simulate_predicted_while(model, proto, out, |_, _| true).map(|_| ())
}

/// [`simulate_predicted_into`] that asks `go_on(row, predicted)` after each row and stops the
/// run where it answers false: `Ok(true)` when every row was simulated, `Ok(false)` when the
/// caller stopped it (rows after the stop are left at zero). An optimiser that only needs to
/// know whether a trial point is worse than its current one stops the trial where it already
/// is; the rows it does simulate are those of the whole run, bit for bit.
pub fn simulate_predicted_while(
    model: &Model,
    proto: &Protocol,
    out: &mut Vec<f64>,
    mut go_on: impl FnMut(usize, f64) -> bool,
) -> Result<bool, SimError> {
    out.clear();
    out.resize(proto.time.len(), 0.0);
    let control = proto.control;
    run(model, proto, |i, st| {
        let v = match control {
            Control::Slip => st.shear,
            Control::Shear => st.slip,
        };
        out[i] = v;
        go_on(i, v)
    })
}
