//! The campaign functions of `subfric._native` (wrapped by `python/subfric/campaign.py`): a
//! local run, and the three steps the Dask path maps over its workers (the plan written, set N
//! run, the table collected), each the application layer's own, so that every way writes the
//! same per-set files and the same table. Results cross as JSON text.

use crate::{error, fail};
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use std::path::PathBuf;
use subfric_app::campaign::{self, CampaignRequest, CampaignSource, SetOptions};
use subfric_app::Silent;

/// A folder of sets or a manifest (a path), or set folders (a list of paths).
fn source(sets: &Bound<'_, PyAny>) -> PyResult<CampaignSource> {
    if sets.is_instance_of::<PyList>() || sets.is_instance_of::<PyTuple>() {
        let dirs: Vec<PathBuf> = sets.extract().map_err(|_| {
            fail("sets: a list holding something else than paths (expected set folders)")
        })?;
        return Ok(CampaignSource::Sets(dirs));
    }
    let path: PathBuf = sets.extract().map_err(|_| {
        fail("sets: expected a folder of sets, a manifest file, or a list of set folders")
    })?;
    CampaignSource::of(&path).map_err(error)
}

#[allow(clippy::too_many_arguments)]
fn request(
    sets: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    seed: u64,
    starts: usize,
    global_evals: usize,
    profiles: bool,
    diagnose: bool,
    force: bool,
) -> PyResult<CampaignRequest> {
    if starts == 0 {
        return Err(fail("starts: 0 (expected at least one local start)"));
    }
    Ok(CampaignRequest {
        source: source(sets)?,
        out,
        defaults: SetOptions {
            seed,
            starts,
            global_evals,
            profiles,
            diagnose,
            ..SetOptions::default()
        },
        force,
    })
}

fn json<T: serde::Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| error(e.into()))
}

/// The campaign folder, absolute (workers elsewhere resolve it alike).
fn absolute(p: PathBuf) -> PyResult<String> {
    std::path::absolute(&p)
        .map(|a| a.display().to_string())
        .map_err(|e| fail(format!("{}: {e}", p.display())))
}

/// `subfric campaign`: every set run here (in parallel), the table and figures written.
/// Returns {"out", "runs", "rows", "files"} as JSON.
#[pyfunction]
#[pyo3(signature = (sets, *, out, seed, starts, global_evals, profiles, diagnose, force, jobs, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn campaign_run(
    py: Python<'_>,
    sets: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    seed: u64,
    starts: usize,
    global_evals: usize,
    profiles: bool,
    diagnose: bool,
    force: bool,
    jobs: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<String> {
    let progress = crate::progress::Callback::of(py, progress)?;
    let req = request(
        sets,
        out,
        seed,
        starts,
        global_evals,
        profiles,
        diagnose,
        force,
    )?;
    let f = py.detach(|| match &progress {
        Some(p) => campaign::run(&req, jobs, &|_| {}, &crate::progress::SetsOnly(p)),
        None => campaign::run(&req, jobs, &|_| {}, &Silent),
    });
    progress.map_or(Ok(()), crate::progress::Callback::finish)?;
    let f = f.map_err(error)?;
    json(&serde_json::json!({
        "out": absolute(f.collected.out.clone())?,
        "runs": f.runs,
        "rows": f.collected.rows,
        "files": f.collected.files,
    }))
}

/// The plan written into the campaign folder (claimed, then committed): {"out", "sets": [ids]}.
#[pyfunction]
#[pyo3(signature = (sets, *, out, seed, starts, global_evals, profiles, diagnose, force))]
#[allow(clippy::too_many_arguments)]
pub fn campaign_prepare(
    py: Python<'_>,
    sets: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    seed: u64,
    starts: usize,
    global_evals: usize,
    profiles: bool,
    diagnose: bool,
    force: bool,
) -> PyResult<String> {
    let req = request(
        sets,
        out,
        seed,
        starts,
        global_evals,
        profiles,
        diagnose,
        force,
    )?;
    let p = py.detach(|| campaign::prepare(&req)).map_err(error)?;
    let ids: Vec<&str> = p.plan.sets.iter().map(|s| s.id.as_str()).collect();
    json(&serde_json::json!({"out": absolute(p.out.clone())?, "sets": ids, "notes": p.notes}))
}

/// Set `index` of the plan in the campaign folder `out` run (a Dask task): the run as JSON
/// (a failed set is an outcome, not an exception).
#[pyfunction]
#[pyo3(signature = (out, index, *, force))]
pub fn campaign_run_index(
    py: Python<'_>,
    out: PathBuf,
    index: usize,
    force: bool,
) -> PyResult<String> {
    let r = py
        .detach(|| campaign::run_index(None, &out, index, force, &Silent))
        .map_err(error)?;
    json(&r)
}

/// The table and figures from the per-set folders: {"out", "rows", "files"}.
#[pyfunction]
#[pyo3(signature = (sets, *, out, seed, starts, global_evals, profiles, diagnose, force))]
#[allow(clippy::too_many_arguments)]
pub fn campaign_collect(
    py: Python<'_>,
    sets: &Bound<'_, PyAny>,
    out: Option<PathBuf>,
    seed: u64,
    starts: usize,
    global_evals: usize,
    profiles: bool,
    diagnose: bool,
    force: bool,
) -> PyResult<String> {
    let req = request(
        sets,
        out,
        seed,
        starts,
        global_evals,
        profiles,
        diagnose,
        force,
    )?;
    let c = py.detach(|| campaign::collect(&req)).map_err(error)?;
    json(&serde_json::json!({
        "out": absolute(c.out.clone())?,
        "rows": c.rows,
        "files": c.files,
    }))
}

/// Adds the campaign functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(campaign_run, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_prepare, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_run_index, m)?)?;
    m.add_function(wrap_pyfunction!(campaign_collect, m)?)?;
    Ok(())
}
