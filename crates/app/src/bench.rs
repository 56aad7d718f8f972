//! `subfric bench`: speed of the model step, of fitting each paper table, of multi-start
//! fitting on 1 core versus all cores, of whole diagnoses, of a fit of 10 000 short tests, and of
//! the posterior sampler.

use crate::fit::{run_fit, FitRequest};
use crate::progress::Silent;
use anyhow::{bail, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;
use subfric_fit::FitOptions;
use subfric_model::{simulate, Contact1, Control, Model, Params, Protocol, State1};

/// One part of the benchmark (`subfric bench --only`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum BenchPart {
    /// The model step on one core.
    Step,
    /// One full fit of each set of the experiments folder.
    Fits,
    /// A multi-start fit on 1 thread and on all.
    Multistart,
    /// A fit of 10 000 short tests.
    ManyTests,
    /// Whole diagnoses of two generated sets.
    Diagnoses,
    /// The posterior sampler.
    Sampler,
}

impl BenchPart {
    /// Every part, in the order they run.
    pub const ALL: [BenchPart; 6] = [
        BenchPart::Step,
        BenchPart::Fits,
        BenchPart::Multistart,
        BenchPart::ManyTests,
        BenchPart::Diagnoses,
        BenchPart::Sampler,
    ];

    /// Whether the part reads the experiments folder.
    fn reads_sets(self) -> bool {
        matches!(
            self,
            BenchPart::Fits | BenchPart::Multistart | BenchPart::Sampler
        )
    }
}

/// Results; a part not asked for is `None` (left out of the JSON).
#[derive(Debug, Serialize)]
pub struct BenchReport {
    /// The step benchmark case.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_case: Option<String>,
    /// Steps per second on one core (best of repeats).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub steps_per_second: Option<f64>,
    /// Whether the hot loop gave bit-identical results to the general simulate path.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identical_to_simulate: Option<bool>,
    /// Seconds for one full fit of each paper set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit_seconds: Option<Vec<(String, f64)>>,
    /// Multi-start fitting: seconds with 1 thread, with all threads, threads, speed-up.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub multistart: Option<MultiStart>,
    /// Whole diagnoses of generated sets of lab size.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diagnoses: Option<Vec<DiagnosisTime>>,
    /// A fit of a set of many short tests (the cost must grow linearly with their number).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub many_tests: Option<ManyTestsFit>,
    /// The posterior sampler's model runs per second.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampler: Option<SamplerSpeed>,
    /// The model step against a peer script run in the same benchmark (`--peer`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peer: Option<PeerStep>,
    /// Whole diagnoses of the records asked for (`--record`), from the folder to the verdict.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub records: Option<Vec<DiagnosisTime>>,
}

/// What `subfric bench` measures beyond its parts: the step against a peer, and diagnoses of
/// records the user names (a lab's own, or `../shared/real-dev`'s).
#[derive(Clone, Debug, Default)]
pub struct BenchExtras {
    /// A peer script that prints `… X steps/s` for the step protocol of [`step_case`] (the
    /// numba peer `peer_numba.py`), run with `python3`.
    pub peer: Option<PathBuf>,
    /// Set folders to diagnose, each timed.
    pub records: Vec<PathBuf>,
}

/// The model step against a peer, alternated round by round in one run (ours, the peer's, …),
/// the best of each kept: on a shared machine the two then see the same load.
#[derive(Debug, Serialize)]
pub struct PeerStep {
    /// The peer script.
    pub peer: String,
    /// Rounds of the alternation.
    pub rounds: usize,
    /// Our steps per second (best round).
    pub steps_per_second: f64,
    /// The peer's steps per second (best round).
    pub peer_steps_per_second: f64,
    /// Ours over the peer's.
    pub ratio: f64,
}

/// Speed of the posterior sampler (`fit --posterior`): a fixed number of steps of the ensemble
/// from the least-squares optimum, walkers moved in parallel on every thread.
#[derive(Debug, Serialize)]
pub struct SamplerSpeed {
    /// Set sampled.
    pub set: String,
    /// Walkers and steps.
    pub walkers: usize,
    /// Steps of the ensemble.
    pub steps: usize,
    /// Model runs of the sampler.
    pub model_runs: usize,
    /// Wall time of the sampling [s].
    pub seconds: f64,
    /// Model runs per second.
    pub runs_per_second: f64,
    /// Threads.
    pub threads: usize,
    /// The machine's 1-minute load average when it ended (Linux; NaN elsewhere): on a shared
    /// machine the wall time says little without it.
    pub load_average: f64,
}

/// Walkers and steps of the sampler benchmark (as `cargo bench -p subfric-posterior`).
const SAMPLER_WALKERS: usize = 32;
const SAMPLER_STEPS: usize = 100;

/// Samples the posterior of `set` for [`SAMPLER_STEPS`] steps (a budget far below
/// convergence, so the same work every time) and times it.
fn sampler_speed(set: &Path) -> Result<SamplerSpeed> {
    let mut req = request(set.to_path_buf());
    req.posterior = Some(crate::posterior::PosteriorRequest {
        max_evals: SAMPLER_WALKERS * (SAMPLER_STEPS + 1),
        ..Default::default()
    });
    let fitted = crate::fit::fit(&req, &Silent)?;
    let Some(s) = fitted.posterior else {
        bail!("the posterior was asked for and not sampled");
    };
    let p = &s.posterior;
    Ok(SamplerSpeed {
        set: set
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string(),
        walkers: p.convergence.walkers,
        steps: p.convergence.steps,
        model_runs: p.model_runs,
        seconds: p.elapsed_s,
        runs_per_second: p.model_runs as f64 / p.elapsed_s,
        threads: rayon::current_num_threads(),
        load_average: std::fs::read_to_string("/proc/loadavg")
            .ok()
            .and_then(|l| l.split_whitespace().next()?.parse().ok())
            .unwrap_or(f64::NAN),
    })
}

/// One timed diagnosis.
#[derive(Debug, Serialize)]
pub struct DiagnosisTime {
    /// What was diagnosed.
    pub case: String,
    /// Rows of the set.
    pub rows: usize,
    /// Tests of the set.
    pub tests: usize,
    /// Wall time from the loaded set to the verdict [s].
    pub seconds: f64,
    /// Peak resident memory of the process after it [MB].
    pub peak_memory_mb: f64,
    /// Processor time of the process during it, all threads [s] (Linux; 0 elsewhere): over
    /// `seconds`, how many cores it kept busy.
    pub cpu_seconds: f64,
    /// Threads it could use.
    pub threads: usize,
    /// The verdict.
    pub verdict: String,
}

/// The verdict of a diagnosis as the benchmark prints it (`none` for no effect).
fn verdict_words(d: &subfric_diagnose::Diagnosis) -> String {
    let v = d
        .verdict
        .effects
        .iter()
        .map(|e| e.effect.to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    if v.is_empty() {
        "none".into()
    } else {
        v
    }
}

/// Times a whole diagnosis of each set folder of `records`, from loading it to the verdict, as
/// `subfric diagnose` runs it; an error names the folder.
fn record_diagnoses(records: &[PathBuf]) -> Result<Vec<DiagnosisTime>> {
    records
        .iter()
        .map(|dir| {
            let (t0, cpu0) = (Instant::now(), cpu_seconds());
            let d = crate::diagnose::diagnose(
                dir,
                &subfric_diagnose::DiagnoseOptions::default(),
                &Silent,
            )?;
            Ok(DiagnosisTime {
                case: folder_name(dir),
                rows: d.diagnosis.prepared.iter().map(|p| p.full.len()).sum(),
                tests: d.diagnosis.prepared.len(),
                seconds: t0.elapsed().as_secs_f64(),
                peak_memory_mb: peak_memory_mb(),
                cpu_seconds: cpu_seconds() - cpu0,
                threads: rayon::current_num_threads(),
                verdict: verdict_words(&d.diagnosis),
            })
        })
        .collect()
}

/// Rounds of the step's alternation with a peer.
const PEER_ROUNDS: usize = 3;

/// The peer's steps per second, from the last `… X steps/s` line it prints.
fn peer_steps_per_second(peer: &Path) -> Result<f64> {
    let out = std::process::Command::new("python3")
        .arg(peer)
        .output()
        .map_err(|e| anyhow::anyhow!("{}: cannot run python3 on the peer: {e}", peer.display()))?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = stderr.lines().rev().take(3).collect();
        bail!(
            "{}: the peer failed ({}): {} (the numba peer needs numpy and numba: pip install numpy numba)",
            peer.display(),
            out.status,
            tail.into_iter().rev().collect::<Vec<_>>().join(" / ")
        );
    }
    stdout
        .lines()
        .rev()
        .find_map(|l| {
            let before = l.trim().strip_suffix("steps/s")?;
            before.split_whitespace().last()?.parse::<f64>().ok()
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| {
            anyhow::anyhow!(
                "{}: the peer printed no `… X steps/s` line (it printed: {})",
                peer.display(),
                stdout.trim()
            )
        })
}

/// Our step and the peer's, alternated for [`PEER_ROUNDS`] rounds, the best of each.
fn step_against_peer(peer: &Path) -> Result<PeerStep> {
    let (mut ours, mut theirs) = (0.0f64, 0.0f64);
    for _ in 0..PEER_ROUNDS {
        let (sps, identical) = steps_per_second(3);
        if !identical {
            bail!("the step benchmark's hot loop differs from the general simulate path");
        }
        ours = ours.max(sps);
        theirs = theirs.max(peer_steps_per_second(peer)?);
    }
    Ok(PeerStep {
        peer: peer.display().to_string(),
        rounds: PEER_ROUNDS,
        steps_per_second: ours,
        peer_steps_per_second: theirs,
        ratio: ours / theirs,
    })
}

/// Peak resident memory of this process [MB] (Linux; 0 elsewhere).
fn peak_memory_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines().find(|l| l.starts_with("VmHWM:")).and_then(|l| {
                l.split_whitespace()
                    .nth(1)
                    .and_then(|v| v.parse::<f64>().ok())
            })
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// Times the diagnosis of a lab-like set of about 15 000 rows (rate and state, a lab logger's
/// sampling) and of a 3-test long record of about 115 000 rows, both made by the independent
/// generator of `subfric-harness` (the targets: under 10 s and under 20 s on 2 cores).
fn diagnoses() -> Result<Vec<DiagnosisTime>> {
    use subfric_diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions};
    use subfric_harness::generator::{generate_seeded, long_record_set, Form, Options, Profile};
    let lab = generate_seeded(
        "lab-15k",
        &[Form::RsfAgeing],
        Profile::Logger,
        &Options::rows(1.4),
        5,
    )
    .map_err(|e| anyhow::anyhow!("generating the lab-like set: {e}"))?
    .set;
    let long = long_record_set(38_500, 9)
        .map_err(|e| anyhow::anyhow!("generating the long record: {e}"))?;
    Ok([
        ("lab-like set, rate and state", lab),
        ("long velocity-step record", long),
    ]
    .into_iter()
    .map(|(case, set)| {
        let rows: usize = set.tests.iter().map(|t| t.len()).sum();
        let (t0, cpu0) = (Instant::now(), cpu_seconds());
        let verdict = match diagnose(&prepare_for_diagnosis(&set), &DiagnoseOptions::default()) {
            Ok(d) => verdict_words(&d),
            Err(e) => format!("error: {e}"),
        };
        DiagnosisTime {
            case: case.into(),
            rows,
            tests: set.tests.len(),
            seconds: t0.elapsed().as_secs_f64(),
            peak_memory_mb: peak_memory_mb(),
            cpu_seconds: cpu_seconds() - cpu0,
            threads: rayon::current_num_threads(),
            verdict,
        }
    })
    .collect())
}

/// One timed fit of a set of many short tests, generated.
#[derive(Debug, Serialize)]
pub struct ManyTestsFit {
    /// Tests of the set.
    pub tests: usize,
    /// Rows of each test.
    pub rows_per_test: usize,
    /// Wall time of `subfric fit` without its output: reading, segmenting, calibrating with
    /// profiles, per-test misfits [s]. The target: under 60 s on 2 cores.
    pub seconds: f64,
    /// Processor time of those threads together [s] (Linux; 0 elsewhere): the wall time an
    /// idle machine of 2 cores needs is about half of it, whatever else runs meanwhile.
    pub cpu_seconds: f64,
    /// Model runs of the calibration (a run of the global stage covers its share of the tests).
    pub model_runs: usize,
    /// Largest relative error of the fitted μ_s, μ_k against the parameters the data came from.
    pub worst_recovery: f64,
}

/// Processor time (user and system) of this process so far [s]; 0 where /proc is absent.
fn cpu_seconds() -> f64 {
    // Fields 14 and 15 of /proc/self/stat, in USER_HZ (100 per second by the Linux ABI). The
    // command name (field 2) is in parentheses and may hold spaces: count after the last ')'.
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = s.rsplit_once(')')?.1;
            let fields: Vec<&str> = rest.split_whitespace().collect();
            let ticks = |k: usize| fields.get(k)?.parse::<f64>().ok();
            // After the ')': field 3 is at index 0, so field 14 at 11 and 15 at 12.
            Some((ticks(11)? + ticks(12)?) / 100.0)
        })
        .unwrap_or(0.0)
}

/// A folder under the system's temporary folder, removed when dropped.
struct TempFolder(PathBuf);

impl Drop for TempFolder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `n` slip-controlled tests of 39 rows written as a set under `dir`: monotonic slides to 3 mm,
/// rows denser at the start (where the peak is), each at its own normal stress (50–200 kPa)
/// and rate (0.005–0.05 mm/s), computed with Table 1 (medium)'s parameters plus 0.3 % noise.
/// Returns the parameters.
fn many_tests_set(dir: &Path, n: usize) -> Result<Model> {
    use subfric_data::{
        write_set, ControlColumn, ExperimentMeta, ExperimentSet, TestData, TestSpec,
    };
    let truth = Model::base(Params {
        mu_s: 0.37,
        mu_k: 0.3,
        kappa: 33.0,
        xi: 0.027,
        u_tilde: 3000.0,
        alpha_t: 2000.0,
        alpha_n: 2000.0,
        mu_0: None,
    })?;
    // A deterministic generator: splitmix64, and Box–Muller for the noise.
    let mut state = 0x5eed_u64;
    let mut uniform = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let rows = 39;
    let mut specs = Vec::with_capacity(n);
    let mut tests = Vec::with_capacity(n);
    for i in 0..n {
        let p = 50.0 + 150.0 * uniform();
        let v = 0.005 * 10f64.powf(uniform());
        let slip: Vec<f64> = (0..rows)
            .map(|k| {
                let x = k as f64 / (rows - 1) as f64;
                3.0 * (k as f64 + 442.0 * x * x) / 480.0
            })
            .collect();
        let time: Vec<f64> = slip.iter().map(|u| u / v).collect();
        let normal = vec![p; rows];
        let out = simulate(
            &truth,
            &Protocol {
                control: Control::Slip,
                time: &time,
                imposed: &slip,
                normal: &normal,
                initial_slip: 0.0,
                initial: Default::default(),
            },
        )?;
        let sd = 0.003 * out.shear.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let shear: Vec<f64> = out
            .shear
            .iter()
            .map(|s| {
                let (a, b) = (uniform().max(1e-300), uniform());
                s + sd * (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect();
        let name = format!("t{i:05}");
        let spec = TestSpec::new(&name, &format!("{name}.csv"), ControlColumn::Slip, p);
        tests.push(TestData {
            spec: spec.clone(),
            path: dir.join(&spec.file),
            time_s: time,
            slip_mm: slip,
            shear_kpa: shear,
            normal_kpa: normal,
            friction_given: false,
            line_of_row: (2..rows + 2).collect(),
            comments: vec!["generated by subfric bench".into()],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        });
        specs.push(spec);
    }
    let set = ExperimentSet {
        dir: dir.to_path_buf(),
        meta: ExperimentMeta {
            name: "many-short-tests".into(),
            title: format!("{n} generated tests of {rows} rows"),
            source: "subfric bench".into(),
            provenance: Some("generated from Table 1 (medium)'s parameters, 0.3 % noise".into()),
            interface: Default::default(),
            tests: specs,
            reference_parameters: Some(serde_json::to_value(truth.params)?),
            units: None,
            extra: Default::default(),
        },
        tests,
    };
    write_set(&set, dir)?;
    Ok(truth)
}

/// Times `subfric fit` (without writing) on `n` generated tests of 39 rows.
pub fn many_tests_fit(n: usize) -> Result<ManyTestsFit> {
    let dir = TempFolder(std::env::temp_dir().join(format!(
        "subfric-bench-{}-{}",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos())
    )));
    std::fs::create_dir_all(&dir.0)?;
    let truth = many_tests_set(&dir.0, n)?;
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let outcome = run_fit(&request(dir.0.clone()), &Silent)?;
    let (seconds, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - cpu0);
    let fitted = &outcome.report.model.params;
    let worst_recovery = [
        (fitted.mu_s, truth.params.mu_s),
        (fitted.mu_k, truth.params.mu_k),
    ]
    .iter()
    .map(|(a, b)| ((a - b) / b).abs())
    .fold(0.0, f64::max);
    Ok(ManyTestsFit {
        tests: n,
        rows_per_test: 39,
        seconds,
        cpu_seconds: cpu,
        model_runs: outcome.report.optimizer.evaluations,
        worst_recovery,
    })
}

/// Multi-start scaling.
#[derive(Debug, Serialize)]
pub struct MultiStart {
    /// Set used.
    pub set: String,
    /// Seconds on one thread.
    pub one_thread_s: f64,
    /// Seconds on all threads.
    pub all_threads_s: f64,
    /// Threads.
    pub threads: usize,
    /// Speed-up.
    pub speedup: f64,
}

/// The benchmark history: u(t) = 1 mm sin(2π t / 200 s), 10 cycles in 200 000 equal steps.
pub fn step_case() -> (Model, Vec<f64>, Vec<f64>) {
    let model = Model::base(Params::sample()).expect("sample parameters are valid");
    let n = 200_000;
    let dt = 2000.0 / n as f64;
    let time: Vec<f64> = (0..=n).map(|i| i as f64 * dt).collect();
    let slip: Vec<f64> = time
        .iter()
        .map(|t| (2.0 * std::f64::consts::PI * t / 200.0).sin())
        .collect();
    (model, time, slip)
}

/// Steps per second of the 1-D slip-controlled step, and whether it matches `simulate` exactly.
pub fn steps_per_second(repeats: usize) -> (f64, bool) {
    let (model, time, slip) = step_case();
    // The time steps exactly as `simulate` sees them (equal up to rounding).
    let dts: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mut best = f64::MAX;
    let mut shear = vec![0.0; slip.len()];
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        let mut c = Contact1::new(&model);
        let mut s = State1::virgin(&model, 0.0);
        for ((u, out), dt) in slip.iter().zip(shear.iter_mut()).skip(1).zip(&dts) {
            s = match c.step_slip(&s, *u, 100.0, *dt) {
                Ok(n) => n,
                Err(_) => return (0.0, false),
            };
            *out = s.shear;
        }
        best = best.min(t0.elapsed().as_secs_f64());
    }
    let normal = vec![100.0; time.len()];
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let identical = match simulate(&model, &proto) {
        Ok(t) => t
            .shear
            .iter()
            .zip(&shear)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        Err(_) => false,
    };
    ((slip.len() - 1) as f64 / best, identical)
}

fn request(dir: PathBuf) -> FitRequest {
    FitRequest::of_set(dir, FitOptions::default())
}

/// Runs the benchmark's `parts` (every part when empty); the sets of `experiments` are read
/// only by the parts that fit them.
pub fn measure(experiments: &Path, parts: &[BenchPart]) -> Result<BenchReport> {
    measure_with(experiments, parts, &BenchExtras::default())
}

/// [`measure`], then the step against `extras.peer` and the diagnoses of `extras.records`.
pub fn measure_with(
    experiments: &Path,
    parts: &[BenchPart],
    extras: &BenchExtras,
) -> Result<BenchReport> {
    let mut r = measure_parts(experiments, parts)?;
    if let Some(peer) = &extras.peer {
        r.peer = Some(step_against_peer(peer)?);
    }
    if !extras.records.is_empty() {
        r.records = Some(record_diagnoses(&extras.records)?);
    }
    Ok(r)
}

fn measure_parts(experiments: &Path, parts: &[BenchPart]) -> Result<BenchReport> {
    let parts: Vec<BenchPart> = if parts.is_empty() {
        BenchPart::ALL.to_vec()
    } else {
        parts.to_vec()
    };
    let wants = |p: BenchPart| parts.contains(&p);
    let dirs = if parts.iter().any(|p| p.reads_sets()) {
        experiment_sets(experiments)?
    } else {
        Vec::new()
    };
    let mut r = BenchReport {
        step_case: None,
        steps_per_second: None,
        identical_to_simulate: None,
        fit_seconds: None,
        multistart: None,
        diagnoses: None,
        many_tests: None,
        sampler: None,
        peer: None,
        records: None,
    };
    if wants(BenchPart::Step) {
        let (sps, identical) = steps_per_second(10);
        r.step_case = Some("1-D slip control, u = 1 mm sin(2πt/200 s), 10 cycles in 200 000 steps, Params::sample(), 100 kPa".into());
        r.steps_per_second = Some(sps);
        r.identical_to_simulate = Some(identical);
    }
    if wants(BenchPart::Fits) {
        let mut fit_seconds = Vec::new();
        for d in &dirs {
            let t0 = Instant::now();
            run_fit(&request(d.clone()), &Silent)?;
            fit_seconds.push((folder_name(d), t0.elapsed().as_secs_f64()));
        }
        r.fit_seconds = Some(fit_seconds);
    }
    let probe = dirs
        .iter()
        .find(|d| d.ends_with("table4-two-way"))
        .or(dirs.first())
        .cloned();
    if let (true, Some(probe)) = (wants(BenchPart::Multistart), &probe) {
        let time_with = |threads: usize| -> Result<f64> {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()?;
            let t0 = Instant::now();
            pool.install(|| run_fit(&request(probe.clone()), &Silent))?;
            Ok(t0.elapsed().as_secs_f64())
        };
        let threads = rayon::current_num_threads();
        let one = time_with(1)?;
        let all = time_with(threads)?;
        r.multistart = Some(MultiStart {
            set: folder_name(probe),
            one_thread_s: one,
            all_threads_s: all,
            threads,
            speedup: one / all,
        });
    }
    if wants(BenchPart::ManyTests) {
        r.many_tests = Some(many_tests_fit(MANY_TESTS)?);
    }
    if wants(BenchPart::Diagnoses) {
        r.diagnoses = Some(diagnoses()?);
    }
    if let (true, Some(probe)) = (wants(BenchPart::Sampler), &probe) {
        r.sampler = Some(sampler_speed(probe)?);
    }
    Ok(r)
}

/// The experiment sets (folders with an `experiment.json`) of `experiments`, sorted; an error
/// naming the folder when it cannot be read or holds none.
fn experiment_sets(experiments: &Path) -> Result<Vec<PathBuf>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(experiments)
        .map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot read the experiments folder: {e} (expected a folder of experiment sets, --experiments)",
                experiments.display()
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("experiment.json").is_file())
        .collect();
    dirs.sort();
    if dirs.is_empty() {
        bail!("{}: no experiment set found", experiments.display());
    }
    Ok(dirs)
}

fn folder_name(d: &Path) -> String {
    d.file_name()
        .unwrap_or_default()
        .to_string_lossy()
        .to_string()
}

/// Tests of the many-short-tests case (issue 25: 10 000 tests of 39 rows in under 60 s).
pub const MANY_TESTS: usize = 10_000;
