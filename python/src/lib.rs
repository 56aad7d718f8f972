//! `subfric._native`: the extension module behind the Python package `subfric`
//! (`python/subfric/__init__.py` wraps these functions, normalises their arguments and documents
//! them). Everything here calls the library crates — the same loader, simulator, calibration and
//! diagnosis as the `subfric` command (through its application layer, `subfric_app`) — and
//! converts at the border:
//! NumPy arrays in and out, JSON text for the results that the command writes as JSON files
//! (so that the Python dicts hold exactly what `json.load` gives for those files). Errors become
//! `subfric.SubfricError` with the command's located message; the long calls run with the GIL
//! released.

mod campaign;
mod progress;

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString, PyTuple};
use std::path::PathBuf;
use subfric_app::flags::{parse_bound, parse_fix, parse_param};
use subfric_app::posterior::{PosteriorRequest, ResidualModel};
use subfric_app::{self as api, FitRequest, Silent};
use subfric_data::{load_set as load_set_rs, plausibility, InitialSpec};
use subfric_diagnose::DiagnoseOptions;
use subfric_fit::{FitOptions, Method, Param};
use subfric_model::{simulate as simulate_rs, Control, Initial, Model, Protocol, Trajectory};
use subfric_reading::{control_of, FitTest};

create_exception!(
    subfric,
    SubfricError,
    PyException,
    "An error of subfric: bad input (the message names the file, the line and the field, and what was expected), an impossible parameter, or a result withheld because it cannot be trusted."
);

/// The error as the command prints it (each cause once), raised as `SubfricError`.
fn error(e: anyhow::Error) -> PyErr {
    SubfricError::new_err(subfric_app::error_text(&e))
}

fn fail(message: impl Into<String>) -> PyErr {
    SubfricError::new_err(message.into())
}

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, v)
}

fn column(a: &PyReadonlyArray1<'_, f64>, name: &str) -> PyResult<Vec<f64>> {
    a.as_slice()
        .map(<[f64]>::to_vec)
        .map_err(|e| fail(format!("{name}: {e} (expected a contiguous 1-D array)")))
}

/// A JSON value from a Python value made of dicts (str keys), lists, tuples, str, bool, int,
/// float and None. Numbers are taken as the doubles they are (no decimal text in between, so
/// parameters reach the model bit for bit); `what` names the value in messages.
fn json_of(v: &Bound<'_, PyAny>, what: &str) -> PyResult<serde_json::Value> {
    use serde_json::Value;
    if v.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut m = serde_json::Map::new();
        for (k, x) in d.iter() {
            let k: String = k
                .extract()
                .map_err(|_| fail(format!("{what}: a key {k} (expected str keys)")))?;
            let x = json_of(&x, &format!("{what}[{k:?}]"))?;
            m.insert(k, x);
        }
        return Ok(Value::Object(m));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(i, x)| json_of(&x?, &format!("{what}[{i}]")))
            .collect::<PyResult<_>>()?;
        return Ok(Value::Array(items));
    }
    if v.is_instance_of::<PyFloat>() || v.hasattr("__float__")? && !v.hasattr("__index__")? {
        let x: f64 = v.extract()?;
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| fail(format!("{what}: {x} (expected a finite number)")));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(Value::from(i));
    }
    if let Ok(i) = v.extract::<u64>() {
        return Ok(Value::from(i));
    }
    Err(fail(format!(
        "{what}: a {} (expected a number, a string, a dict or a list)",
        v.get_type().name()?
    )))
}

/// The model from a dict as `params.json`, a fit.json or an experiment.json hold (see
/// `subfric_model::model_from_value`), or from such a file, read as `subfric simulate --params`
/// reads it.
fn model_of(params: &Bound<'_, PyAny>) -> PyResult<Model> {
    if params.is_instance_of::<PyDict>() {
        let v = json_of(params, "params")?;
        return subfric_model::model_from_value(&v).map_err(|e| fail(format!("params: {e}")));
    }
    match params.extract::<PathBuf>() {
        Ok(path) => api::load_model(&path).map_err(error),
        Err(_) => Err(PyTypeError::new_err(format!(
            "params: a {} (expected a dict of parameters or the path of a JSON file)",
            params.get_type().name()?
        ))),
    }
}

fn control_from(s: &str) -> PyResult<Control> {
    s.parse::<subfric_data::ControlColumn>()
        .map(control_of)
        .map_err(|e| fail(format!("control: {e}")))
}

/// The predicted column, μ and r.
type Simulated<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// Simulates one test: the model's response to an imposed slip or shear history.
#[pyfunction]
#[pyo3(signature = (params, time, imposed, normal, control, *, initial=None, initial_slip=0.0))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    params: &Bound<'py, PyAny>,
    time: PyReadonlyArray1<'py, f64>,
    imposed: PyReadonlyArray1<'py, f64>,
    normal: PyReadonlyArray1<'py, f64>,
    control: &str,
    initial: Option<&Bound<'py, PyAny>>,
    initial_slip: f64,
) -> PyResult<Simulated<'py>> {
    let model = model_of(params)?;
    let control = control_from(control)?;
    let initial: Initial = match initial {
        None => Initial::Rest,
        Some(v) if v.is_none() => Initial::Rest,
        Some(v) if v.extract::<String>().is_ok_and(|s| s == "rest") => Initial::Rest,
        Some(v) => serde_json::from_value(json_of(v, "initial")?).map_err(|e| {
            fail(format!(
                "initial: {e} (expected None, \"rest\", {{\"kind\": \"loaded\", \"shear_kpa\": …}} or {{\"kind\": \"sliding\", \"shear_kpa\": …, \"rate_mm_s\": …}})"
            ))
        })?,
    };
    let (t, x, n) = (
        column(&time, "time")?,
        column(&imposed, "imposed")?,
        column(&normal, "normal")?,
    );
    let run = py.detach(move || {
        let proto = Protocol {
            control,
            time: &t,
            imposed: &x,
            normal: &n,
            initial_slip,
            initial,
        };
        // A start given by hand must be one the model can hold (within its capacity, finite,
        // a rate >= 0): the model's own check, the one every caller shares.
        subfric_model::check_start(&model, &proto)?;
        simulate_rs(&model, &proto)
    });
    let traj: Trajectory = run.map_err(|e| fail(format!("simulate: {e}")))?;
    let predicted = traj.predicted(control).to_vec();
    Ok((array(py, predicted), array(py, traj.mu), array(py, traj.r)))
}

/// Loads and validates a set folder: a dict of its description (as JSON text), its tests with
/// their columns as arrays, and its plausibility warnings.
#[pyfunction]
fn load_set<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let set = py
        .detach(|| load_set_rs(&path))
        .map_err(|e| error(e.into()))?;
    let out = PyDict::new(py);
    out.set_item("path", set.dir.display().to_string())?;
    let meta = serde_json::to_string(&set.meta).map_err(|e| error(e.into()))?;
    out.set_item("meta_json", meta)?;
    let warnings: Vec<String> = plausibility(&set).iter().map(|w| w.to_string()).collect();
    out.set_item("warnings", warnings)?;
    let tests = PyList::empty(py);
    for t in set.tests {
        let d = PyDict::new(py);
        d.set_item("name", &t.spec.name)?;
        d.set_item("file", &t.spec.file)?;
        d.set_item("path", t.path.display().to_string())?;
        d.set_item("control", t.spec.control.name())?;
        d.set_item("normal_stress_kpa", t.spec.normal_stress_kpa)?;
        d.set_item(
            "initial",
            t.spec.initial.map(|i| match i {
                InitialSpec::Rest => "rest",
                InitialSpec::Sliding => "sliding",
            }),
        )?;
        d.set_item("friction_given", t.friction_given)?;
        // The units the CSV's columns were written in, as the set declares them; the arrays
        // below are in kPa, mm and s whatever they were.
        match &t.spec.units {
            Some(u) => {
                let units = PyDict::new(py);
                units.set_item("stress", u.stress.clone())?;
                units.set_item("displacement", u.displacement.clone())?;
                units.set_item("time", u.time.clone())?;
                d.set_item("units", units)?;
            }
            None => d.set_item("units", py.None())?,
        }
        d.set_item("comments", t.comments)?;
        d.set_item("time_s", array(py, t.time_s))?;
        d.set_item("slip_mm", array(py, t.slip_mm))?;
        d.set_item("shear_kpa", array(py, t.shear_kpa))?;
        d.set_item("normal_kpa", array(py, t.normal_kpa))?;
        // The further channels the CSV carried (dilation, temperature, forces, area), by name;
        // NaN where the logger missed a sample.
        let channels = PyDict::new(py);
        for c in t.channels {
            channels.set_item(c.name, array(py, c.values))?;
        }
        d.set_item("channels", channels)?;
        tests.append(d)?;
    }
    out.set_item("tests", tests)?;
    Ok(out)
}

fn method_of(s: &str) -> PyResult<Method> {
    match s.trim().to_ascii_lowercase().as_str() {
        "lsq" | "lm" => Ok(Method::Lsq),
        "nm" | "nelder-mead" => Ok(Method::NelderMead),
        other => Err(fail(format!(
            "method: unknown method `{other}` (expected `lsq` (Levenberg–Marquardt) or `nm` (Nelder–Mead))"
        ))),
    }
}

/// Refuses a weight that is not a finite positive number (as the command line does).
fn check_weights(weights: &[(String, f64)]) -> PyResult<()> {
    for (name, w) in weights {
        if !(w.is_finite() && *w > 0.0) {
            return Err(fail(format!(
                "weights: {name}: weight {w} is not a finite positive number (expected a weight > 0)"
            )));
        }
    }
    Ok(())
}

/// One test of a fit for Python: its columns, the fitted curve, μ and r, and how the fit
/// started the model.
fn curve_dict<'py>(py: Python<'py>, t: FitTest, traj: Trajectory) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let control = match t.control {
        Control::Slip => "slip",
        Control::Shear => "shear",
    };
    d.set_item("control", control)?;
    d.set_item("fitted", array(py, traj.predicted(t.control).to_vec()))?;
    d.set_item("time_s", array(py, t.time))?;
    d.set_item("imposed", array(py, t.imposed))?;
    d.set_item("measured", array(py, t.measured))?;
    d.set_item("normal_kpa", array(py, t.normal))?;
    d.set_item("mu", array(py, traj.mu))?;
    d.set_item("r", array(py, traj.r))?;
    // How the fit started the model (what `simulate` needs to reproduce `fitted`).
    d.set_item("initial", initial_dict(py, t.initial)?)?;
    d.set_item("initial_slip", t.initial_slip)?;
    Ok(d)
}

/// The initial state as `simulate` takes it: {"kind": ..., "shear_kpa": ..., "rate_mm_s": ...}.
fn initial_dict(py: Python<'_>, initial: Initial) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    match initial {
        Initial::Rest => d.set_item("kind", "rest")?,
        Initial::Loaded { shear_kpa } => {
            d.set_item("kind", "loaded")?;
            d.set_item("shear_kpa", shear_kpa)?;
        }
        Initial::Sliding {
            shear_kpa,
            rate_mm_s,
        } => {
            d.set_item("kind", "sliding")?;
            d.set_item("shear_kpa", shear_kpa)?;
            d.set_item("rate_mm_s", rate_mm_s)?;
        }
    }
    Ok(d)
}

fn residuals_of(s: &str) -> PyResult<ResidualModel> {
    match s.trim().to_ascii_lowercase().as_str() {
        "correlated" | "autocorrelated" => Ok(ResidualModel::Autocorrelated),
        "independent" => Ok(ResidualModel::Independent),
        other => Err(fail(format!(
            "residuals: unknown residual model `{other}` (expected `correlated` or `independent`)"
        ))),
    }
}

/// The posterior's thinned chain as arrays: `step`, `walker` and one array per parameter key
/// (the columns of posterior-chain.csv).
fn chain_dict<'py>(py: Python<'py>, p: &api::posterior::Posterior) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("step", ints(py, &p.chain.step))?;
    d.set_item("walker", ints(py, &p.chain.walker))?;
    for (k, param) in p.parameters.iter().enumerate() {
        d.set_item(param.key(), array(py, p.chain.column(k)))?;
    }
    Ok(d)
}

fn ints<'py>(py: Python<'py>, v: &[usize]) -> Bound<'py, PyArray1<i64>> {
    PyArray1::from_vec(py, v.iter().map(|&i| i as i64).collect())
}

/// What a sampled posterior adds beside the fit: `chain` (as [`chain_dict`]), `log_density`
/// (per sample of the chain), and the posterior predictive sample — `predictive_samples` (the
/// chain's samples drawn) and `predictive` (per test, the draws' measured columns with the noise
/// added, draw after draw, flattened; NaN for a draw the model could not simulate).
fn sampled_dict<'py>(
    py: Python<'py>,
    p: &api::posterior::Posterior,
    predictive: &api::posterior::PredictiveDraws,
    tests: &[(String, usize)],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("chain", chain_dict(py, p)?)?;
    d.set_item("log_density", array(py, p.chain.log_density.clone()))?;
    d.set_item("predictive_samples", ints(py, &predictive.samples))?;
    let per_test = PyDict::new(py);
    for (t, (name, rows)) in tests.iter().enumerate() {
        let flat: Vec<f64> = predictive
            .curves
            .iter()
            .flat_map(|c| match &c[t] {
                Some(curve) => curve.clone(),
                None => vec![f64::NAN; *rows],
            })
            .collect();
        per_test.set_item(name, array(py, flat))?;
    }
    d.set_item("predictive", per_test)?;
    Ok(d)
}

/// What `fit` returns: the text of fit.json, the curves per test, the warnings, and what the
/// posterior adds when sampled ([`sampled_dict`]).
type FitResult<'py> = (
    String,
    Bound<'py, PyDict>,
    Vec<String>,
    Option<Bound<'py, PyDict>>,
);

/// Calibrates one set, or several jointly, as `subfric fit` does (with `posterior`, as `subfric
/// fit --posterior`). Returns the text of the fit.json it would write, the fitted curves per
/// test (arrays; with the posterior's 95 % band), the plausibility warnings, and the
/// posterior's thinned chain, densities and predictive sample (arrays) when sampled.
#[pyfunction]
#[pyo3(signature = (dirs, *, tests, free, fix, bounds, weights, method, starts, seed, global_evals, profiles, posterior=false, priors=None, max_evals=None, residuals="correlated", progress=None))]
#[allow(clippy::too_many_arguments)]
fn fit<'py>(
    py: Python<'py>,
    dirs: Vec<PathBuf>,
    tests: Vec<String>,
    free: Option<Vec<String>>,
    fix: Vec<(String, f64)>,
    bounds: Vec<(String, f64, f64)>,
    weights: Vec<(String, f64)>,
    method: &str,
    starts: usize,
    seed: u64,
    global_evals: usize,
    profiles: bool,
    posterior: bool,
    priors: Option<PathBuf>,
    max_evals: Option<usize>,
    residuals: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<FitResult<'py>> {
    let progress = progress::Callback::of(py, progress)?;
    // The command line's own parsers, so that a value is refused with the same reason.
    let free_given = free.is_some();
    let free: Vec<Param> = match free {
        None => Param::BASE.to_vec(),
        Some(keys) => keys
            .iter()
            .map(|k| parse_param(k).map_err(|e| fail(format!("free: {e}"))))
            .collect::<PyResult<_>>()?,
    };
    let fix: Vec<(Param, f64)> = fix
        .iter()
        .map(|(k, v)| parse_fix(&format!("{k}={v}")).map_err(|e| fail(format!("fix: {e}"))))
        .collect::<PyResult<_>>()?;
    let bounds: Vec<(Param, f64, f64)> = bounds
        .iter()
        .map(|(k, lo, hi)| {
            parse_bound(&format!("{k}={lo}:{hi}")).map_err(|e| fail(format!("bounds: {e}")))
        })
        .collect::<PyResult<_>>()?;
    check_weights(&weights)?;
    // What the command line refuses as contradicting options (`--free xi --fix xi=0.1`).
    subfric_app::flags::conflicts(free_given.then_some(&free[..]), &fix, &bounds, &weights)
        .map_err(fail)?;
    let residuals = residuals_of(residuals)?;
    if !posterior {
        let given: Vec<&str> = [
            ("priors", priors.is_some()),
            ("max_evals", max_evals.is_some()),
            ("residuals", residuals != ResidualModel::default()),
        ]
        .iter()
        .filter(|(_, g)| *g)
        .map(|(n, _)| *n)
        .collect();
        if !given.is_empty() {
            return Err(fail(format!(
                "{}: options of the posterior given without posterior=True (expected posterior=True, or none of them)",
                given.join(", ")
            )));
        }
    }
    let posterior = posterior.then(|| PosteriorRequest {
        priors,
        max_evals: max_evals.unwrap_or(api::posterior::DEFAULT_MAX_EVALS),
        residuals,
        seed,
    });
    let req = FitRequest {
        dirs,
        tests,
        free,
        fix,
        bounds,
        weights,
        posterior,
        options: FitOptions {
            method: method_of(method)?,
            starts,
            seed,
            global_evaluations: global_evals,
            profiles,
            ..FitOptions::default()
        },
        start: None,
    };
    let run = py.detach(|| -> anyhow::Result<_> {
        let fitted = api::fit(&req, shown(&progress))?;
        let model = fitted.outcome.report.model;
        let mut curves = Vec::new();
        for t in &fitted.outcome.tests {
            let traj = simulate_rs(&model, &t.full.protocol())
                .map_err(|e| anyhow::anyhow!("test `{}`: {e}", t.fit.name))?;
            curves.push((t.fit.name.clone(), t.full.clone(), traj));
        }
        let text = serde_json::to_string(&fitted.json)?;
        let warnings: Vec<String> = fitted.warnings.iter().map(|w| w.to_string()).collect();
        // The posterior predictive sample over every row: what new measurements would read
        // (the model curve of each draw plus the noise), as ArviZ's posterior_predictive holds.
        let predictive = fitted.posterior.as_ref().map(|s| {
            let fulls: Vec<FitTest> = fitted
                .outcome
                .tests
                .iter()
                .map(|t| t.full.clone())
                .collect();
            let opts = api::posterior::BandOptions {
                noise: true,
                ..Default::default()
            };
            s.posterior.predictive_draws(&fulls, &opts)
        });
        Ok((text, curves, warnings, fitted.posterior, predictive))
    });
    progress.map_or(Ok(()), progress::Callback::finish)?;
    let (text, curves, warnings, sampled, predictive) = run.map_err(error)?;
    let rows: Vec<(String, usize)> = curves
        .iter()
        .map(|(name, t, _)| (name.clone(), t.len()))
        .collect();
    let out = PyDict::new(py);
    for (k, (name, t, traj)) in curves.into_iter().enumerate() {
        let d = curve_dict(py, t, traj)?;
        if let Some(band) = sampled.as_ref().and_then(|s| s.bands.get(k)) {
            d.set_item("band_lo", array(py, band.lo.clone()))?;
            d.set_item("band_median", array(py, band.median.clone()))?;
            d.set_item("band_hi", array(py, band.hi.clone()))?;
        }
        out.set_item(name, d)?;
    }
    let sampled = match (&sampled, &predictive) {
        (Some(s), Some(p)) => Some(sampled_dict(py, &s.posterior, p, &rows)?),
        _ => None,
    };
    Ok((text, out, warnings, sampled))
}

/// Diagnoses a set as `subfric diagnose` does. Returns the text of the diagnosis.json it would
/// write and the plausibility warnings.
#[pyfunction]
#[pyo3(signature = (dir, *, seed, replicates, progress=None))]
fn diagnose(
    py: Python<'_>,
    dir: PathBuf,
    seed: u64,
    replicates: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<(String, Vec<String>)> {
    let progress = progress::Callback::of(py, progress)?;
    let opts = DiagnoseOptions {
        seed,
        ..DiagnoseOptions::default()
    };
    let run = py.detach(|| -> anyhow::Result<_> {
        let d = api::diagnose::diagnose_replicated(&dir, &opts, replicates, shown(&progress))?;
        let text = serde_json::to_string(&d.json)?;
        Ok((text, d.warnings.iter().map(|w| w.to_string()).collect()))
    });
    progress.map_or(Ok(()), progress::Callback::finish)?;
    run.map_err(error)
}

/// Where a long call reports its progress: the caller's callable, or nowhere.
fn shown(progress: &Option<progress::Callback>) -> &dyn api::progress::Progress {
    match progress {
        Some(p) => p,
        None => &Silent,
    }
}

/// `subfric check`: the set's summary (as JSON text, the command's text beside it), the rig
/// artifacts recognised and the plausibility and reading warnings.
#[pyfunction]
fn check(py: Python<'_>, dir: PathBuf) -> PyResult<(String, String, Vec<String>)> {
    let run = py.detach(move || -> anyhow::Result<_> {
        let c = api::sets::check(&dir)?;
        let json = serde_json::json!({
            "summary": &c.summary,
            "artifacts": &c.artifacts,
            "warnings": c.warnings.iter().map(|w| w.to_string()).collect::<Vec<_>>(),
        });
        Ok((
            serde_json::to_string(&json)?,
            c.summary.to_string(),
            c.warnings.iter().map(|w| w.to_string()).collect(),
        ))
    });
    run.map_err(error)
}

/// `subfric import`: one lab file into a test of the set in `out` (created, or added to);
/// the options as the command's flags. Returns the warnings (what the reader did: the stage
/// kept, gaps, units assumed).
#[pyfunction]
#[pyo3(signature = (file, out, *, test_name, set_name, format, stage, rate_unit, time, time_unit, slip, slip_unit, shear, shear_unit, friction, normal, normal_unit, normal_stress, area, control, delimiter, skip, channels, keep))]
#[allow(clippy::too_many_arguments)]
fn import_file(
    py: Python<'_>,
    file: PathBuf,
    out: PathBuf,
    test_name: String,
    set_name: Option<String>,
    format: &str,
    stage: Option<String>,
    rate_unit: Option<String>,
    time: String,
    time_unit: &str,
    slip: String,
    slip_unit: &str,
    shear: Option<String>,
    shear_unit: &str,
    friction: Option<String>,
    normal: Option<String>,
    normal_unit: &str,
    normal_stress: Option<f64>,
    area: Option<f64>,
    control: &str,
    delimiter: &str,
    skip: usize,
    channels: Vec<(String, String)>,
    keep: Option<String>,
) -> PyResult<Vec<String>> {
    use subfric_data::{ColumnRef, ImportSpec};
    let parse =
        |what: &str, r: Result<ColumnRef, String>| r.map_err(|e| fail(format!("{what}: {e}")));
    let unit = |what: &str, e: String| fail(format!("{what}: {e}"));
    let shear_col = match (&shear, &friction) {
        (Some(c), _) => Some((
            parse("shear", c.parse())?,
            shear_unit.parse().map_err(|e| unit("shear_unit", e))?,
        )),
        (None, Some(_)) => None,
        (None, None) => Some((
            ColumnRef::Name("shear_kpa".into()),
            shear_unit.parse().map_err(|e| unit("shear_unit", e))?,
        )),
    };
    let spec = ImportSpec {
        delimiter: delimiter.parse().map_err(|e| unit("delimiter", e))?,
        skip_lines: skip,
        has_header: true,
        time: parse("time", time.parse())?,
        time_unit: time_unit.parse().map_err(|e| unit("time_unit", e))?,
        slip: parse("slip", slip.parse())?,
        slip_unit: slip_unit.parse().map_err(|e| unit("slip_unit", e))?,
        shear: shear_col,
        friction: friction.map(|c| parse("friction", c.parse())).transpose()?,
        normal: match normal {
            Some(c) => Some((
                parse("normal", c.parse())?,
                normal_unit.parse().map_err(|e| unit("normal_unit", e))?,
            )),
            None => None,
        },
        normal_stress_kpa: normal_stress,
        area_mm2: area,
        control: control.parse().map_err(|e| unit("control", e))?,
        test_name,
        set_name: set_name.unwrap_or_else(|| {
            out.file_name()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_else(|| "imported".into())
        }),
        title: None,
        soil: None,
        surface: None,
        source: Some(file.display().to_string()),
        keep: keep
            .map(|k| k.parse().map_err(|e| unit("keep", e)))
            .transpose()?,
        format: format.parse().map_err(|e| unit("format", e))?,
        stage,
        channels: channels
            .into_iter()
            .map(|(n, c)| Ok((n, parse("channels", c.parse())?)))
            .collect::<PyResult<_>>()?,
        rate_unit: rate_unit
            .map(|u| u.parse().map_err(|e| unit("rate_unit", e)))
            .transpose()?,
    };
    let run = py.detach(move || -> anyhow::Result<_> {
        let c = api::sets::import_test(&file, &spec, &out)?;
        Ok(c.warnings.iter().map(|w| w.to_string()).collect())
    });
    run.map_err(error)
}

/// `subfric plan`: the plan written to `out` (default `fits/<set>/plan`), returned as the
/// plan.json text, the plan's text and its warnings.
#[pyfunction]
#[pyo3(signature = (dir, *, out, diagnosis, seed, check, setup_hours, force))]
#[allow(clippy::too_many_arguments)]
fn plan(
    py: Python<'_>,
    dir: PathBuf,
    out: Option<PathBuf>,
    diagnosis: Option<PathBuf>,
    seed: u64,
    check: usize,
    setup_hours: f64,
    force: bool,
) -> PyResult<(String, String)> {
    let run = py.detach(move || -> anyhow::Result<_> {
        let req = api::plan::PlanRequest {
            set: dir,
            seed,
            check,
            setup_hours,
            diagnosis,
        };
        let to = api::folders::output::Destination { dir: out, force };
        let p = api::plan::plan_to_folder(&req, &to, &Silent)?;
        let json_file = p
            .files
            .iter()
            .find(|f| f.file_name().is_some_and(|n| n == "plan.json"))
            .ok_or_else(|| anyhow::anyhow!("the plan wrote no plan.json"))?;
        Ok((std::fs::read_to_string(json_file)?, p.text))
    });
    run.map_err(error)
}

/// `subfric plot`: the overlay figures of a set (measured, published, the model in `params`)
/// into `out`; returns the PNG files written (an SVG beside each) and the curves that could not
/// be drawn, and why.
#[pyfunction]
#[pyo3(signature = (dir, *, params, out, force))]
fn plot(
    py: Python<'_>,
    dir: PathBuf,
    params: Option<PathBuf>,
    out: Option<PathBuf>,
    force: bool,
) -> PyResult<(Vec<String>, Vec<String>)> {
    let run = py.detach(move || -> anyhow::Result<_> {
        let to = api::folders::output::Destination { dir: out, force };
        let p = api::render::figures::plot(&dir, params.as_deref(), &to, &Silent)?;
        Ok((
            p.files.iter().map(|f| f.display().to_string()).collect(),
            p.notes,
        ))
    });
    run.map_err(error)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("SubfricError", m.py().get_type::<SubfricError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(load_set, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(import_file, m)?)?;
    m.add_function(wrap_pyfunction!(plan, m)?)?;
    m.add_function(wrap_pyfunction!(plot, m)?)?;
    campaign::register(m)?;
    Ok(())
}
