//! Lab-like test sets with known effects (none, one, or two at once, in any of the forms the
//! diagnosis knows, or a measurement drift outside them), for checking the diagnosis on data
//! whose effects it is not told.
//!
//! Four tests per set, as in a typical sand–steel campaign: velocity steps and slide–hold–slide
//! at 100 kPa, two-way cycles at 200 kPa, a monotonic test at 400 kPa, with noise on the measured
//! and on the imposed column. Options make them look like real records: a clock that jitters and
//! samples faster when sliding faster, slip quantised at 0.1 µm, and files that start mid-run.

use crate::candidates::Effect;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use subfric_data::{
    ControlColumn as DataControl, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec,
};
use subfric_model::{
    simulate, Control, DirectionEffect, Extensions, Healing, HealingForm, Initial, Model, Params,
    PressureEffect, PressureForm, Protocol, RateEffect, RateForm, SlipForm, SlipHardening, Target,
};

/// One effect built into a set, in one form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Built {
    /// The family.
    pub effect: Effect,
    /// Which of the family's forms (see [`form_names`]).
    pub form: usize,
}

/// The forms the generator builds, per family.
pub fn form_names(effect: Effect) -> &'static [&'static str] {
    match effect {
        Effect::Rate => &[
            "direct effect",
            "rate and state, ageing law",
            "rate and state, slip law",
            "power law",
            "steady state only",
        ],
        Effect::Pressure => &[
            "power law on mu",
            "linear on mu",
            "exponential on mu",
            "power law on mu_s",
            "power law on mu_k",
        ],
        Effect::SlipHardening => &["exponential", "capped linear", "hyperbolic"],
        Effect::LogHealing => &["log time", "power-law time"],
        Effect::Direction => &["on mu", "on mu_s", "on mu_k", "on kappa", "on u_tilde"],
        Effect::None | Effect::Unexplained => &[],
    }
}

/// The name in the candidate library ([`crate::library`]) of the form that `b` builds.
pub fn library_name(b: Built) -> Option<&'static str> {
    let names: &[&str] = match b.effect {
        Effect::Rate => &[
            "direct effect a ln(1 + v/v_c)",
            "rate and state, ageing law",
            "rate and state, slip law",
            "power law ((v + v_c)/v_ref)^n",
            "steady state only, mu_k + a ln(v/v_ref)",
        ],
        Effect::Pressure => &[
            "power law on mu, (p/p_ref)^-beta",
            "linear on mu, 1 - beta (p/p_ref - 1)",
            "exponential on mu, exp(-beta (p/p_ref - 1))",
            "power law on mu_s only",
            "power law on mu_k only",
        ],
        Effect::SlipHardening => &[
            "exponential, h s_h (1 - exp(-s/s_h))",
            "capped linear, h min(s, s_h)",
            "hyperbolic, h s / (1 + s/s_h)",
        ],
        Effect::LogHealing => &[
            "log time, b ln(1 + t/t_c) at rest",
            "power-law time, b t^n at rest",
        ],
        Effect::Direction => &[
            "backward mu x (1 - d)",
            "backward mu_s x (1 - d)",
            "backward mu_k x (1 - d)",
            "backward kappa x (1 - d)",
            "backward u_tilde x (1 - d)",
        ],
        Effect::None | Effect::Unexplained => &[],
    };
    names.get(b.form).copied()
}

/// What a generated set holds (kept from the diagnosis, used to score it).
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// The effects built in (empty: none; a drift is `Unexplained`).
    pub effects: Vec<Built>,
    /// The model that generated the data.
    pub model: Model,
    /// Drift of the measured shear [kPa/s] (the "unexplained" class).
    pub drift_kpa_per_s: f64,
}

impl Truth {
    /// The families built in, in order (empty for none, `[Unexplained]` for a drift).
    pub fn families(&self) -> Vec<Effect> {
        self.effects.iter().map(|b| b.effect).collect()
    }

    /// A short label: "rate (power law) + pressure (linear on mu)", "none", "drift".
    pub fn label(&self) -> String {
        if self.effects.is_empty() {
            return "none".into();
        }
        self.effects
            .iter()
            .map(|b| match b.effect {
                Effect::Unexplained => "drift".to_string(),
                e => format!("{} ({})", e, form_names(e)[b.form]),
            })
            .collect::<Vec<_>>()
            .join(" + ")
    }
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
    /// Like a real logger: the clock jitters, samples 10× faster at 10× the rate, and slip is
    /// quantised at 0.1 µm.
    pub lab_like: bool,
    /// The velocity-step test starts mid-run (cut after 1.5 mm of sliding).
    pub mid_run: bool,
}

impl Default for SynthOptions {
    fn default() -> Self {
        SynthOptions {
            slip_per_row: 0.005,
            shear_noise: 0.3,
            slip_noise: 0.0002,
            lab_like: false,
            mid_run: false,
        }
    }
}

fn log_uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    (a.ln() + rng.gen::<f64>() * (b.ln() - a.ln())).exp()
}

fn uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    a + rng.gen::<f64>() * (b - a)
}

fn signed(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    let v = uniform(rng, a, b);
    if rng.gen::<bool>() {
        v
    } else {
        -v
    }
}

fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.gen::<f64>().max(1e-300);
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Switches one effect on in `ext`, in form `form`, with random parameters of a size a lab would
/// notice.
fn add_effect(ext: &mut Extensions, b: Built, rng: &mut ChaCha8Rng) {
    let v_ref = 0.01;
    match b.effect {
        Effect::Rate => {
            let a = uniform(rng, 0.01, 0.02);
            ext.rate = Some(match b.form {
                0 => {
                    RateEffect::log_direct(uniform(rng, 0.01, 0.025), log_uniform(rng, 1e-5, 1e-4))
                }
                1 | 2 => RateEffect {
                    form: if b.form == 1 {
                        RateForm::StateAgeing
                    } else {
                        RateForm::StateSlip
                    },
                    a,
                    b: a * uniform(rng, 0.6, 1.4),
                    d_c: log_uniform(rng, 0.02, 0.15),
                    v_c: log_uniform(rng, 1e-6, 1e-5),
                    n: 0.0,
                    v_ref,
                    at_rest: subfric_model::AtRest::Creep,
                },
                3 => RateEffect {
                    form: RateForm::Power,
                    n: signed(rng, 0.025, 0.05),
                    v_c: 1e-5,
                    v_ref,
                    ..RateEffect::log_direct(0.0, 1e-5)
                },
                _ => RateEffect {
                    form: RateForm::SteadyState,
                    a: signed(rng, 0.012, 0.025),
                    v_c: 1e-6,
                    v_ref,
                    ..RateEffect::log_direct(0.0, 1e-6)
                },
            });
        }
        Effect::Pressure => {
            let (form, target, beta) = match b.form {
                0 => (
                    PressureForm::Power,
                    Target::Friction,
                    signed(rng, 0.06, 0.15),
                ),
                1 => (
                    PressureForm::Linear,
                    Target::Friction,
                    signed(rng, 0.03, 0.08),
                ),
                2 => (
                    PressureForm::Exponential,
                    Target::Friction,
                    signed(rng, 0.03, 0.08),
                ),
                3 => (PressureForm::Power, Target::MuS, uniform(rng, 0.1, 0.2)),
                _ => (PressureForm::Power, Target::MuK, uniform(rng, 0.1, 0.2)),
            };
            ext.pressure = Some(PressureEffect {
                beta,
                form,
                target,
                p_ref: uniform(rng, 100.0, 200.0),
                beta_k: 0.0,
            });
        }
        Effect::SlipHardening => {
            let (form, s_h, h) = match b.form {
                0 => {
                    let s_h = uniform(rng, 1.0, 4.0);
                    (SlipForm::Exponential, s_h, signed(rng, 0.05, 0.12) / s_h)
                }
                1 => {
                    let s_h = uniform(rng, 4.0, 12.0);
                    (SlipForm::Capped, s_h, signed(rng, 0.05, 0.12) / s_h)
                }
                _ => {
                    let s_h = uniform(rng, 1.0, 3.0);
                    (SlipForm::Hyperbolic, s_h, signed(rng, 0.06, 0.12) / s_h)
                }
            };
            ext.slip_hardening = Some(SlipHardening { h, s_h, form });
        }
        Effect::LogHealing => {
            ext.healing = Some(if b.form == 0 {
                Healing {
                    b: uniform(rng, 0.008, 0.02),
                    t_c: log_uniform(rng, 2.0, 50.0),
                    n: 0.5,
                    form: HealingForm::Log,
                }
            } else {
                Healing {
                    b: uniform(rng, 0.003, 0.008),
                    t_c: 10.0,
                    n: uniform(rng, 0.25, 0.45),
                    form: HealingForm::Power,
                }
            });
        }
        Effect::Direction => {
            let (target, d) = match b.form {
                0 => (Target::Friction, signed(rng, 0.08, 0.2)),
                1 => (Target::MuS, signed(rng, 0.12, 0.25)),
                2 => (Target::MuK, signed(rng, 0.12, 0.25)),
                3 => (Target::Kappa, signed(rng, 0.4, 0.6)),
                _ => (Target::UTilde, signed(rng, 0.4, 0.6)),
            };
            ext.direction = Some(DirectionEffect {
                d,
                target,
                d_k: 0.0,
            });
        }
        Effect::None | Effect::Unexplained => {}
    }
}

/// A random sand–steel parameter set with the effects `built` (a drift when it holds
/// `Unexplained`).
pub fn random_truth(built: &[Built], rng: &mut ChaCha8Rng) -> Truth {
    let mu_s = uniform(rng, 0.5, 0.8);
    let params = Params {
        mu_s,
        mu_k: mu_s * uniform(rng, 0.65, 0.85),
        kappa: log_uniform(rng, 1.0, 4.0),
        xi: log_uniform(rng, 1e-3, 6e-3),
        u_tilde: log_uniform(rng, 8.0, 40.0),
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: None,
    };
    let mut ext = Extensions::default();
    let mut drift = 0.0;
    for &b in built {
        if b.effect == Effect::Unexplained {
            drift = signed(rng, 2.0, 5.0) / 2000.0;
        } else {
            add_effect(&mut ext, b, rng);
        }
    }
    Truth {
        effects: built.to_vec(),
        model: Model { params, ext },
        drift_kpa_per_s: drift,
    }
}

/// A slip-controlled loading path: (time, slip) vertices, imposed piecewise linearly.
struct Path {
    points: Vec<(f64, f64)>,
}

impl Path {
    fn new() -> Self {
        Path {
            points: vec![(0.0, 0.0)],
        }
    }
    fn last(&self) -> (f64, f64) {
        *self.points.last().expect("a path has a start")
    }
    fn slide(&mut self, rate: f64, distance: f64) {
        let (t, u) = self.last();
        self.points.push((t + distance.abs() / rate, u + distance));
    }
    fn hold(&mut self, duration: f64) {
        let (t, u) = self.last();
        self.points.push((t + duration, u));
    }
    /// Sampling rows: `du` of slip per row while sliding (so faster sliding samples faster), 30
    /// rows per hold; a lab-like clock jitters by ±20 % of its interval.
    fn rows(&self, du: f64, jitter: Option<&mut ChaCha8Rng>) -> (Vec<f64>, Vec<f64>) {
        let mut t = vec![0.0];
        let mut u = vec![self.points[0].1];
        let mut rng = jitter;
        for w in self.points.windows(2) {
            let ((t0, u0), (t1, u1)) = (w[0], w[1]);
            let n = if u1 == u0 {
                30
            } else {
                ((u1 - u0).abs() / du).round().max(1.0) as usize
            };
            for j in 1..=n {
                let mut f = j as f64 / n as f64;
                if let Some(r) = rng.as_deref_mut() {
                    if j < n {
                        f += 0.4 * (r.gen::<f64>() - 0.5) / n as f64;
                    }
                }
                t.push(t0 + f * (t1 - t0));
                u.push(u0 + f * (u1 - u0));
            }
        }
        (t, u)
    }
}

/// The four protocols: (name, normal stress, path).
fn protocols() -> Vec<(&'static str, f64, Path)> {
    let mut vs = Path::new();
    vs.slide(0.01, 2.0);
    vs.slide(0.1, 1.0);
    vs.slide(0.01, 0.9);
    vs.slide(0.001, 0.5);
    vs.slide(0.01, 0.6);
    let mut shs = Path::new();
    shs.slide(0.01, 2.0);
    for &h in &[10.0, 100.0, 1000.0] {
        shs.hold(h);
        shs.slide(0.01, 0.8);
    }
    let mut cyc = Path::new();
    for _ in 0..4 {
        cyc.slide(0.01, 1.0);
        cyc.slide(0.01, -2.0);
        cyc.slide(0.01, 1.0);
    }
    let mut mono = Path::new();
    mono.slide(0.01, 4.0);
    vec![
        ("velocity-steps", 100.0, vs),
        ("slide-hold-slide", 100.0, shs),
        ("two-way-cyclic", 200.0, cyc),
        ("monotonic-400kPa", 400.0, mono),
    ]
}

/// Generates one test: simulate the path, add noise (and the lab-like clock and quantisation),
/// cut it mid-run when asked.
fn generate_test(
    name: &str,
    normal: f64,
    path: &Path,
    truth: &Truth,
    opts: &SynthOptions,
    cut_mm: f64,
    rng: &mut ChaCha8Rng,
) -> TestData {
    let (t, u) = if opts.lab_like {
        path.rows(opts.slip_per_row, Some(rng))
    } else {
        path.rows(opts.slip_per_row, None)
    };
    let n = t.len();
    let normal_col = vec![normal; n];
    let proto = Protocol {
        control: Control::Slip,
        time: &t,
        imposed: &u,
        normal: &normal_col,
        initial_slip: 0.0,
        initial: Initial::Rest,
    };
    let shear = simulate(&truth.model, &proto).map_or_else(|_| vec![0.0; n], |o| o.shear);
    let quantum = if opts.lab_like { 1e-4 } else { 0.0 };
    let start = u.iter().position(|&x| x >= cut_mm).unwrap_or(0);
    let (mut time, mut slip, mut meas) = (Vec::new(), Vec::new(), Vec::new());
    for i in start..n {
        let mut s = u[i] + opts.slip_noise * gauss(rng);
        if quantum > 0.0 {
            s = (s / quantum).round() * quantum;
        }
        time.push(t[i] - t[start]);
        slip.push(s - u[start]);
        meas.push(shear[i] + truth.drift_kpa_per_s * t[i] + opts.shear_noise * gauss(rng));
    }
    let rows = time.len();
    let spec = TestSpec::new(name, &format!("{name}.csv"), DataControl::Slip, normal);
    TestData {
        spec,
        path: format!("{name}.csv").into(),
        time_s: time,
        slip_mm: slip,
        shear_kpa: meas,
        normal_kpa: vec![normal; rows],
        friction_given: false,
        line_of_row: (2..rows + 2).collect(),
        comments: vec!["generated by subfric selfcheck".into()],
    }
}

/// Generates one set in memory (data format types, as if loaded from disk).
pub fn generate_set(
    name: &str,
    truth: &Truth,
    opts: &SynthOptions,
    rng: &mut ChaCha8Rng,
) -> ExperimentSet {
    let mut tests = Vec::new();
    for (k, (test_name, normal, path)) in protocols().into_iter().enumerate() {
        let cut = if opts.mid_run && k == 0 { 1.5 } else { 0.0 };
        tests.push(generate_test(
            test_name, normal, &path, truth, opts, cut, rng,
        ));
    }
    ExperimentSet {
        dir: name.into(),
        meta: ExperimentMeta {
            name: name.into(),
            title: format!("generated set {name}"),
            source: "subfric selfcheck generator".into(),
            provenance: Some("synthetic: effects withheld from the diagnosis".into()),
            interface: Interface {
                soil: Some("synthetic sand".into()),
                surface: Some("synthetic steel".into()),
                roughness_rmax_um: None,
                extra: Default::default(),
            },
            tests: tests.iter().map(|t| t.spec.clone()).collect(),
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

/// A long record like a real velocity-step run: three tests at 5, 10 and 15 MPa, each a ladder
/// 10 → 1 → 3 → 10 → 30 → 100 → 300 → 100 → 30 → 10 → 3 → 1 µm/s with 0.4 mm per step and a
/// 100-s hold, sampled by a jittering clock at `rows_per_test` rows (denser when faster), slip
/// quantised at 0.1 µm, from a model with a rate-and-state effect and slip hardening. For
/// timing the diagnosis of records of 10⁴–10⁵ rows.
pub fn long_record_set(rows_per_test: usize, seed: u64) -> ExperimentSet {
    let mut r = rng(seed);
    let mut truth = random_truth(
        &[
            Built {
                effect: Effect::Rate,
                form: 1,
            },
            Built {
                effect: Effect::SlipHardening,
                form: 0,
            },
        ],
        &mut r,
    );
    if let Some(rate) = truth.model.ext.rate.as_mut() {
        rate.v_ref = 0.01;
    }
    let um = 1e-3;
    let mut path = Path::new();
    path.slide(10.0 * um, 0.6);
    path.hold(100.0);
    for v in [
        1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 100.0, 30.0, 10.0, 3.0, 1.0,
    ] {
        path.slide(v * um, 0.4);
    }
    let travel = 0.6 + 11.0 * 0.4;
    let opts = SynthOptions {
        slip_per_row: travel / rows_per_test.max(100) as f64,
        shear_noise: 5.0,
        slip_noise: 3e-5,
        lab_like: true,
        mid_run: false,
    };
    let mut tests = Vec::new();
    for normal in [5000.0, 10_000.0, 15_000.0] {
        let name = format!("sn{:02}MPa", (normal / 1000.0) as usize);
        tests.push(generate_test(
            &name, normal, &path, &truth, &opts, 0.0, &mut r,
        ));
    }
    ExperimentSet {
        dir: "long-record".into(),
        meta: ExperimentMeta {
            name: "long-record".into(),
            title: "generated long velocity-step record".into(),
            source: "subfric bench generator".into(),
            provenance: Some("synthetic".into()),
            interface: Interface::default(),
            tests: tests.iter().map(|t| t.spec.clone()).collect(),
            reference_parameters: None,
            extra: Default::default(),
        },
        tests,
    }
}
