//! Random draws of a sand–steel campaign: the base parameters, the effects in the forms of
//! [`Form`], the rig and logger ([`Artifacts`]) and the tests ([`TestPlan`]). The ranges are
//! the friction literature's (see `docs/selfcheck-generator.md`), not the diagnosis's.

use super::effects::{
    Combine, Direction, Effects, Gap, HealShape, Healing, Pressure, PressureShape, Rate, RateForm,
    Reading, Slip, SlipShape, StateLaw, Target,
};
use super::forward::{Base, Toe, KPA_PER_MM_PER_KN_MM3};
use super::path::{Sampling, Segment};
use super::record::{Noise, Resolution};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// A form the generator builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Form {
    /// Rate and state, ageing law (creep or locked reading).
    RsfAgeing,
    /// Rate and state, slip law.
    RsfSlip,
    /// Power-law rate dependence.
    RatePower,
    /// Log-rate direct effect without state.
    RateLog,
    /// Pressure: power law (on μ, μ_s or μ_k).
    PressurePower,
    /// Pressure: linear.
    PressureLinear,
    /// Pressure: exponential approach to a drop.
    PressureExp,
    /// Slip hardening or softening, exponential (additive or multiplicative).
    SlipExp,
    /// Slip hardening or softening, hyperbolic.
    SlipHyperbolic,
    /// Slip hardening or softening, capped linear.
    SlipCapped,
    /// Healing at rest, log of time.
    HealLog,
    /// Healing at rest, power of time.
    HealPower,
    /// Direction dependence of μ.
    DirectionMu,
    /// Direction dependence of μ_k.
    DirectionMuK,
    /// Direction dependence of κ.
    DirectionKappa,
    /// A linear drift of the load cell.
    Drift,
    /// A slow vibration of the load cell.
    Vibration,
    /// A creep of the load cell: its reading creeps towards a share of its load with a
    /// first-order lag.
    Creep,
}

impl Form {
    /// Every form.
    pub const ALL: [Form; 18] = [
        Form::RsfAgeing,
        Form::RsfSlip,
        Form::RatePower,
        Form::RateLog,
        Form::PressurePower,
        Form::PressureLinear,
        Form::PressureExp,
        Form::SlipExp,
        Form::SlipHyperbolic,
        Form::SlipCapped,
        Form::HealLog,
        Form::HealPower,
        Form::DirectionMu,
        Form::DirectionMuK,
        Form::DirectionKappa,
        Form::Drift,
        Form::Vibration,
        Form::Creep,
    ];

    /// The family, as `truth.json` names it.
    pub fn family(self) -> &'static str {
        match self {
            Form::RsfAgeing | Form::RsfSlip | Form::RatePower | Form::RateLog => "rate",
            Form::PressurePower | Form::PressureLinear | Form::PressureExp => "pressure",
            Form::SlipExp | Form::SlipHyperbolic | Form::SlipCapped => "slip-hardening",
            Form::HealLog | Form::HealPower => "log-healing",
            Form::DirectionMu | Form::DirectionMuK | Form::DirectionKappa => "direction",
            Form::Drift | Form::Vibration | Form::Creep => "unexplained",
        }
    }

    /// A short name (the class list of `subfric selfcheck`).
    pub fn label(self) -> &'static str {
        match self {
            Form::RsfAgeing => "rate and state, ageing law",
            Form::RsfSlip => "rate and state, slip law",
            Form::RatePower => "power-law rate",
            Form::RateLog => "log-rate direct effect",
            Form::PressurePower => "pressure power law",
            Form::PressureLinear => "pressure linear",
            Form::PressureExp => "pressure exponential",
            Form::SlipExp => "slip, exponential",
            Form::SlipHyperbolic => "slip, hyperbolic",
            Form::SlipCapped => "slip, capped linear",
            Form::HealLog => "healing, log time",
            Form::HealPower => "healing, power of time",
            Form::DirectionMu => "direction on mu",
            Form::DirectionMuK => "direction on mu_k",
            Form::DirectionKappa => "direction on kappa",
            Form::Drift => "load-cell drift",
            Form::Vibration => "load-cell vibration",
            Form::Creep => "load-cell creep",
        }
    }
}

/// How much of a real rig and logger a set shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Profile {
    /// A row every few µm of slip and every few seconds in holds, white noise, a rigid
    /// machine.
    Clean,
    /// A lab logger: rate-adaptive sampling, a jittering clock, 0.1 µm quantised displacement,
    /// correlated noise.
    Logger,
    /// A lab rig: machine compliance, seating toes, an unload, correlated noise.
    Rig,
    /// Both, and files cut out of a longer run.
    Lab,
}

impl Profile {
    /// In turn.
    pub const ALL: [Profile; 4] = [Profile::Lab, Profile::Clean, Profile::Logger, Profile::Rig];

    /// A lab logger's sampling, clock and resolution.
    pub fn logger(self) -> bool {
        matches!(self, Profile::Logger | Profile::Lab)
    }

    /// A lab rig's compliance, seating toes and unloads.
    pub fn rig(self) -> bool {
        matches!(self, Profile::Rig | Profile::Lab)
    }
}

/// The rig and logger of a set.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Artifacts {
    /// Which profile they were drawn from.
    pub profile: Profile,
    /// Machine stiffness in series with the interface [kN/mm³]: the recorded displacement is
    /// the load point's.
    pub machine_kn_mm3: Option<f64>,
    /// The series stiffness of rig and interface [kPa/mm].
    pub series_kpa_per_mm: f64,
    /// The seating toe of each test loaded from rest.
    pub seating_toes: Vec<SeatingToe>,
    /// Tests cut out of a longer run (filled when the tests are run).
    pub midrun: Vec<MidRun>,
    /// Tests with an unload and reload.
    pub unloads: Vec<String>,
    /// Sampling.
    #[serde(serialize_with = "sampling_text")]
    pub sampling: Sampling,
    /// Largest clock jitter, as a fraction of the sampling interval.
    pub jitter: f64,
    /// Noise.
    pub noise: Noise,
    /// Resolution of the written numbers.
    pub resolution: Resolution,
}

/// A seating toe in a test's first loading.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeatingToe {
    /// The test.
    pub test: String,
    /// Displacement the toe takes up [mm].
    pub gap_mm: f64,
    /// Shear scale over which it closes [kPa] (closed to e^-n at n times it).
    pub shear_scale_kpa: f64,
}

/// A test cut out of a longer run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MidRun {
    /// The test.
    pub test: String,
    /// Time of the cut in the run [s].
    pub cut_at_s: f64,
    /// Recorded displacement there [mm].
    pub cut_at_mm: f64,
    /// Time and displacement restart at zero in the file (else they run on).
    pub rezeroed: bool,
}

fn sampling_text<S: serde::Serializer>(s: &Sampling, ser: S) -> Result<S::Ok, S::Error> {
    ser.serialize_str(&match *s {
        Sampling::Uniform { dt } => format!("uniform, every {dt:.3} s"),
        Sampling::RateAdaptive {
            slip_per_row,
            min_dt,
            max_dt,
            min_hold_dt,
            hold_growth,
        } if hold_growth > 1.0 => format!(
            "rate-adaptive: {slip_per_row:.4} mm per row sliding ({min_dt}-{max_dt} s), holds from {min_hold_dt:.2} s growing x{hold_growth}"
        ),
        Sampling::RateAdaptive {
            slip_per_row,
            min_hold_dt,
            ..
        } => format!(
            "every {slip_per_row:.4} mm while sliding, every {min_hold_dt:.2} s in holds"
        ),
    })
}

/// One test of a campaign.
#[derive(Clone, Debug, PartialEq)]
pub struct TestPlan {
    /// Name (also the CSV's).
    pub name: String,
    /// Normal stress [kPa].
    pub p: f64,
    /// The load point's path.
    pub segments: Vec<Segment>,
    /// Cut the file at this displacement of the run [mm] (a file from mid-run), and whether
    /// its time and displacement then restart at zero.
    pub cut_mm: Option<(f64, bool)>,
    /// A seating toe on its first loading.
    pub toe: Option<Toe>,
}

/// Uniform in [a, b].
pub fn uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    a + rng.gen::<f64>() * (b - a)
}

/// Log-uniform in [a, b].
pub fn log_uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    uniform(rng, a.ln(), b.ln()).exp()
}

/// ± uniform in [a, b].
fn signed(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    let v = uniform(rng, a, b);
    if rng.gen::<bool>() {
        v
    } else {
        -v
    }
}

fn pick<T: Copy>(rng: &mut ChaCha8Rng, items: &[T]) -> T {
    items[rng.gen_range(0..items.len())]
}

/// Base parameters in sand–steel ranges (μ_s 0.3–0.7, μ_k/μ_s 0.6–0.95; κ, ξ, ũ as the
/// paper's Tables 2–4 and the shared dev families; α_t as stiff as the paper's tables).
pub fn base(rng: &mut ChaCha8Rng) -> Base {
    let mu_s = uniform(rng, 0.3, 0.7);
    Base {
        mu_s,
        mu_k: mu_s * uniform(rng, 0.6, 0.95),
        kappa: log_uniform(rng, 0.5, 4.0),
        xi: log_uniform(rng, 1e-3, 1e-2),
        u_tilde: log_uniform(rng, 3.0, 40.0),
        alpha_t: log_uniform(rng, 1000.0, 10_000.0),
    }
}

/// What an effect's draw needs to know of the campaign.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// Base sliding rate [mm/s].
    pub v0: f64,
    /// Normal stress of the velocity-step and hold tests [kPa].
    pub p_ref: f64,
    /// Largest normal stress of the campaign [kPa].
    pub p_max: f64,
    /// Series stiffness of rig and interface [kPa/mm].
    pub k_series: f64,
    /// The rig is compliant (the creep reading needs a spring to relax through).
    pub compliant: bool,
}

/// Switches the effect of `form` on in `fx`, with parameters from the literature's ranges.
pub fn add_effect(fx: &mut Effects, form: Form, s: &Setting, rng: &mut ChaCha8Rng) {
    // Creep needs a spring to relax through: with a rigid rig every hold would drop at once by
    // a ln(v0/v_min). Drawn for every form, so that each form's draws follow the same ones.
    let reading = if s.compliant && rng.gen::<f64>() < 0.6 {
        Reading::Creep
    } else {
        Reading::Locked
    };
    let v_min = log_uniform(rng, 1e-7, 1e-5);
    match form {
        Form::RsfAgeing | Form::RsfSlip | Form::RatePower | Form::RateLog => {
            fx.rate = Some(rate_effect(form, s, reading, v_min, rng));
        }
        Form::PressurePower | Form::PressureLinear | Form::PressureExp => {
            fx.pressure = Some(pressure_effect(form, s, rng));
        }
        Form::SlipExp | Form::SlipHyperbolic | Form::SlipCapped => {
            fx.slip = Some(slip_effect(form, rng));
        }
        Form::HealLog | Form::HealPower => fx.healing = Some(healing_effect(form, rng)),
        Form::DirectionMu | Form::DirectionMuK | Form::DirectionKappa => {
            let (target, delta) = match form {
                Form::DirectionMu => (Target::Mu, signed(rng, 0.08, 0.25)),
                Form::DirectionMuK => (Target::MuK, signed(rng, 0.08, 0.25)),
                _ => (Target::Kappa, signed(rng, 0.3, 0.7)),
            };
            fx.direction = Some(Direction { target, delta });
        }
        Form::Drift | Form::Creep | Form::Vibration => fx.gap = Some(gap_effect(form, rng)),
    }
}

/// A rate effect of `form` (rate and state by either law, a power law, a log law), read
/// through `reading`, creeping down to `v_min` in holds.
fn rate_effect(
    form: Form,
    s: &Setting,
    reading: Reading,
    v_min: f64,
    rng: &mut ChaCha8Rng,
) -> Rate {
    // A negative direct effect has no creeping reading (instant weakening is unstable).
    let rate_sign = |rng: &mut ChaCha8Rng| {
        if reading == Reading::Creep || rng.gen::<f64>() < 0.6 {
            1.0
        } else {
            -1.0
        }
    };
    let form = match form {
        Form::RsfAgeing | Form::RsfSlip => {
            let a = uniform(rng, 0.002, 0.02);
            let mut b = (a + uniform(rng, -0.01, 0.01)).max(0.0);
            let mut dc = log_uniform(rng, 1e-3, 1.0);
            if reading == Reading::Creep && b > a {
                // Stable sliding through the rig: k ≥ 2 k_crit = 2 p (b − a)/D_c.
                let needed = 2.0 * s.p_max * (b - a) / s.k_series;
                if dc < needed {
                    dc = needed.min(1.0);
                    b = b.min(a + s.k_series * dc / (2.0 * s.p_max));
                }
            }
            let law = if form == Form::RsfAgeing {
                StateLaw::Ageing
            } else {
                StateLaw::Slip
            };
            RateForm::State { law, a, b, dc }
        }
        Form::RatePower => RateForm::Power {
            n: rate_sign(rng) * uniform(rng, 0.005, 0.03),
        },
        _ => RateForm::Log {
            a: rate_sign(rng) * uniform(rng, 0.003, 0.015),
        },
    };
    Rate {
        form,
        v_star: s.v0,
        v_min,
        reading,
    }
}

/// A pressure effect of `form` (power, linear, exponential) on μ, μ_s or μ_k.
fn pressure_effect(form: Form, s: &Setting, rng: &mut ChaCha8Rng) -> Pressure {
    // Sand–steel interfaces mostly lose friction with normal stress (grain crushing, less
    // dilatancy); one in five draws gains.
    let sign = if rng.gen::<f64>() < 0.8 { 1.0 } else { -1.0 };
    let shape = match form {
        Form::PressurePower => PressureShape::Power {
            n: sign * uniform(rng, 0.03, 0.15),
        },
        Form::PressureLinear => PressureShape::Linear {
            c: sign * uniform(rng, 0.03, 0.1),
        },
        _ => PressureShape::Exponential {
            drop: sign * uniform(rng, 0.1, 0.3),
            p_c: log_uniform(rng, 100.0, 400.0),
        },
    };
    Pressure {
        shape,
        target: pick(rng, &[Target::Mu, Target::MuS, Target::MuK]),
        p_ref: s.p_ref,
    }
}

/// A hardening or softening with slip of `form` (exponential, hyperbolic, linear to a cap),
/// added to or multiplying friction.
fn slip_effect(form: Form, rng: &mut ChaCha8Rng) -> Slip {
    let combine = pick(rng, &[Combine::Additive, Combine::Multiplicative]);
    let amount = match combine {
        Combine::Additive => signed(rng, 0.03, 0.12),
        Combine::Multiplicative => signed(rng, 0.06, 0.25),
    };
    Slip {
        shape: match form {
            Form::SlipExp => SlipShape::Exponential,
            Form::SlipHyperbolic => SlipShape::Hyperbolic,
            _ => SlipShape::LinearCapped,
        },
        combine,
        amount,
        length: log_uniform(rng, 1.0, 6.0),
    }
}

/// A time healing of `form` (log or power of the hold time), erased over a slip `d_h`.
fn healing_effect(form: Form, rng: &mut ChaCha8Rng) -> Healing {
    let per_decade = uniform(rng, 0.002, 0.02);
    let tau = log_uniform(rng, 0.3, 10.0);
    let shape = if form == Form::HealLog {
        HealShape::Log { per_decade }
    } else {
        // The same mean gain per decade between 10 and 1000 s as the log form.
        let m = uniform(rng, 0.15, 0.45);
        let span = (1.0 + 1000.0 / tau).powf(m) - (1.0 + 10.0 / tau).powf(m);
        HealShape::Power {
            c: 2.0 * per_decade / span,
            m,
        }
    };
    Healing {
        shape,
        tau,
        d_h: log_uniform(rng, 0.01, 0.1),
    }
}

/// A gap of the measurement of `form`: a drift of the zero, a creep of the load cell, a
/// vibration.
fn gap_effect(form: Form, rng: &mut ChaCha8Rng) -> Gap {
    match form {
        Form::Drift => Gap::Drift {
            kpa_per_s: signed(rng, 0.5, 3.0) / 1000.0,
        },
        Form::Creep => Gap::Creep {
            share: uniform(rng, 0.02, 0.06),
            tau_s: log_uniform(rng, 100.0, 3000.0),
        },
        _ => Gap::Vibration {
            amplitude_kpa: uniform(rng, 0.5, 2.0),
            period_s: log_uniform(rng, 100.0, 600.0),
            phase: uniform(rng, 0.0, std::f64::consts::TAU),
        },
    }
}

fn slide(rate: f64, distance: f64) -> Segment {
    Segment::Slide { rate, distance }
}

/// The campaign's tests: velocity steps and slide–hold–slide (holds of 3 to 3000 s) at one
/// stress, two-way cycles at another, monotonic tests at two or three more, all at the base
/// rate `v0`; with `unloads`, one monotonic test is unloaded and reloaded half way.
pub fn plans(v0: f64, unloads: bool, rng: &mut ChaCha8Rng) -> Vec<TestPlan> {
    let p_main = pick(rng, &[50.0, 100.0, 150.0, 200.0]);
    let p_cyc = pick(rng, &[50.0, 100.0, 200.0]);
    let mut mono: Vec<f64> = [50.0, 100.0, 200.0, 300.0, 400.0]
        .into_iter()
        .filter(|p| *p != p_main)
        .collect();
    let keep = if rng.gen::<bool>() { 2 } else { 3 };
    while mono.len() > keep {
        let i = rng.gen_range(0..mono.len());
        mono.remove(i);
    }
    let plan = |name: String, p: f64, segments: Vec<Segment>| TestPlan {
        name,
        p,
        segments,
        cut_mm: None,
        toe: None,
    };
    let mut out = Vec::new();
    let run_in = uniform(rng, 1.5, 2.0);
    let ladder: &[f64] = pick(
        rng,
        &[
            &[10.0, 1.0, 0.1, 1.0][..],
            &[3.0, 30.0, 3.0, 0.3, 1.0][..],
            &[0.1, 1.0, 10.0, 1.0][..],
        ],
    );
    let mut vs = vec![slide(v0, run_in)];
    for m in ladder {
        vs.push(slide(m * v0, uniform(rng, 0.5, 1.0)));
    }
    out.push(plan(format!("vel-steps-{p_main:.0}kPa"), p_main, vs));
    let holds: &[f64] = pick(
        rng,
        &[
            &[3.0, 30.0, 300.0, 3000.0][..],
            &[10.0, 100.0, 1000.0][..],
            &[3.0, 10.0, 30.0, 100.0, 300.0][..],
            &[30.0, 100.0, 300.0, 1000.0, 3000.0][..],
        ],
    );
    let mut shs = vec![slide(v0, uniform(rng, 1.5, 2.0))];
    for h in holds {
        shs.push(Segment::Hold { duration: *h });
        shs.push(slide(v0, uniform(rng, 0.4, 0.8)));
    }
    out.push(plan(format!("shs-{p_main:.0}kPa"), p_main, shs));
    let amp = uniform(rng, 0.5, 1.5);
    let mut cyc = vec![slide(v0, amp)];
    for _ in 0..rng.gen_range(3..=4) {
        cyc.push(slide(v0, -2.0 * amp));
        cyc.push(slide(v0, 2.0 * amp));
    }
    cyc.push(slide(v0, -amp));
    out.push(plan(format!("cyclic-{p_cyc:.0}kPa"), p_cyc, cyc));
    let unloaded = rng.gen_range(0..mono.len());
    for (k, p) in mono.into_iter().enumerate() {
        let travel = uniform(rng, 3.0, 6.0);
        let segs = if unloads && k == unloaded {
            unloaded_half_way(v0, travel, rng)
        } else {
            vec![slide(v0, travel)]
        };
        out.push(plan(format!("mono-{p:.0}kPa"), p, segs));
    }
    out
}

/// A monotonic slide over `travel` mm at `v0`, unloaded to 5–20 % of its shear over 10–30 s
/// half way, held 5–30 s, and reloaded.
fn unloaded_half_way(v0: f64, travel: f64, rng: &mut ChaCha8Rng) -> Vec<Segment> {
    vec![
        slide(v0, 0.5 * travel),
        Segment::Unload {
            fraction: uniform(rng, 0.05, 0.2),
            duration: uniform(rng, 10.0, 30.0),
        },
        Segment::Hold {
            duration: uniform(rng, 5.0, 30.0),
        },
        slide(v0, 0.5 * travel),
    ]
}

/// A direct-shear programme at the base rate `v0`: monotonic tests at three or four normal
/// stresses (25 to 400 kPa), each over 5–10 mm, through its peak to the residual; with
/// `unloads`, one of them is unloaded, held and reloaded half way.
pub fn direct_shear_plans(v0: f64, unloads: bool, rng: &mut ChaCha8Rng) -> Vec<TestPlan> {
    let mut stresses = vec![25.0, 50.0, 100.0, 200.0, 300.0, 400.0];
    let keep = if rng.gen::<bool>() { 3 } else { 4 };
    while stresses.len() > keep {
        let i = rng.gen_range(0..stresses.len());
        stresses.remove(i);
    }
    let unloaded = unloads.then(|| rng.gen_range(0..stresses.len()));
    stresses
        .into_iter()
        .enumerate()
        .map(|(k, p)| {
            let travel = uniform(rng, 5.0, 10.0);
            let segments = if unloaded == Some(k) {
                unloaded_half_way(v0, travel, rng)
            } else {
                vec![slide(v0, travel)]
            };
            TestPlan {
                name: format!("ds-{p:.0}kPa"),
                p,
                segments,
                cut_mm: None,
                toe: None,
            }
        })
        .collect()
}

/// The rig and logger of a set of `profile`, and its tests changed to match (toes, cuts).
pub fn artifacts(
    profile: Profile,
    b: &Base,
    plans: &mut [TestPlan],
    rng: &mut ChaCha8Rng,
) -> Artifacts {
    let machine = profile.rig().then(|| log_uniform(rng, 0.002, 0.02));
    rig_and_logger(profile, b, plans, rng, machine, profile == Profile::Lab)
}

/// The rig and logger of a direct-shear programme of `profile`: whatever the profile, the
/// specimen and the box are soft in series with the interface (10⁻⁴–10⁻³ kN/mm³, i.e. 100 to
/// 1000 kPa per mm of the recorded displacement), and every file starts at rest (no cuts).
pub fn direct_shear_artifacts(
    profile: Profile,
    b: &Base,
    plans: &mut [TestPlan],
    rng: &mut ChaCha8Rng,
) -> Artifacts {
    let machine = Some(log_uniform(rng, 1e-4, 1e-3));
    rig_and_logger(profile, b, plans, rng, machine, false)
}

/// The rig and logger of a set of `profile` with the series spring `machine` [kN/mm³], the
/// first tests cut from a longer run when `cuts`.
fn rig_and_logger(
    profile: Profile,
    b: &Base,
    plans: &mut [TestPlan],
    rng: &mut ChaCha8Rng,
    machine: Option<f64>,
    cuts: bool,
) -> Artifacts {
    let alpha = b.alpha_t * KPA_PER_MM_PER_KN_MM3;
    let series = match machine {
        Some(m) => 1.0 / (1.0 / alpha + 1.0 / (m * KPA_PER_MM_PER_KN_MM3)),
        None => alpha,
    };
    if cuts {
        // The velocity steps, and half the time the holds too, come from a longer run: cut
        // during the run-in's steady sliding.
        let cut = if rng.gen::<bool>() { 2 } else { 1 };
        for plan in plans.iter_mut().take(cut) {
            plan.cut_mm = Some((uniform(rng, 1.0, 1.4), rng.gen::<bool>()));
        }
    }
    let mut seating_toes = Vec::new();
    if profile.rig() {
        for plan in plans.iter_mut().filter(|p| p.cut_mm.is_none()) {
            let toe = Toe {
                gap_mm: uniform(rng, 0.05, 0.8),
                force_kpa: uniform(rng, 0.003, 0.006) * b.mu_s * plan.p,
            };
            plan.toe = Some(toe);
            seating_toes.push(SeatingToe {
                test: plan.name.clone(),
                gap_mm: toe.gap_mm,
                shear_scale_kpa: toe.force_kpa,
            });
        }
    }
    let unloads = plans
        .iter()
        .filter(|p| {
            p.segments
                .iter()
                .any(|s| matches!(s, Segment::Unload { .. }))
        })
        .map(|p| p.name.clone())
        .collect();
    let white = log_uniform(rng, 0.1, 0.5);
    let correlated = profile != Profile::Clean;
    let noise = Noise {
        white_kpa: white,
        ar1_kpa: if correlated {
            white * uniform(rng, 0.3, 1.0)
        } else {
            0.0
        },
        ar1_tau_s: log_uniform(rng, 2.0, 30.0),
        slip_mm: uniform(rng, 0.0, 3e-4),
    };
    let (sampling, jitter, quantum) = if profile.logger() {
        (
            Sampling::RateAdaptive {
                slip_per_row: uniform(rng, 0.002, 0.005),
                min_dt: 0.01,
                max_dt: 30.0,
                min_hold_dt: uniform(rng, 0.2, 1.0),
                hold_growth: 1.5,
            },
            uniform(rng, 0.1, 0.4),
            1e-4,
        )
    } else {
        (
            Sampling::RateAdaptive {
                slip_per_row: uniform(rng, 0.004, 0.006),
                min_dt: 0.01,
                max_dt: 1e9,
                min_hold_dt: uniform(rng, 2.0, 5.0),
                hold_growth: 1.0,
            },
            0.0,
            1e-5,
        )
    };
    Artifacts {
        profile,
        machine_kn_mm3: machine,
        series_kpa_per_mm: series,
        seating_toes,
        midrun: Vec::new(),
        unloads,
        sampling,
        jitter,
        noise,
        resolution: Resolution {
            slip_mm: quantum,
            shear_kpa: 1e-3,
            time_s: 1e-3,
        },
    }
}
