//! Generated sets and their truth: classes of effects, sets in the data format, `truth.json` in
//! the schema of the shared dev families, whole campaigns, and the long record `subfric bench`
//! times the diagnosis on.

use super::draw::{self, Artifacts, Form, MidRun, Profile, Setting, TestPlan};
use super::effects::{Combine, Effects, Rate, RateForm, Reading, Slip, SlipShape, StateLaw};
use super::forward::{Base, Contact, GenError, Rig};
use super::path::{run, Run, Sampling, Segment};
use super::record::{clean_shear, record, test_data, Cut, Noise, Resolution};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::{json, Map, Value};
use std::path::Path;
use subfric_data::{write_atomic, write_set, ExperimentMeta, ExperimentSet, Interface};

/// Substep accuracy of generated sets (1: the forward model's limits).
const ACCURACY: f64 = 1.0;

/// An effect is drawn again until it moves [`VISIBLE_ROWS`] rows of some test's recorded shear
/// by at least this many noise SDs (a set whose effect is buried in the noise holds none that a
/// diagnosis could see).
pub const MIN_VISIBILITY: f64 = 2.5;

/// Rows an effect must move (see [`MIN_VISIBILITY`]).
pub const VISIBLE_ROWS: usize = 10;

/// Draws of an effect's parameters per draw of the set.
const DRAWS: usize = 10;

/// Draws of the whole set (base, tests, rig) before the most visible draw is kept.
const SET_DRAWS: usize = 8;

/// A class of generated sets: the forms built in (empty: none).
pub type Class = Vec<Form>;

/// The classes of a campaign of `layout`: of [`all_classes`], those whose every form can show
/// in its tests (numbered as there, so that set names and seeds agree).
pub fn classes_of(layout: Layout) -> Vec<(usize, Class)> {
    all_classes()
        .into_iter()
        .enumerate()
        .filter(|(_, c)| c.iter().all(|f| layout.shows(*f)))
        .collect()
}

/// None, every form alone, and six pairs of two effects; the load-cell creep, which came
/// later, last, so that the classes before it keep their numbers (and the seeds of their sets).
pub fn all_classes() -> Vec<Class> {
    let mut out: Vec<Class> = vec![Vec::new()];
    out.extend(
        Form::ALL
            .iter()
            .filter(|f| **f != Form::Creep)
            .map(|f| vec![*f]),
    );
    out.extend([
        vec![Form::RsfAgeing, Form::PressurePower],
        vec![Form::SlipExp, Form::PressureLinear],
        vec![Form::RsfSlip, Form::SlipCapped],
        vec![Form::HealLog, Form::DirectionMu],
        vec![Form::PressureExp, Form::DirectionMuK],
        vec![Form::RatePower, Form::SlipHyperbolic],
        vec![Form::Creep],
    ]);
    out
}

/// A class in words: "none", "rate and state, ageing law + pressure power law".
pub fn class_label(class: &[Form]) -> String {
    if class.is_empty() {
        return "none".into();
    }
    class
        .iter()
        .map(|f| f.label())
        .collect::<Vec<_>>()
        .join(" + ")
}

/// What a generated set holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    /// The families built in (empty: none; `unexplained` for a gap in the recording).
    pub families: Vec<&'static str>,
    /// The families and forms in words: "rate (rsf-ageing-creep) + pressure (pressure-power-mu)".
    pub label: String,
    /// The forms built in (the class).
    pub forms: Vec<Form>,
    /// The profile of rig and logger.
    pub profile: Profile,
    /// Its `truth.json` entry: effect, form, kw, params, effects, midrun, artifacts (the shared
    /// dev families' schema, plus `artifacts`, `forms` and `visibility`).
    pub json: Value,
}

/// A generated set and its truth.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The set, as if loaded from disk.
    pub set: ExperimentSet,
    /// What it holds.
    pub truth: Truth,
}

/// Options of the generator.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Rows relative to a lab file (0.5: half as many rows, for fast tests).
    pub rows_scale: f64,
    /// What tests a campaign holds.
    pub layout: Layout,
}

impl Options {
    /// Lab-file rows, the mixed campaign.
    pub const DEFAULT: Options = Options {
        rows_scale: 1.0,
        layout: Layout::Mixed,
    };

    /// The mixed campaign with rows scaled by `rows_scale`.
    pub const fn rows(rows_scale: f64) -> Options {
        Options {
            rows_scale,
            layout: Layout::Mixed,
        }
    }
}

impl Default for Options {
    fn default() -> Self {
        Options::DEFAULT
    }
}

/// What tests a campaign holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Layout {
    /// Velocity steps, slide–hold–slide, two-way cycles and monotonic tests (see
    /// [`draw::plans`]).
    #[default]
    Mixed,
    /// A direct-shear programme: monotonic tests only, at three or four normal stresses, each
    /// through its peak to the residual, on a soft rig (the specimen and the box in series
    /// with the interface: 10⁻⁴–10⁻³ kN/mm³, so that the peak comes at a few tenths of a mm to
    /// a mm or two of displacement; see [`draw::direct_shear_plans`]).
    DirectShear,
    /// A direct-shear programme of dense sand whose curves follow the geotechnical
    /// literature's empirical laws, not the paper's model (Bolton's stress–dilatancy peak, a
    /// saturating rise, exponential softening; see [`super::dense_sand`]): the shape a real
    /// shear box records. Two classes: none (one peak ratio at every stress; what is left is
    /// the shape the model lacks, `unexplained`) and pressure (Bolton's peak falling with the
    /// normal stress).
    DenseSand,
}

impl Layout {
    /// A class of this layout in words.
    pub fn class_label(self, class: &[Form]) -> String {
        match (self, class.is_empty()) {
            (Layout::DenseSand, true) => "the empirical shape alone (no listed effect)".into(),
            (Layout::DenseSand, false) => "pressure: Bolton's stress-dilatancy peak".into(),
            _ => class_label(class),
        }
    }

    /// Can an effect of `form` show in this layout's tests? A direct-shear programme slides at
    /// one rate in one direction without holds: only what changes with the normal stress, with
    /// slip or with time can show.
    pub fn shows(self, form: Form) -> bool {
        match self {
            Layout::Mixed => true,
            // A load-cell creep grows with time under load as slip hardening grows with slip:
            // monotonic tests at one rate, without holds, cannot tell the two apart.
            Layout::DirectShear => {
                matches!(form.family(), "pressure" | "slip-hardening" | "unexplained")
                    && form != Form::Creep
            }
            // One pressure class: Bolton's law stands for the family.
            Layout::DenseSand => form == Form::PressurePower,
        }
    }
}

/// The profile of set `k` of class number `class_index` (from 0): in turn, so that every
/// profile appears even with one set per class, and the first set with no effect is the one
/// with every artifact.
pub fn profile_of(class_index: usize, k: usize) -> Profile {
    Profile::ALL[(class_index + k) % Profile::ALL.len()]
}

/// The name of set `k` of class `class_index` (both from 0).
pub fn set_name(class_index: usize, k: usize) -> String {
    format!("gen-{:02}-{}", class_index + 1, k + 1)
}

/// The seed of set `k` of class `class_index` in a campaign of `seed`: each set can be made
/// alone, the same as in the whole campaign.
pub fn set_seed(seed: u64, class_index: usize, k: usize) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((class_index as u64) << 20)
        .wrapping_add(k as u64)
}

/// Set `k` of class `class_index` of a campaign of `seed`.
pub fn campaign_set(
    seed: u64,
    class_index: usize,
    k: usize,
    class: &[Form],
    opts: &Options,
) -> Result<Generated, GenError> {
    if opts.layout == Layout::DenseSand {
        return Ok(super::dense_sand::dense_sand_programme(
            &set_name(class_index, k),
            !class.is_empty(),
            set_seed(seed, class_index, k),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(set_seed(seed, class_index, k));
    generate(
        &set_name(class_index, k),
        class,
        profile_of(class_index, k),
        opts,
        &mut rng,
    )
}

/// [`generate`] from a seed.
pub fn generate_seeded(
    name: &str,
    class: &[Form],
    profile: Profile,
    opts: &Options,
    seed: u64,
) -> Result<Generated, GenError> {
    generate(
        name,
        class,
        profile,
        opts,
        &mut ChaCha8Rng::seed_from_u64(seed),
    )
}

/// The shear of every test noise-free, each test's rows drawn by its own seeded clock so that
/// runs of different effects share their instants.
fn run_all(
    base: &Base,
    fx: &Effects,
    plans: &[TestPlan],
    arts: &Artifacts,
    clock_seed: u64,
) -> Result<Vec<Run>, GenError> {
    plans
        .iter()
        .enumerate()
        .map(|(k, plan)| {
            let rig = Rig {
                machine_kn_mm3: arts.machine_kn_mm3,
                toe: plan.toe,
            };
            let mut c = Contact::new(*base, *fx, rig, plan.p, ACCURACY);
            let mut clock = ChaCha8Rng::seed_from_u64(clock_seed.wrapping_add(k as u64));
            run(
                &mut c,
                &plan.segments,
                plan.p,
                &arts.sampling,
                arts.jitter,
                &mut clock,
            )
        })
        .collect()
}

/// The first row of each test's file (a cut at a displacement of the run).
fn first_rows(plans: &[TestPlan], runs: &[Run]) -> Vec<usize> {
    plans
        .iter()
        .zip(runs)
        .map(|(plan, r)| match plan.cut_mm {
            Some((at, _)) => r.u.iter().position(|u| *u >= at).unwrap_or(0),
            None => 0,
        })
        .collect()
}

/// How clearly `fx` shows in the recorded rows: over the tests, the largest of the
/// [`VISIBLE_ROWS`]-th largest change it makes to the noise-free shear of `base_runs`, in noise
/// SDs (a change of several SDs on a handful of rows, such as a healing peak, counts; one row
/// does not).
fn visibility(fx: &Effects, runs: &[Run], base_runs: &[Run], from: &[usize], noise: &Noise) -> f64 {
    runs.iter()
        .zip(base_runs)
        .zip(from)
        .map(|((r, b), &i0)| {
            let with = clean_shear(r, fx.gap.as_ref());
            let mut d: Vec<f64> = with[i0..]
                .iter()
                .zip(&b.f[i0..])
                .map(|(x, y)| (x - y).abs())
                .collect();
            d.sort_by(|x, y| y.total_cmp(x));
            d.get(VISIBLE_ROWS - 1).copied().unwrap_or(0.0)
        })
        .fold(0.0, f64::max)
        / noise.shear_sd()
}

/// Scales the rows of a sampling.
fn scaled(s: Sampling, rows_scale: f64) -> Sampling {
    let k = rows_scale.max(1e-3);
    match s {
        Sampling::Uniform { dt } => Sampling::Uniform { dt: dt / k },
        Sampling::RateAdaptive {
            slip_per_row,
            min_dt,
            max_dt,
            min_hold_dt,
            hold_growth,
        } => Sampling::RateAdaptive {
            slip_per_row: slip_per_row / k,
            min_dt,
            max_dt: max_dt / k,
            min_hold_dt: min_hold_dt / k,
            hold_growth,
        },
    }
}

/// One draw of everything but the noise.
struct World {
    base: Base,
    plans: Vec<TestPlan>,
    arts: Artifacts,
    clock_seed: u64,
    fx: Effects,
    /// Visibility of each effect (see [`MIN_VISIBILITY`]).
    seen: Vec<f64>,
}

impl World {
    /// The least visible effect's visibility (infinite with none).
    fn weakest(&self) -> f64 {
        self.seen.iter().cloned().fold(f64::INFINITY, f64::min)
    }
}

/// Draws base, tests, rig and logger, then each effect of `class` until it shows.
fn draw_world(
    class: &[Form],
    profile: Profile,
    opts: &Options,
    rng: &mut ChaCha8Rng,
) -> Result<World, GenError> {
    let base = draw::base(rng);
    let v0 = draw::log_uniform(rng, 0.005, 0.02);
    let (plans, mut arts) = match opts.layout {
        Layout::Mixed => {
            let mut plans = draw::plans(v0, profile.rig(), rng);
            let arts = draw::artifacts(profile, &base, &mut plans, rng);
            (plans, arts)
        }
        // A dense-sand programme is made by its own empirical laws (`campaign_set`); drawn
        // through the forward model it is a direct-shear programme.
        Layout::DirectShear | Layout::DenseSand => {
            let mut plans = draw::direct_shear_plans(v0, profile.rig(), rng);
            let arts = draw::direct_shear_artifacts(profile, &base, &mut plans, rng);
            (plans, arts)
        }
    };
    arts.sampling = scaled(arts.sampling, opts.rows_scale);
    let setting = Setting {
        v0,
        p_ref: plans[0].p,
        p_max: plans.iter().map(|p| p.p).fold(0.0, f64::max),
        k_series: arts.series_kpa_per_mm,
        compliant: arts.machine_kn_mm3.is_some(),
    };
    let clock_seed: u64 = rng.gen();
    let mut fx = Effects::default();
    let mut seen = Vec::new();
    if !class.is_empty() {
        let base_runs = run_all(&base, &Effects::default(), &plans, &arts, clock_seed)?;
        let from = first_rows(&plans, &base_runs);
        for &form in class {
            let mut best: Option<(f64, Effects)> = None;
            for _ in 0..DRAWS {
                let mut one = Effects::default();
                draw::add_effect(&mut one, form, &setting, rng);
                let runs = run_all(&base, &one, &plans, &arts, clock_seed)?;
                let v = visibility(&one, &runs, &base_runs, &from, &arts.noise);
                if best.as_ref().is_none_or(|(b, _)| v > *b) {
                    best = Some((v, one));
                }
                if v >= MIN_VISIBILITY {
                    break;
                }
            }
            let (v, one) = best.expect("at least one draw");
            merge(&mut fx, &one);
            seen.push(v);
        }
    }
    Ok(World {
        base,
        plans,
        arts,
        clock_seed,
        fx,
        seen,
    })
}

/// Generates one set with the forms of `class` and the artifacts of `profile`: the whole set
/// is drawn again (up to a limit, then the most visible draw is kept) until each effect shows
/// in the data ([`MIN_VISIBILITY`]).
pub fn generate(
    name: &str,
    class: &[Form],
    profile: Profile,
    opts: &Options,
    rng: &mut ChaCha8Rng,
) -> Result<Generated, GenError> {
    let mut world = draw_world(class, profile, opts, rng)?;
    for _ in 1..SET_DRAWS {
        if world.weakest() >= MIN_VISIBILITY {
            break;
        }
        let again = draw_world(class, profile, opts, rng)?;
        if again.weakest() > world.weakest() {
            world = again;
        }
    }
    let World {
        base,
        plans,
        mut arts,
        clock_seed,
        fx,
        seen,
    } = world;
    let runs = run_all(&base, &fx, &plans, &arts, clock_seed)?;
    let from = first_rows(&plans, &runs);
    let mut tests = Vec::new();
    for ((plan, r), &i0) in plans.iter().zip(&runs).zip(&from) {
        let cut = plan.cut_mm.map(|(_, rezeroed)| Cut { from: i0, rezeroed });
        if let Some((_, rezeroed)) = plan.cut_mm {
            arts.midrun.push(MidRun {
                test: plan.name.clone(),
                cut_at_s: r.t[i0],
                cut_at_mm: r.u[i0],
                rezeroed,
            });
        }
        let rec = record(r, fx.gap.as_ref(), &arts.noise, &arts.resolution, cut, rng);
        let comments = vec![format!(
            "generated by the subfric self-check generator (independent forward model), set {name}"
        )];
        tests.push(test_data(&plan.name, plan.p, rec, comments));
    }
    let truth = truth(class, &base, &fx, &arts, &seen);
    let set = generated_set(
        name,
        format!("Sand-steel interface, generated set {name}"),
        "subfric selfcheck generator",
        "synthetic: an independent forward model with withheld effects and rig artifacts",
        "silica sand",
        tests,
    );
    Ok(Generated { set, truth })
}

/// A generated set of `tests` on steel, named `name` with its title, source, provenance and
/// soil.
pub(super) fn generated_set(
    name: &str,
    title: String,
    source: &str,
    provenance: &str,
    soil: &str,
    tests: Vec<subfric_data::TestData>,
) -> ExperimentSet {
    ExperimentSet {
        dir: name.into(),
        meta: ExperimentMeta {
            name: name.into(),
            title,
            source: source.into(),
            provenance: Some(provenance.into()),
            interface: Interface {
                soil: Some(soil.into()),
                surface: Some("steel".into()),
                roughness_rmax_um: None,
                extra: Default::default(),
            },
            tests: tests.iter().map(|t| t.spec.clone()).collect(),
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests,
    }
}

/// Copies the effects `one` switches on into `fx`.
fn merge(fx: &mut Effects, one: &Effects) {
    fx.rate = one.rate.or(fx.rate);
    fx.pressure = one.pressure.or(fx.pressure);
    fx.slip = one.slip.or(fx.slip);
    fx.healing = one.healing.or(fx.healing);
    fx.direction = one.direction.or(fx.direction);
    fx.gap = one.gap.or(fx.gap);
}

/// The truth of a set, as `truth.json` holds it.
fn truth(class: &[Form], base: &Base, fx: &Effects, arts: &Artifacts, visibility: &[f64]) -> Truth {
    // In the order of the class (its first family is the entry's `effect`).
    let mut described = fx.described();
    described.sort_by_key(|d| class.iter().position(|f| f.family() == d.0));
    let families: Vec<&'static str> = described.iter().map(|d| d.0).collect();
    let mut kw = Map::new();
    for (_, _, m) in &described {
        kw.extend(m.clone());
    }
    let form = if described.is_empty() {
        "none".to_string()
    } else {
        described
            .iter()
            .map(|d| d.1.clone())
            .collect::<Vec<_>>()
            .join("+")
    };
    let label = if described.is_empty() {
        "none".to_string()
    } else {
        described
            .iter()
            .map(|(f, n, _)| format!("{f} ({n})"))
            .collect::<Vec<_>>()
            .join(" + ")
    };
    let json = json!({
        "effect": families.first().copied().unwrap_or("none"),
        "form": form,
        "kw": kw,
        "params": {
            "mu_s": base.mu_s,
            "mu_k": base.mu_k,
            "kappa": base.kappa,
            "xi": base.xi,
            "u_tilde": base.u_tilde,
            "alpha_t": base.alpha_t,
            "alpha_n": base.alpha_t,
        },
        "effects": if families.is_empty() { vec!["none"] } else { families.clone() },
        "midrun": !arts.midrun.is_empty(),
        "artifacts": arts,
        "forms": described
            .iter()
            .map(|(f, n, m)| json!({"effect": f, "form": n, "kw": m}))
            .collect::<Vec<_>>(),
        "visibility": visibility,
    });
    Truth {
        families,
        label,
        forms: class.to_vec(),
        profile: arts.profile,
        json,
    }
}

/// Writes generated sets into the folder `dir`, one folder per set and their truths in
/// `truth.json` (which `subfric selfcheck --sets` scores). Whether `dir` may already exist is
/// the caller's decision.
pub fn write_campaign(dir: &Path, sets: &[Generated]) -> Result<(), subfric_data::DataError> {
    let mut truths = Map::new();
    for g in sets {
        write_set(&g.set, &dir.join(&g.set.meta.name))?;
        truths.insert(g.set.meta.name.clone(), g.truth.json.clone());
    }
    let mut text = serde_json::to_string_pretty(&Value::Object(truths))
        .expect("truth values are finite numbers and strings");
    text.push('\n');
    write_atomic(&dir.join("truth.json"), text.as_bytes())
}

/// A long record like a real velocity-step run, for timing the diagnosis of records of 10⁴–10⁵
/// rows: three tests at 5, 10 and 15 MPa, each a 0.6-mm run-in at 10 µm/s, a 100-s hold and a
/// ladder 1 → 3 → 10 → 30 → 100 → 300 → 100 → 30 → 10 → 3 → 1 µm/s of 0.4 mm per step,
/// about `rows_per_test` rows each (denser when faster, a jittering clock, 0.1 µm quantised
/// displacement), from rate and state (ageing law, locked) with exponential slip hardening.
pub fn long_record_set(rows_per_test: usize, seed: u64) -> Result<ExperimentSet, GenError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let base = draw::base(&mut rng);
    let um = 1e-3;
    let fx = Effects {
        rate: Some(Rate {
            form: RateForm::State {
                law: StateLaw::Ageing,
                a: draw::uniform(&mut rng, 0.006, 0.012),
                b: draw::uniform(&mut rng, 0.006, 0.014),
                dc: draw::log_uniform(&mut rng, 0.005, 0.05),
            },
            v_star: 10.0 * um,
            v_min: 1e-7,
            reading: Reading::Locked,
        }),
        slip: Some(Slip {
            shape: SlipShape::Exponential,
            combine: Combine::Additive,
            amount: draw::uniform(&mut rng, 0.03, 0.08),
            length: draw::uniform(&mut rng, 1.0, 3.0),
        }),
        ..Effects::default()
    };
    let mut segs = vec![
        Segment::Slide {
            rate: 10.0 * um,
            distance: 0.6,
        },
        Segment::Hold { duration: 100.0 },
    ];
    for v in [
        1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 100.0, 30.0, 10.0, 3.0, 1.0,
    ] {
        segs.push(Segment::Slide {
            rate: v * um,
            distance: 0.4,
        });
    }
    let sampling = Sampling::RateAdaptive {
        slip_per_row: 5.0 / rows_per_test.max(100) as f64,
        min_dt: 0.005,
        max_dt: 30.0,
        min_hold_dt: 0.5,
        hold_growth: 1.5,
    };
    let noise = Noise {
        white_kpa: 5.0,
        ar1_kpa: 0.0,
        ar1_tau_s: 1.0,
        slip_mm: 3e-5,
    };
    let res = Resolution {
        slip_mm: 1e-4,
        shear_kpa: 1e-3,
        time_s: 1e-3,
    };
    let mut tests = Vec::new();
    for p in [5000.0, 10_000.0, 15_000.0] {
        let mut c = Contact::new(base, fx, Rig::default(), p, ACCURACY);
        let r = run(&mut c, &segs, p, &sampling, 0.2, &mut rng)?;
        let rec = record(&r, None, &noise, &res, None, &mut rng);
        let name = format!("sn{:02}MPa", (p / 1000.0) as usize);
        tests.push(test_data(
            &name,
            p,
            rec,
            vec!["generated long record".into()],
        ));
    }
    Ok(ExperimentSet {
        dir: "long-record".into(),
        meta: ExperimentMeta {
            name: "long-record".into(),
            title: "generated long velocity-step record".into(),
            source: "subfric bench generator".into(),
            provenance: Some("synthetic".into()),
            interface: Interface::default(),
            tests: tests.iter().map(|t| t.spec.clone()).collect(),
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests,
    })
}
