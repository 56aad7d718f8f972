//! Declarative loading scenarios, so users can explore the model without data.
//!
//! ```
//! use subfric_model::{Scenario, Stage, Control};
//! let sc: Scenario = serde_json::from_str(r#"{
//!   "name": "shs", "control": "slip", "normal_stress_kpa": 100, "dt_s": 0.5,
//!   "stages": [ {"type": "slide", "rate_mm_s": 0.01, "distance_mm": 1.0},
//!               {"type": "hold", "duration_s": 100},
//!               {"type": "slide", "rate_mm_s": 0.01, "distance_mm": 1.0} ] }"#).unwrap();
//! let rows = sc.rows().unwrap();
//! assert_eq!(rows.time.len(), 601);
//! assert!((rows.imposed.last().unwrap() - 2.0).abs() < 1e-12);
//! ```

use crate::contact3::Vec3;
use crate::simulate::Control;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// One stage of a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Stage {
    /// Slip control: slide at `rate_mm_s` over `distance_mm` (negative distance slides backward).
    Slide {
        /// Slip rate magnitude [mm/s].
        rate_mm_s: f64,
        /// Signed distance [mm].
        distance_mm: f64,
    },
    /// Hold the imposed quantity constant.
    Hold {
        /// Duration [s].
        duration_s: f64,
    },
    /// Slip control: a sequence of slides at each rate, each over `distance_mm`.
    VelocitySteps {
        /// Rates [mm/s].
        rates_mm_s: Vec<f64>,
        /// Distance of each step [mm].
        distance_mm: f64,
    },
    /// Slip control: two-way triangular cycles between +amplitude and −amplitude.
    Cycles {
        /// Slip amplitude [mm].
        amplitude_mm: f64,
        /// Slip rate magnitude [mm/s].
        rate_mm_s: f64,
        /// Number of full cycles.
        count: u32,
    },
    /// Slip control: two-way sinusoidal cycles u = A sin(2π t/T) about the current slip.
    SineCycles {
        /// Slip amplitude [mm].
        amplitude_mm: f64,
        /// Period [s].
        period_s: f64,
        /// Number of cycles.
        count: u32,
    },
    /// Traction control: ramp the shear to `to_kpa` at `rate_kpa_s`.
    ShearRamp {
        /// Target shear [kPa].
        to_kpa: f64,
        /// Ramp rate magnitude [kPa/s].
        rate_kpa_s: f64,
    },
    /// Traction control: one-way (pulsating) cycles 0 → max → 0.
    Pulsating {
        /// Peak shear [kPa].
        max_kpa: f64,
        /// Period [s].
        period_s: f64,
        /// Number of cycles.
        count: u32,
    },
    /// Traction control: two-way cycles 0 → +A → −A → 0.
    ShearCycles {
        /// Shear amplitude [kPa].
        amplitude_kpa: f64,
        /// Period [s].
        period_s: f64,
        /// Number of cycles.
        count: u32,
    },
}

/// A loading scenario: stages run one after another at constant normal stress.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name, used for output files.
    pub name: String,
    /// Which quantity is imposed.
    pub control: Control,
    /// Normal stress [kPa].
    pub normal_stress_kpa: f64,
    /// Time step of the generated rows [s].
    pub dt_s: f64,
    /// Stages in order.
    pub stages: Vec<Stage>,
}

/// Rows generated from a scenario.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ScenarioRows {
    /// Time [s].
    pub time: Vec<f64>,
    /// Imposed slip [mm] or shear [kPa].
    pub imposed: Vec<f64>,
    /// Normal stress [kPa].
    pub normal: Vec<f64>,
}

/// A scenario that cannot be run, naming the stage and field.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("scenario `{scenario}`, {location}: {message}")]
pub struct ScenarioError {
    /// Scenario name.
    pub scenario: String,
    /// Stage index and field, e.g. "stage 2 field `rate_mm_s`".
    pub location: String,
    /// What is wrong and what was expected.
    pub message: String,
}

/// Most rows a scenario may generate by default: a row costs about 200 bytes on its way to a
/// CSV file, so 2 million rows are about 400 MB. [`Scenario::rows_with_limit`] takes another limit.
pub const MAX_SCENARIO_ROWS: usize = 2_000_000;

impl Scenario {
    fn err(&self, location: String, message: String) -> ScenarioError {
        ScenarioError {
            scenario: self.name.clone(),
            location,
            message,
        }
    }

    fn positive(&self, i: usize, field: &str, v: f64) -> Result<(), ScenarioError> {
        if v > 0.0 && v.is_finite() {
            Ok(())
        } else {
            Err(self.err(
                format!("stage {} field `{field}`", i + 1),
                format!("expected a finite number > 0, got {v}"),
            ))
        }
    }

    /// Generates the rows (time, imposed, normal), checking every stage, refusing a scenario
    /// of more than [`MAX_SCENARIO_ROWS`] rows.
    pub fn rows(&self) -> Result<ScenarioRows, ScenarioError> {
        self.rows_with_limit(MAX_SCENARIO_ROWS)
    }

    /// The number of rows the scenario generates, computed without generating them (it may
    /// exceed what memory can hold, hence a float).
    ///
    /// ```
    /// use subfric_model::Scenario;
    /// let sc: Scenario = serde_json::from_str(r#"{"name": "long", "control": "slip",
    ///   "normal_stress_kpa": 100, "dt_s": 1e-9,
    ///   "stages": [{"type": "slide", "rate_mm_s": 1, "distance_mm": 1000}]}"#).unwrap();
    /// assert_eq!(sc.row_count().unwrap(), 1e12 + 1.0);
    /// let err = sc.rows().unwrap_err().to_string();
    /// assert!(err.contains("1000000000001 rows"), "{err}");
    /// ```
    pub fn row_count(&self) -> Result<f64, ScenarioError> {
        self.check_fields()?;
        let mut counter = Builder::counting(self.dt_s);
        self.run_stages(&mut counter)?;
        Ok(counter.rows)
    }

    /// As [`Scenario::rows`], refusing a scenario of more than `max_rows` rows before
    /// generating any (the error gives the count it would need).
    pub fn rows_with_limit(&self, max_rows: usize) -> Result<ScenarioRows, ScenarioError> {
        let n = self.row_count()?;
        if n > max_rows as f64 {
            let count = if n < 1e15 {
                format!("{n:.0}")
            } else {
                format!("{n:.3e}")
            };
            return Err(self.err(
                "field `dt_s`".into(),
                format!(
                    "the scenario would generate {count} rows, more than the limit of {max_rows} \
                     (expected a larger time step dt_s, shorter stages, or a higher row limit)"
                ),
            ));
        }
        let mut b = Builder::storing(self.dt_s, n as usize);
        self.run_stages(&mut b)?;
        let n = b.time.len();
        Ok(ScenarioRows {
            time: b.time,
            imposed: b.x,
            normal: vec![self.normal_stress_kpa; n],
        })
    }

    /// Checks the scenario-wide fields.
    fn check_fields(&self) -> Result<(), ScenarioError> {
        self.positive(usize::MAX, "dt_s", self.dt_s).map_err(|_| {
            self.err(
                "field `dt_s`".into(),
                format!("expected a time step > 0 s, got {}", self.dt_s),
            )
        })?;
        if !(self.normal_stress_kpa > 0.0 && self.normal_stress_kpa.is_finite()) {
            return Err(self.err(
                "field `normal_stress_kpa`".into(),
                format!(
                    "expected a normal stress > 0 kPa, got {}",
                    self.normal_stress_kpa
                ),
            ));
        }
        if self.stages.is_empty() {
            return Err(self.err(
                "field `stages`".into(),
                "expected at least one stage".into(),
            ));
        }
        Ok(())
    }

    /// Runs every stage through `b` (which counts or stores the rows).
    fn run_stages(&self, b: &mut Builder) -> Result<(), ScenarioError> {
        for (i, st) in self.stages.iter().enumerate() {
            self.check_control(i, st)?;
            self.stage(i, st, b)?;
        }
        Ok(())
    }

    /// A stage must suit the scenario's control.
    fn check_control(&self, i: usize, st: &Stage) -> Result<(), ScenarioError> {
        let slip_stage = !matches!(
            st,
            Stage::ShearRamp { .. } | Stage::Pulsating { .. } | Stage::ShearCycles { .. }
        );
        let shear_stage = !matches!(
            st,
            Stage::Slide { .. }
                | Stage::VelocitySteps { .. }
                | Stage::Cycles { .. }
                | Stage::SineCycles { .. }
        );
        let fits = match self.control {
            Control::Slip => slip_stage,
            Control::Shear => shear_stage,
        };
        if fits {
            Ok(())
        } else {
            Err(self.err(
                format!("stage {} field `type`", i + 1),
                format!(
                    "this stage needs the other control than the scenario's {:?}",
                    self.control
                ),
            ))
        }
    }

    /// Checks stage `i` and adds its rows to `b`.
    fn stage(&self, i: usize, st: &Stage, b: &mut Builder) -> Result<(), ScenarioError> {
        match st {
            Stage::Slide {
                rate_mm_s,
                distance_mm,
            } => {
                self.positive(i, "rate_mm_s", *rate_mm_s)?;
                b.ramp_to(b.last() + distance_mm, distance_mm.abs() / rate_mm_s);
            }
            Stage::Hold { duration_s } => {
                self.positive(i, "duration_s", *duration_s)?;
                b.ramp_to(b.last(), *duration_s);
            }
            Stage::VelocitySteps {
                rates_mm_s,
                distance_mm,
            } => {
                self.positive(i, "distance_mm", *distance_mm)?;
                for &v in rates_mm_s {
                    self.positive(i, "rates_mm_s", v)?;
                    b.ramp_to(b.last() + distance_mm, distance_mm / v);
                }
            }
            Stage::Cycles {
                amplitude_mm,
                rate_mm_s,
                count,
            } => {
                self.positive(i, "amplitude_mm", *amplitude_mm)?;
                self.positive(i, "rate_mm_s", *rate_mm_s)?;
                let c0 = b.last();
                b.repeat(*count, |b| {
                    for target in [c0 + amplitude_mm, c0 - amplitude_mm, c0] {
                        let d = (target - b.last()).abs();
                        b.ramp_to(target, d / rate_mm_s);
                    }
                });
            }
            Stage::SineCycles {
                amplitude_mm,
                period_s,
                count,
            } => {
                self.positive(i, "amplitude_mm", *amplitude_mm)?;
                self.positive(i, "period_s", *period_s)?;
                let c0 = b.last();
                let (a, t) = (*amplitude_mm, *period_s);
                b.function(t * *count as f64, |s| c0 + a * (2.0 * PI * s / t).sin());
            }
            Stage::ShearRamp { to_kpa, rate_kpa_s } => {
                self.positive(i, "rate_kpa_s", *rate_kpa_s)?;
                b.ramp_to(*to_kpa, (to_kpa - b.last()).abs() / rate_kpa_s);
            }
            Stage::Pulsating {
                max_kpa,
                period_s,
                count,
            } => {
                self.positive(i, "max_kpa", max_kpa.abs())?;
                self.positive(i, "period_s", *period_s)?;
                b.repeat(*count, |b| {
                    b.ramp_to(*max_kpa, 0.5 * period_s);
                    b.ramp_to(0.0, 0.5 * period_s);
                });
            }
            Stage::ShearCycles {
                amplitude_kpa,
                period_s,
                count,
            } => {
                self.positive(i, "amplitude_kpa", *amplitude_kpa)?;
                self.positive(i, "period_s", *period_s)?;
                b.repeat(*count, |b| {
                    b.ramp_to(*amplitude_kpa, 0.25 * period_s);
                    b.ramp_to(-amplitude_kpa, 0.5 * period_s);
                    b.ramp_to(0.0, 0.25 * period_s);
                });
            }
        }
        Ok(())
    }
}

/// Generates the rows of a scenario, or (counting) only their number and the last value.
struct Builder {
    dt: f64,
    /// Store the rows (else only count them).
    store: bool,
    /// Rows so far.
    rows: f64,
    /// Current imposed value.
    last: f64,
    time: Vec<f64>,
    x: Vec<f64>,
}

impl Builder {
    fn counting(dt: f64) -> Self {
        Builder {
            dt,
            store: false,
            rows: 1.0,
            last: 0.0,
            time: Vec::new(),
            x: Vec::new(),
        }
    }

    fn storing(dt: f64, capacity: usize) -> Self {
        let mut time = Vec::with_capacity(capacity);
        let mut x = Vec::with_capacity(capacity);
        time.push(0.0);
        x.push(0.0);
        Builder {
            dt,
            store: true,
            rows: 1.0,
            last: 0.0,
            time,
            x,
        }
    }

    fn last(&self) -> f64 {
        self.last
    }

    /// Linear ramp from the current value to `target` over `duration` seconds.
    fn ramp_to(&mut self, target: f64, duration: f64) {
        let x0 = self.last();
        self.function(duration, |s| x0 + (target - x0) * (s / duration));
    }

    /// Samples `f(s)` for s in (0, duration] at the scenario's time step (the end included).
    fn function(&mut self, duration: f64, f: impl Fn(f64) -> f64) {
        if duration.is_nan() || duration <= 0.0 {
            return;
        }
        let n = (duration / self.dt).round().max(1.0);
        self.rows += n;
        if !self.store {
            self.last = f(duration);
            return;
        }
        let t0 = *self.time.last().unwrap_or(&0.0);
        let n = n as usize;
        for j in 1..=n {
            let s = duration * j as f64 / n as f64;
            self.time.push(t0 + s);
            self.x.push(f(s));
        }
        self.last = *self.x.last().unwrap_or(&0.0);
    }

    /// Runs `count` identical cycles (each ends where the first one ends); counting runs one
    /// and multiplies, so a huge count costs nothing to count.
    fn repeat(&mut self, count: u32, mut one: impl FnMut(&mut Builder)) {
        if count == 0 {
            return;
        }
        if self.store {
            for _ in 0..count {
                one(self);
            }
        } else {
            let before = self.rows;
            one(self);
            self.rows = before + (self.rows - before) * f64::from(count);
        }
    }
}

/// A closed planar slip path for 3-D tests.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "kebab-case")]
pub enum PlanarPath {
    /// A circle of radius R entered from the origin along +e₁ then followed anticlockwise.
    Circle {
        /// Radius [mm].
        radius_mm: f64,
    },
    /// A figure-eight (lemniscate of Gerono) of half-width A.
    FigureEight {
        /// Half-width [mm].
        amplitude_mm: f64,
    },
}

impl PlanarPath {
    /// Slip vectors in the plane spanned by e₁, e₂ at `steps` equal steps per cycle, `cycles`
    /// cycles, starting at the origin; the returned slip is along e₁ = `axes.0`, e₂ = `axes.1`.
    pub fn sample(&self, steps: usize, cycles: usize, axes: (Vec3, Vec3)) -> Vec<Vec3> {
        let (e1, e2) = axes;
        let at = |a: f64, b: f64| {
            [
                a * e1[0] + b * e2[0],
                a * e1[1] + b * e2[1],
                a * e1[2] + b * e2[2],
            ]
        };
        let mut out = Vec::with_capacity(steps * cycles + steps / 4 + 1);
        match *self {
            PlanarPath::Circle { radius_mm } => {
                // Radial approach to (R, 0), then the circle.
                let approach = (steps / 8).max(1);
                for j in 0..=approach {
                    out.push(at(radius_mm * j as f64 / approach as f64, 0.0));
                }
                for j in 1..=steps * cycles {
                    let th = 2.0 * PI * j as f64 / steps as f64;
                    out.push(at(radius_mm * th.cos(), radius_mm * th.sin()));
                }
            }
            PlanarPath::FigureEight { amplitude_mm } => {
                for j in 0..=steps * cycles {
                    let th = 2.0 * PI * j as f64 / steps as f64;
                    out.push(at(
                        amplitude_mm * th.sin(),
                        amplitude_mm * th.sin() * th.cos(),
                    ));
                }
            }
        }
        out
    }
}
