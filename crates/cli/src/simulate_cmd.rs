//! `subfric simulate`: drive the model through every test of a set, or a declarative scenario,
//! and write the result as a new set. Never into the set simulated; an existing set in the
//! output folder only with `--force` (see [`crate::output::SetDir`]).

use crate::args::SimulateArgs;
use crate::output::SetDir;
use anyhow::{anyhow, Context, Result};
use std::path::{Path, PathBuf};
use subfric_data::import::file_name_for;
use subfric_data::{
    load_set, write_set, ControlColumn, ExperimentMeta, ExperimentSet, Interface, PathKind,
    TestData, TestSpec, EXPERIMENT_JSON,
};
use subfric_fit::prepare_set;
use subfric_model::{simulate, Control, Model, Scenario};

/// `subfric simulate`.
pub fn run(args: SimulateArgs) -> Result<()> {
    let model = crate::io::load_model(&args.params)?;
    let written = match (&args.set, &args.scenario) {
        (Some(dir), None) => simulate_set(dir, &model, &args.out, args.force)?,
        (None, Some(sc)) => simulate_scenario(sc, &model, &args.out, args.force, args.max_rows)?,
        // clap refuses both and neither; kept for callers that build the arguments themselves.
        _ => anyhow::bail!("give either a set folder or --scenario <file> (expected exactly one)"),
    };
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// The output folder's file names for a set: its CSVs and experiment.json.
fn set_files(tests: &[TestSpec]) -> Vec<String> {
    let mut files: Vec<String> = tests.iter().map(|t| t.file.clone()).collect();
    files.push(EXPERIMENT_JSON.to_string());
    files
}

/// Writes `set` into the claimed folder; reports old CSVs removed.
fn write_claimed(set: &ExperimentSet, claim: SetDir) -> Result<Vec<PathBuf>> {
    write_set(set, claim.path())?;
    let out = claim.path().to_path_buf();
    for f in claim.commit() {
        eprintln!(
            "note: removed {} (a test of the set replaced by --force)",
            f.display()
        );
    }
    let mut written: Vec<PathBuf> = set.tests.iter().map(|t| out.join(&t.spec.file)).collect();
    written.push(out.join(EXPERIMENT_JSON));
    Ok(written)
}

/// Simulates every test of the set in `dir`; writes a set of the same shape under `out`, with
/// the model's output in place of the measured column. Returns the files written.
pub fn simulate_set(dir: &Path, model: &Model, out: &Path, force: bool) -> Result<Vec<PathBuf>> {
    let mut set = load_set(dir)?;
    let claim = SetDir::claim(out, Some(dir), &set_files(&set.meta.tests), force)?;
    let prepared = prepare_set(&set, false);
    for (t, p) in set.tests.iter_mut().zip(&prepared) {
        let pred = p.full.predict(model).map_err(|e| {
            anyhow!(
                "{}: test `{}`: {e} (row numbers count data rows from 0)",
                t.path.display(),
                t.spec.name
            )
        })?;
        match p.full.control {
            Control::Slip => t.shear_kpa = pred,
            Control::Shear => t.slip_mm = pred,
        }
        t.friction_given = false;
        t.comments = vec![format!(
            "simulated by subfric {} from {} with mu_s={} mu_k={} kappa={} xi={} u_tilde={} alpha_t={}",
            env!("CARGO_PKG_VERSION"),
            t.path.display(),
            model.params.mu_s,
            model.params.mu_k,
            model.params.kappa,
            model.params.xi,
            model.params.u_tilde,
            model.params.alpha_t
        )];
    }
    set.meta.provenance = Some(format!("simulated by subfric from {}", dir.display()));
    write_claimed(&set, claim)
}

/// Runs a scenario file; writes a one-test set under `out`. A scenario of more than
/// `max_rows` rows is refused before any row is generated.
pub fn simulate_scenario(
    path: &Path,
    model: &Model,
    out: &Path,
    force: bool,
    max_rows: usize,
) -> Result<Vec<PathBuf>> {
    let kind = PathKind::of(path);
    if kind != PathKind::File {
        anyhow::bail!(
            "{}: the scenario {} (expected a JSON file)",
            path.display(),
            kind.describe()
        );
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the scenario", path.display()))?;
    let sc: Scenario = serde_json::from_str(&text)
        .map_err(|e| anyhow!("{}:{}:{}: {e}", path.display(), e.line(), e.column()))?;
    let rows = sc.rows_with_limit(max_rows).map_err(|e| {
        anyhow!(
            "{}: {e}{}",
            path.display(),
            if e.message.contains("limit") {
                " (--max-rows raises the limit)"
            } else {
                ""
            }
        )
    })?;
    let control = match sc.control {
        Control::Slip => ControlColumn::Slip,
        Control::Shear => ControlColumn::Shear,
    };
    let file = file_name_for(&sc.name);
    let spec = TestSpec::new(&sc.name, &file, control, sc.normal_stress_kpa);
    let claim = SetDir::claim(out, None, &set_files(std::slice::from_ref(&spec)), force)?;
    let proto = subfric_model::Protocol {
        control: sc.control,
        time: &rows.time,
        imposed: &rows.imposed,
        normal: &rows.normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let traj = simulate(model, &proto).map_err(|e| anyhow!("{}: {e}", path.display()))?;
    let n = rows.time.len();
    let test = TestData {
        spec: spec.clone(),
        path: out.join(&file),
        time_s: rows.time,
        slip_mm: traj.slip,
        shear_kpa: traj.shear,
        normal_kpa: rows.normal,
        friction_given: false,
        line_of_row: (2..n + 2).collect(),
        comments: vec![format!("scenario {} simulated by subfric", path.display())],
    };
    let meta = ExperimentMeta {
        name: sc.name.clone(),
        title: format!("scenario {}", sc.name),
        source: path.display().to_string(),
        provenance: Some("simulated by subfric from a declarative scenario".into()),
        interface: Interface::default(),
        tests: vec![spec],
        reference_parameters: Some(serde_json::to_value(model.params)?),
        extra: Default::default(),
    };
    let set = ExperimentSet {
        dir: out.to_path_buf(),
        meta,
        tests: vec![test],
    };
    write_claimed(&set, claim)
}
