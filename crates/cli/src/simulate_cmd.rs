//! `subfric simulate`: drive the model through every test of a set, or a declarative scenario.

use anyhow::{anyhow, Context, Result};
use std::path::Path;
use subfric_data::{
    load_set, write_set, Control as DataControl, ExperimentMeta, ExperimentSet, Interface,
    TestData, TestSpec,
};
use subfric_fit::prepare_set;
use subfric_model::{simulate, Control, Model, Scenario};

/// Simulates every test of the set in `dir`; writes a set of the same shape under `out`, with
/// the model's output in place of the measured column.
pub fn simulate_set(dir: &Path, model: &Model, out: &Path) -> Result<Vec<String>> {
    let mut set = load_set(dir)?;
    let prepared = prepare_set(&set, false);
    let mut written = Vec::new();
    for (t, p) in set.tests.iter_mut().zip(&prepared) {
        let pred = p.fit.predict(model).map_err(|e| {
            anyhow!(
                "{}: test `{}`: {e} (row numbers count data rows from 0)",
                t.path.display(),
                t.spec.name
            )
        })?;
        match p.fit.control {
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
        written.push(out.join(&t.spec.file).display().to_string());
    }
    set.meta.provenance = Some(format!("simulated by subfric from {}", dir.display()));
    write_set(&set, out)?;
    Ok(written)
}

/// Runs a scenario file; writes a one-test set under `out`.
pub fn simulate_scenario(path: &Path, model: &Model, out: &Path) -> Result<String> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("{}: cannot read the scenario", path.display()))?;
    let sc: Scenario = serde_json::from_str(&text)
        .map_err(|e| anyhow!("{}:{}:{}: {e}", path.display(), e.line(), e.column()))?;
    let rows = sc.rows().map_err(|e| anyhow!("{}: {e}", path.display()))?;
    let proto = subfric_model::Protocol {
        control: sc.control,
        time: &rows.time,
        imposed: &rows.imposed,
        normal: &rows.normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let traj = simulate(model, &proto).map_err(|e| anyhow!("{}: {e}", path.display()))?;
    let control = match sc.control {
        Control::Slip => DataControl::Slip,
        Control::Shear => DataControl::Shear,
    };
    let file = format!("{}.csv", sc.name);
    let spec = TestSpec::new(&sc.name, &file, control, sc.normal_stress_kpa);
    let n = rows.time.len();
    let test = TestData {
        spec: spec.clone(),
        path: out.join(&file),
        time_s: rows.time.clone(),
        slip_mm: traj.slip.clone(),
        shear_kpa: traj.shear.clone(),
        normal_kpa: rows.normal.clone(),
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
    write_set(&set, out)?;
    Ok(out.join(file).display().to_string())
}
