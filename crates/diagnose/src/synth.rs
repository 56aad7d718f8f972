//! Lab-like test sets with one known effect (or none), for checking the diagnosis on data whose
//! effect it is not told. Four tests per set, as in a typical sand–steel campaign: velocity
//! steps and slide–hold–slide at 100 kPa, two-way cycles at 200 kPa, a monotonic test at 400 kPa;
//! noise on the measured and on the imposed column.

use crate::candidates::Effect;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use subfric_data::{
    Control as DataControl, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec,
};
use subfric_model::{
    simulate, Control, DirectionEffect, Extensions, Healing, HealingForm, Model, Params,
    PressureEffect, PressureForm, Protocol, RateEffect, SlipForm, SlipHardening, Target,
};

/// What a generated set holds (kept from the diagnosis, used to score it).
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// The effect built in ("unexplained" for a measurement drift outside the library).
    pub effect: Effect,
    /// The model that generated the data.
    pub model: Model,
    /// Drift of the measured shear [kPa/s] (the "unexplained" class).
    pub drift_kpa_per_s: f64,
}

/// Options of the generator.
#[derive(Clone, Copy, Debug)]
pub struct SynthOptions {
    /// Slip per row while sliding [mm] (0.005 in typical lab files; larger is faster).
    pub slip_per_row: f64,
    /// Noise SD of the measured shear [kPa].
    pub shear_noise: f64,
    /// Noise SD of the measured (imposed) slip [mm].
    pub slip_noise: f64,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            slip_per_row: 0.005,
            shear_noise: 0.3,
            slip_noise: 0.0002,
        }
    }
}

/// Rows of a slip-controlled protocol built stage by stage.
struct Rows {
    t: Vec<f64>,
    u: Vec<f64>,
    du: f64,
}

impl Rows {
    fn new(du: f64) -> Self {
        Rows {
            t: vec![0.0],
            u: vec![0.0],
            du,
        }
    }
    fn last(&self) -> (f64, f64) {
        (
            *self.t.last().unwrap_or(&0.0),
            *self.u.last().unwrap_or(&0.0),
        )
    }
    fn slide(&mut self, rate: f64, distance: f64) {
        let (t0, u0) = self.last();
        let n = (distance.abs() / self.du).round().max(1.0) as usize;
        for j in 1..=n {
            let f = j as f64 / n as f64;
            self.t.push(t0 + f * distance.abs() / rate);
            self.u.push(u0 + f * distance);
        }
    }
    fn hold(&mut self, duration: f64) {
        let (t0, u0) = self.last();
        let n = 30usize;
        for j in 1..=n {
            self.t.push(t0 + duration * j as f64 / n as f64);
            self.u.push(u0);
        }
    }
}

fn log_uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    (a.ln() + rng.gen::<f64>() * (b.ln() - a.ln())).exp()
}

fn signed(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    let v = a + rng.gen::<f64>() * (b - a);
    if rng.gen::<bool>() {
        v
    } else {
        -v
    }
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller.
    let u1: f64 = rng.gen::<f64>().max(1e-300);
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// A random sand–steel parameter set with the given effect built in.
pub fn random_truth(effect: Effect, rng: &mut ChaCha8Rng) -> Truth {
    let mu_s = 0.5 + 0.3 * rng.gen::<f64>();
    let params = Params {
        mu_s,
        mu_k: mu_s * (0.65 + 0.2 * rng.gen::<f64>()),
        kappa: log_uniform(rng, 1.0, 4.0),
        xi: log_uniform(rng, 1e-3, 6e-3),
        u_tilde: log_uniform(rng, 8.0, 40.0),
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: None,
    };
    let mut ext = Extensions::default();
    let mut drift = 0.0;
    match effect {
        Effect::Rate => {
            ext.rate = Some(RateEffect::log_direct(
                0.01 + 0.015 * rng.gen::<f64>(),
                log_uniform(rng, 1e-5, 1e-4),
            ))
        }
        Effect::Pressure => {
            ext.pressure = Some(PressureEffect {
                beta: signed(rng, 0.06, 0.15),
                form: PressureForm::Power,
                target: Target::Friction,
                p_ref: subfric_model::extensions::PRESSURE_REF_KPA,
            })
        }
        Effect::SlipHardening => {
            let capped = rng.gen::<bool>();
            let s_h = if capped {
                4.0 + 8.0 * rng.gen::<f64>()
            } else {
                1.0 + 3.0 * rng.gen::<f64>()
            };
            ext.slip_hardening = Some(SlipHardening {
                h: signed(rng, 0.05, 0.12) / s_h,
                s_h,
                form: if capped {
                    SlipForm::Capped
                } else {
                    SlipForm::Exponential
                },
            })
        }
        Effect::LogHealing => {
            ext.healing = Some(Healing {
                b: 0.008 + 0.012 * rng.gen::<f64>(),
                t_c: log_uniform(rng, 2.0, 50.0),
                n: 0.5,
                form: HealingForm::Log,
            })
        }
        Effect::Direction => {
            ext.direction = Some(DirectionEffect {
                d: signed(rng, 0.08, 0.2),
                target: Target::Friction,
            })
        }
        Effect::Unexplained => drift = signed(rng, 2.0, 5.0) / 2000.0,
        Effect::None => {}
    }
    Truth {
        effect,
        model: Model { params, ext },
        drift_kpa_per_s: drift,
    }
}

/// The four protocols: (name, normal stress, rows).
fn protocols(du: f64) -> Vec<(&'static str, f64, Rows)> {
    let mut vs = Rows::new(du);
    vs.slide(0.01, 2.0);
    vs.slide(0.1, 1.0);
    vs.slide(0.01, 0.9);
    vs.slide(0.001, 0.5);
    vs.slide(0.01, 0.6);
    let mut shs = Rows::new(du);
    shs.slide(0.01, 2.0);
    for &h in &[10.0, 100.0, 1000.0] {
        shs.hold(h);
        shs.slide(0.01, 0.8);
    }
    let mut cyc = Rows::new(du);
    for _ in 0..4 {
        cyc.slide(0.01, 1.0);
        cyc.slide(0.01, -2.0);
        cyc.slide(0.01, 1.0);
    }
    let mut mono = Rows::new(du);
    mono.slide(0.01, 4.0);
    vec![
        ("velocity-steps", 100.0, vs),
        ("slide-hold-slide", 100.0, shs),
        ("two-way-cyclic", 200.0, cyc),
        ("monotonic-400kPa", 400.0, mono),
    ]
}

/// Generates one set in memory (data format types, as if loaded from disk).
pub fn generate_set(
    name: &str,
    truth: &Truth,
    opts: &SynthOptions,
    rng: &mut ChaCha8Rng,
) -> ExperimentSet {
    let mut tests = Vec::new();
    let mut specs = Vec::new();
    for (test_name, normal, rows) in protocols(opts.slip_per_row) {
        let n = rows.t.len();
        let normal_col = vec![normal; n];
        let proto = Protocol {
            control: Control::Slip,
            time: &rows.t,
            imposed: &rows.u,
            normal: &normal_col,
            initial_slip: 0.0,
            initial: Default::default(),
        };
        let shear = match simulate(&truth.model, &proto) {
            Ok(out) => out.shear,
            Err(_) => vec![0.0; n],
        };
        let slip_meas: Vec<f64> = rows
            .u
            .iter()
            .map(|u| u + opts.slip_noise * gauss(rng))
            .collect();
        let shear_meas: Vec<f64> = shear
            .iter()
            .zip(&rows.t)
            .map(|(s, t)| s + truth.drift_kpa_per_s * t + opts.shear_noise * gauss(rng))
            .collect();
        let spec = TestSpec::new(
            test_name,
            &format!("{test_name}.csv"),
            DataControl::Slip,
            normal,
        );
        specs.push(spec.clone());
        tests.push(TestData {
            spec,
            path: format!("{test_name}.csv").into(),
            time_s: rows.t.clone(),
            slip_mm: slip_meas,
            shear_kpa: shear_meas,
            normal_kpa: normal_col,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec!["generated by subfric selfcheck".into()],
        });
    }
    ExperimentSet {
        dir: name.into(),
        meta: ExperimentMeta {
            name: name.into(),
            title: format!("generated set {name}"),
            source: "subfric selfcheck generator".into(),
            provenance: Some("synthetic: effect withheld from the diagnosis".into()),
            interface: Interface {
                soil: Some("synthetic sand".into()),
                surface: Some("synthetic steel".into()),
                roughness_rmax_um: None,
                extra: Default::default(),
            },
            tests: specs,
            reference_parameters: None,
            extra: Default::default(),
        },
        tests,
    }
}

/// A seeded random source for the generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}
