//! `subfric simulate`: drive the model through every test of a set, or a declarative scenario,
//! and write the result as a new set. Never into the set simulated; an existing set in the
//! output folder only with `--force` (see [`crate::folders::output::SetDir`]).

use crate::folders::io::load_model;
use crate::folders::output::SetDir;
use anyhow::{anyhow, Result};
use std::path::{Path, PathBuf};
use subfric_data::import::file_name_for;
use subfric_data::{
    load_set, write_set, ControlColumn, ExperimentMeta, ExperimentSet, Interface, PathKind,
    TestData, TestSpec, EXPERIMENT_JSON,
};
use subfric_model::{Control, Model, Scenario};
use subfric_reading::prepare_set;

/// What to simulate.
#[derive(Clone, Debug)]
pub enum SimulateSource {
    /// Every test of the set in this folder.
    Set(PathBuf),
    /// A declarative scenario file, refused beyond `max_rows` rows.
    Scenario {
        /// The scenario's JSON file.
        file: PathBuf,
        /// Most rows it may generate.
        max_rows: usize,
    },
}

/// A simulation: the model's parameter file, what to simulate, where the new set goes.
#[derive(Clone, Debug)]
pub struct SimulateRequest {
    /// params.json, a fit.json, or an experiment.json with reference_parameters.
    pub params: PathBuf,
    /// What to simulate.
    pub source: SimulateSource,
    /// Folder of the new set (never the set simulated).
    pub out: PathBuf,
    /// Replace a set already in `out` (its old CSVs are removed).
    pub force: bool,
}

/// The new set written.
pub struct Simulated {
    /// Its files: the CSVs and experiment.json.
    pub files: Vec<PathBuf>,
    /// CSVs of the set replaced by `force` that the new one does not overwrite, removed.
    pub removed: Vec<PathBuf>,
}

/// `subfric simulate`.
pub fn simulate(req: &SimulateRequest) -> Result<Simulated> {
    let model = load_model(&req.params)?;
    match &req.source {
        SimulateSource::Set(dir) => simulate_set(dir, &model, &req.out, req.force),
        SimulateSource::Scenario { file, max_rows } => {
            simulate_scenario(file, &model, &req.out, req.force, *max_rows)
        }
    }
}

/// The output folder's file names for a set: its CSVs and experiment.json.
fn set_files(tests: &[TestSpec]) -> Vec<String> {
    let mut files: Vec<String> = tests.iter().map(|t| t.file.clone()).collect();
    files.push(EXPERIMENT_JSON.to_string());
    files
}

/// Writes `set` into the claimed folder; the files written and the old CSVs removed.
fn write_claimed(set: &ExperimentSet, claim: SetDir) -> Result<Simulated> {
    write_set(set, claim.path())?;
    let out = claim.path().to_path_buf();
    let removed = claim.commit();
    let mut files: Vec<PathBuf> = set.tests.iter().map(|t| out.join(&t.spec.file)).collect();
    files.push(out.join(EXPERIMENT_JSON));
    Ok(Simulated { files, removed })
}

/// Simulates every test of the set in `dir`; writes a set of the same shape under `out`, with
/// the model's output in place of the measured column.
pub fn simulate_set(dir: &Path, model: &Model, out: &Path, force: bool) -> Result<Simulated> {
    let mut set = load_set(dir)?;
    let claim = SetDir::claim(out, Some(dir), &set_files(&set.meta.tests), force)?;
    let prepared = prepare_set(&set, false);
    for (t, p) in set.tests.iter_mut().zip(&prepared) {
        // A seating toe is left out of what the model simulates (the test starts at rest after
        // it): the simulated test leaves out its rows too, and says so, so that every column
        // keeps one value per row.
        let toe_note = p.toe.as_ref().map(|toe| {
            *t = t.rows_from(toe.first_kept);
            // The rows over which the rest of a gap closed are left out too; the slip column
            // stays the record's.
            if let Some(g) = &toe.remainder {
                *t = subfric_reading::without_gap_rows(t, g);
            }
            format!(
                "; the record's first {} rows (a seating toe over {:.3} mm) are left out: the model starts at rest under {:.2} kPa after them{}",
                toe.first_kept,
                toe.travel_mm,
                toe.start_shear_kpa,
                toe.remainder.as_ref().map_or(String::new(), |g| format!(
                    "; the {} rows over which the rest of the gap ({:.4} mm) closed on the first reload the same way are left out, and the model's travel after them is shorter by that much (the slip column is the record's)",
                    g.to_row - g.from_row - 1,
                    g.travel_mm
                ))
            )
        });
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
        ) + toe_note.as_deref().unwrap_or("")];
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
) -> Result<Simulated> {
    let kind = PathKind::of(path);
    if kind != PathKind::File {
        anyhow::bail!(
            "{}: the scenario {} (expected a JSON file)",
            path.display(),
            kind.describe()
        );
    }
    let text = crate::folders::io::read_settings_text(path, "the scenario")?;
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
    let traj =
        subfric_model::simulate(model, &proto).map_err(|e| anyhow!("{}: {e}", path.display()))?;
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
        reading_notes: Vec::new(),
        channels: Vec::new(),
    };
    let meta = ExperimentMeta {
        name: sc.name.clone(),
        title: format!("scenario {}", sc.name),
        source: path.display().to_string(),
        provenance: Some("simulated by subfric from a declarative scenario".into()),
        interface: Interface::default(),
        tests: vec![spec],
        reference_parameters: Some(serde_json::to_value(model.params)?),
        units: None,
        extra: Default::default(),
    };
    let set = ExperimentSet {
        dir: out.to_path_buf(),
        meta,
        tests: vec![test],
    };
    write_claimed(&set, claim)
}
