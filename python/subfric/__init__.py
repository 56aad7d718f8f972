"""subfric: calibrate the subloading-friction model of sand-metal interfaces and diagnose where
the calibrated model and the laboratory disagree.

The same code as the ``subfric`` command (a Rust library), from Python::

    import subfric
    s = subfric.load_set("experiments/table1-medium")      # tests as NumPy arrays
    r = subfric.fit(s)                                       # fit.json's content + fitted curves
    r["report"]["parameters"][0]["value"]                    # mu_s
    c = r["curves"]["monotonic"]                             # time_s, measured, fitted, mu, r
    shear, mu, ratio = subfric.simulate(r, c["time_s"], c["imposed"], 78.4)
    d = subfric.diagnose(s)                                  # diagnosis.json's content
    d["verdict"]["effect"]
    c = subfric.campaign("lab/", out="campaigns/lab")        # every set: a table and figures
    c = subfric.campaign("lab/", client, out="campaigns/lab")  # the same on a Dask cluster

Units: slip mm, time s, traction kPa; kappa, u_tilde in 1/mm; xi in 1/s; alpha_t, alpha_n in
kN/mm^3. Every error of the data or the parameters raises :class:`SubfricError` with the message
the command prints (file, line, field, and what was expected). The long calls (``fit``,
``diagnose``, ``simulate``) release the GIL, so other Python threads run meanwhile.
"""

import json
import operator
import os
import warnings as _warnings

import numpy as np

from . import _native
from ._native import SubfricError

__version__ = _native.__version__

__all__ = [
    "SubfricError",
    "SubfricWarning",
    "ExperimentSet",
    "Test",
    "simulate",
    "load_set",
    "fit",
    "diagnose",
    "check",
    "import_file",
    "plan",
    "plot",
    "to_inference_data",
    "campaign",
]


class SubfricWarning(UserWarning):
    """Valid but implausible data (a unit off by 10^3, a shear of 0 on every row, ...): the
    warnings ``subfric check``, ``fit`` and ``diagnose`` print, naming the file and the column."""


def _warn(messages):
    for m in messages:
        _warnings.warn(m, SubfricWarning, stacklevel=3)


class Test:
    """One test of a set: its description from experiment.json and its columns as NumPy arrays
    (one entry per data row of the CSV)."""

    def __init__(self, d):
        self.name = d["name"]
        #: CSV file name, relative to the set's folder
        self.file = d["file"]
        #: path of the CSV file
        self.path = d["path"]
        #: "slip" (slip imposed, shear measured) or "shear" (shear imposed, slip measured)
        self.control = d["control"]
        self.normal_stress_kpa = d["normal_stress_kpa"]
        #: None (decided from the data), "rest" or "sliding"
        self.initial = d["initial"]
        #: True when the CSV gave `friction` instead of `shear_kpa`
        self.friction_given = d["friction_given"]
        #: the units the CSV's columns were written in (`units` of experiment.json: a dict of
        #: stress, displacement and time, None where not given), or None for kPa, mm and s;
        #: the arrays are in kPa, mm and s either way
        self.units = d["units"]
        #: the CSV's comment lines (provenance)
        self.comments = d["comments"]
        self.time_s = d["time_s"]
        self.slip_mm = d["slip_mm"]
        self.shear_kpa = d["shear_kpa"]
        #: normal stress per row (the `normal_kpa` column, else the test's normal stress)
        self.normal_kpa = d["normal_kpa"]
        #: further channels the CSV carried, by column name (``normal_disp_mm``,
        #: ``temperature_c``, ``shear_force_kn``, ``normal_force_kn``, ``area_mm2``): arrays,
        #: NaN where the logger missed a sample; carried as read, not used by the model
        self.channels = d["channels"]

    @property
    def imposed(self):
        """The column the apparatus imposed: slip under slip control, shear under shear control."""
        return self.slip_mm if self.control == "slip" else self.shear_kpa

    @property
    def measured(self):
        """The measured column: shear under slip control, slip under shear control."""
        return self.shear_kpa if self.control == "slip" else self.slip_mm

    @property
    def friction(self):
        """Friction ratio shear / normal per row."""
        return self.shear_kpa / self.normal_kpa

    def __len__(self):
        return len(self.time_s)

    def __repr__(self):
        return (
            f"<subfric.Test {self.name!r}: {len(self)} rows, {self.control} control, "
            f"{self.normal_stress_kpa} kPa>"
        )


class ExperimentSet:
    """A set folder as :func:`load_set` read it: ``experiment.json`` (``meta``, with ``name``,
    ``title``, ``source``, ``reference_parameters`` ... as attributes) and its ``tests``
    (:class:`Test`, also by name: ``s["monotonic"]``). :func:`fit` and :func:`diagnose` accept
    it in place of its folder (they read the folder ``path``)."""

    def __init__(self, d):
        #: the set's folder
        self.path = d["path"]
        #: experiment.json's content
        self.meta = json.loads(d["meta_json"])
        self.name = self.meta["name"]
        self.title = self.meta["title"]
        self.source = self.meta["source"]
        self.provenance = self.meta.get("provenance")
        self.interface = self.meta.get("interface", {})
        #: published parameters (a dict, as in experiment.json), or None
        self.reference_parameters = self.meta.get("reference_parameters")
        self.tests = [Test(t) for t in d["tests"]]
        #: plausibility warnings (also issued as SubfricWarning)
        self.warnings = list(d["warnings"])

    def __getitem__(self, key):
        if isinstance(key, str):
            for t in self.tests:
                if t.name == key:
                    return t
            names = ", ".join(t.name for t in self.tests)
            raise KeyError(f"{key!r}: no such test in set {self.name!r} (it has: {names})")
        return self.tests[key]

    def __iter__(self):
        return iter(self.tests)

    def __len__(self):
        return len(self.tests)

    def __fspath__(self):
        return self.path

    def __repr__(self):
        names = ", ".join(t.name for t in self.tests)
        return f"<subfric.ExperimentSet {self.name!r} from {self.path!r}: {names}>"


def load_set(path):
    """Loads and validates a set folder (``experiment.json`` and one CSV per test).

    Returns an :class:`ExperimentSet`. Every problem of every file is reported together in one
    :class:`SubfricError` naming the file, the line and the field; plausibility warnings are
    issued as :class:`SubfricWarning` (and kept in ``.warnings``).
    """
    s = ExperimentSet(_native.load_set(os.fspath(path)))
    _warn(s.warnings)
    return s


def _column(name, x):
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim != 1:
        raise SubfricError(f"{name}: an array of {a.ndim} dimensions (expected a 1-D array)")
    return a


def simulate(params, time, imposed, normal, control="slip", *, initial=None, initial_slip=0.0):
    """Drives the model through one test: rows of time [s], the imposed column (slip [mm] under
    ``control="slip"``, shear [kPa] under ``control="shear"``) and the normal stress [kPa] (an
    array, or one number for every row).

    ``params`` is a dict of parameters (``mu_s, mu_k, kappa, xi, u_tilde, alpha_t``, optional
    ``alpha_n, mu_0``: the keys of ``reference_parameters``), a dict as :func:`fit` returns or as
    fit.json holds (its ``model``: parameters and extensions), an experiment.json's content, or the
    path of such a JSON file (as ``subfric simulate --params`` reads it).

    ``initial``: None or ``"rest"`` (an unloaded interface at rest), or
    ``{"kind": "loaded", "shear_kpa": ...}``, or
    ``{"kind": "sliding", "shear_kpa": ..., "rate_mm_s": ...}`` (already sliding at the first row).
    A start must be one the model can hold: a finite traction within the friction capacity at
    rest (loaded) or of a contact sliding at that rate (sliding), and a finite rate >= 0 (a
    speed: the direction of sliding is the sign of ``shear_kpa``); anything else raises
    :class:`SubfricError` saying what was given and what is allowed.
    ``initial_slip``: the slip at the first row under shear control [mm], a finite number.
    The model depends on slip differences only, and a slip too large for its doubles to carry
    the elastic slip (beyond about 10^5 mm at alpha_t = 2000 kN/mm^3) raises, naming the row:
    subtract a constant from the slip.

    Returns three arrays: the predicted column (shear [kPa] under slip control, slip [mm] under
    shear control), the friction coefficient mu and the normal-yield ratio r. A row the model
    cannot follow (runaway sliding under shear control, time not increasing, ...) raises
    :class:`SubfricError` naming the row (counted from 0).
    """
    if isinstance(params, dict) and "model" in params:
        params = {"model": params["model"]}  # a fit result: its model, not its curves
    elif isinstance(params, os.PathLike):
        params = os.fspath(params)
    time = _column("time", time)
    imposed = _column("imposed", imposed)
    if np.ndim(normal) == 0:
        normal = np.full(time.shape, float(normal))
    normal = _column("normal", normal)
    return _native.simulate(
        params, time, imposed, normal, str(control), initial=initial, initial_slip=float(initial_slip)
    )


# Arguments are checked here, each refused with SubfricError naming it, as the command line
# refuses a flag's value: never coerced (``starts=1.5`` is not 1), never an internal error.


# Most diagnoses `diagnose(replicates=...)` runs, as the command's --replicates.
_MAX_REPLICATES = 64


def _count(name, v, least):
    """A whole number of at least ``least`` (a bool or a float is refused, not coerced)."""
    if isinstance(v, bool) or isinstance(v, float):
        raise SubfricError(f"{name}: {v!r} is not a whole number (expected an int >= {least})")
    try:
        n = operator.index(v)
    except TypeError:
        raise SubfricError(
            f"{name}: {type(v).__name__} {v!r} is not a whole number (expected an int >= {least})"
        ) from None
    if n < least:
        raise SubfricError(f"{name}: {n} is below {least} (expected an int >= {least})")
    return n


def _set_dir(set):
    """The folder of a set given as a path or an :class:`ExperimentSet`."""
    if not isinstance(set, (str, os.PathLike, ExperimentSet)):
        raise SubfricError(f"set: {type(set).__name__} {set!r} is not a set folder (expected a path or an ExperimentSet)")
    return os.fspath(set)


def _flag(name, v):
    if not isinstance(v, (bool, np.bool_)):
        raise SubfricError(f"{name}: {type(v).__name__} {v!r} is not True or False (expected a bool)")
    return bool(v)


def _text(name, v):
    if not isinstance(v, str):
        raise SubfricError(f"{name}: {type(v).__name__} {v!r} is not a string (expected a str)")
    return v


def _number(name, v):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise SubfricError(f"{name}: {type(v).__name__} {v!r} is not a number (expected a float)")
    return float(v)


def _names(name, v):
    """A list of names, or None; an empty list is refused (``None`` means all)."""
    if v is None:
        return None
    if isinstance(v, str) or not isinstance(v, (list, tuple)):
        raise SubfricError(
            f"{name}: {type(v).__name__} {v!r} is not a list of names (expected a list of str, or None)"
        )
    if not v:
        raise SubfricError(f"{name}: an empty list (expected at least one name, or None for all)")
    return [_text(f"{name}[{i}]", k) for i, k in enumerate(v)]


def _mapping(name, v, value):
    """A dict of key -> value(``name[key]``, v), or {} for None."""
    if v is None:
        return []
    if not isinstance(v, dict):
        raise SubfricError(
            f"{name}: {type(v).__name__} {v!r} is not a dict (expected a dict such as {{\"xi\": 0.003}})"
        )
    return [(_text(f"{name} key", k), value(f"{name}[{k!r}]", x)) for k, x in v.items()]


def _range(name, v):
    if not isinstance(v, (list, tuple)) or len(v) != 2:
        raise SubfricError(f"{name}: {v!r} is not a (lo, hi) pair (expected two numbers)")
    return (_number(f"{name}[0]", v[0]), _number(f"{name}[1]", v[1]))


def _set_paths(sets):
    if isinstance(sets, (str, os.PathLike, ExperimentSet)):
        sets = [sets]
    if not isinstance(sets, (list, tuple)):
        raise SubfricError(f"sets: {type(sets).__name__} {sets!r} is not a set folder or a list of them")
    for i, s in enumerate(sets):
        if not isinstance(s, (str, os.PathLike, ExperimentSet)):
            raise SubfricError(f"sets[{i}]: {type(s).__name__} {s!r} is not a set folder (expected a path)")
    paths = [os.fspath(s) for s in sets]
    if not paths:
        raise SubfricError("sets: no set folder given (expected one or more)")
    return paths


def fit(
    sets,
    *,
    tests=None,
    free=None,
    fix=None,
    bounds=None,
    weights=None,
    method="lsq",
    starts=8,
    seed=1,
    global_evals=3000,
    profiles=True,
    posterior=False,
    priors=None,
    max_evals=None,
    residuals="correlated",
    progress=None,
):
    """Calibrates the model against one set, or several jointly, exactly as ``subfric fit``.

    ``sets``: a set folder, an :class:`ExperimentSet`, or a list of them (a joint fit sharing the
    parameters; tests are then named ``set/test``). Options, as the command's flags:
    ``tests`` (names; all by default), ``free`` (parameter keys; default
    ``["mu_s", "mu_k", "kappa", "xi", "u_tilde"]``), ``fix`` (``{"xi": 0.003}``), ``bounds``
    (``{"kappa": (0.1, 10)}``, in the parameters' own units), ``weights`` (``{"test": 2.0}``),
    ``method`` (``"lsq"`` Levenberg-Marquardt or ``"nm"`` Nelder-Mead), ``starts``, ``seed``,
    ``global_evals`` (model runs of the global stage), ``profiles`` (profile intervals).
    ``progress``: None, or a function ``progress(stage, done, total)`` called as the command's
    progress display is drawn: when a stage begins (``done`` None; ``total`` its budget in
    model runs when known, else None) and, with the posterior, at most ten times a second with
    the sampler's model runs done (``done`` of about ``total``). It is called from the threads doing the work; an exception
    it raises stops the calls and is raised once the fit has ended. With tqdm::

        bar = tqdm.tqdm()
        def progress(stage, done, total):
            bar.set_description(stage)
            if total: bar.total = total
            if done is not None: bar.n = done
            bar.refresh()

    Returns a dict with the content of the fit.json that ``subfric fit`` writes (``set``,
    ``tests``, ``params``, ``model``, ``report``: parameters with standard errors, intervals and
    identifiability — each parameter's ``reads`` is its value as the reports read it,
    ``"not determined (≤ 0.30)"`` for one the data do not determine — combinations, per-test
    misfits, optimiser) and ``curves``: per test, arrays
    ``time_s``, ``imposed`` (as the model was driven: the imposed column conditioned),
    ``measured``, ``fitted`` (the model's prediction of the measured column), ``normal_kpa``,
    ``mu`` and ``r``, its ``control``, and how the model was started (``initial``,
    ``initial_slip``): ``simulate(result, c["time_s"], c["imposed"], c["normal_kpa"],
    c["control"], initial=c["initial"], initial_slip=c["initial_slip"])`` gives ``c["fitted"]``
    again. Deterministic for a seed.

    ``posterior=True`` then samples the posterior of the free parameters, as ``subfric fit
    --posterior`` (docs/posterior.md): ``priors`` a prior file (JSON or TOML; default uniform
    within the bounds on the fit's scale), ``max_evals`` the sampler's budget in model runs
    (default 300 000; it stops once converged), ``residuals`` ``"correlated"`` (default) or
    ``"independent"``. The result then holds ``posterior``, as in fit.json (``summary``: per
    parameter ``median``, ``lo``/``hi`` the 95 % credible interval beside ``profile_interval``;
    ``correlation``; ``convergence``; ``converged`` and ``message``), plus ``chain``: arrays
    ``step``, ``walker`` and one per parameter (the thinned chain of posterior-chain.csv),
    ``log_density`` (per sample of the chain: the log posterior density on the sampler's
    coordinates, up to a constant), ``predictive_samples`` and ``predictive`` (per test, an
    array of draws × rows: the measured column as new measurements would read it, each draw's
    model curve plus the noise, for the chain's samples ``predictive_samples``); and each curve
    ``band_lo``, ``band_median``, ``band_hi`` (the 95 % band of the model curve). When arviz is
    installed the result also holds ``inference_data``, the same posterior as an ArviZ
    ``InferenceData`` (see :func:`to_inference_data`). A
    run that has not converged issues a :class:`SubfricWarning` saying how large a
    ``max_evals`` it needs. A prior file with an error raises :class:`SubfricError` naming
    its line and field.
    """
    if priors is not None and not isinstance(priors, (str, os.PathLike)):
        raise SubfricError(f"priors: {type(priors).__name__} {priors!r} is not a path (expected a str or a path)")
    text, curves, warns, sampled = _native.fit(
        _set_paths(sets),
        tests=_names("tests", tests) or [],
        free=_names("free", free),
        fix=_mapping("fix", fix, _number),
        bounds=[(k, lo, hi) for k, (lo, hi) in _mapping("bounds", bounds, _range)],
        weights=_mapping("weights", weights, _number),
        method=_text("method", method),
        starts=_count("starts", starts, 1),
        seed=_count("seed", seed, 0),
        global_evals=_count("global_evals", global_evals, 0),
        profiles=_flag("profiles", profiles),
        posterior=_flag("posterior", posterior),
        priors=None if priors is None else os.fspath(priors),
        max_evals=None if max_evals is None else _count("max_evals", max_evals, 1),
        residuals=_text("residuals", residuals),
        progress=progress,
    )
    _warn(warns)
    result = json.loads(text)
    result["curves"] = curves
    if sampled is not None:
        p = result["posterior"]
        p["chain"] = sampled["chain"]
        p["log_density"] = sampled["log_density"]
        p["predictive_samples"] = sampled["predictive_samples"]
        p["predictive"] = {
            name: flat.reshape(-1, len(curves[name]["time_s"]))
            for name, flat in sampled["predictive"].items()
        }
        if not p["converged"]:
            need = p["max_evals_needed"]
            _warn([p["message"].replace(f"--max-evals {need}", f"max_evals={need}")])
        arviz = _arviz()
        if arviz is not None:
            result["inference_data"] = to_inference_data(result, arviz=arviz)
    return result


def _arviz():
    """ArviZ when it is installed, else None (imported quietly: its import announces a
    refactor in a FutureWarning that is not the user's business here)."""
    with _warnings.catch_warnings():
        _warnings.simplefilter("ignore", FutureWarning)
        try:
            import arviz
        except ImportError:
            return None
    return arviz


def to_inference_data(result, *, arviz=None):
    """The posterior of ``fit(..., posterior=True)`` as an ArviZ ``InferenceData``, the object
    Python users analyse posteriors with (``az.summary``, ``az.plot_trace``, ``az.plot_pair``,
    ``az.plot_ppc``, ``az.ess``, ``az.rhat``). ``fit`` adds it to its result as
    ``inference_data`` when arviz is installed (``pip install arviz``, or ``./python[arviz]``).

    Groups:

    - ``posterior``: every free parameter (``mu_s``, ...) in its natural units, dims
      ``(chain, draw)``: one chain per walker of the ensemble, one draw per thinned step after
      the burn-in (emcee's convention, as ``az.from_emcee``); the ``draw`` coordinates are the
      steps.
    - ``sample_stats``: ``lp``, the log posterior density of each sample on the sampler's
      coordinates, up to a constant.
    - ``posterior_predictive``: per test, the measured column (shear [kPa] under slip control,
      slip [mm] under traction control) as new measurements would read it — each draw's model
      curve plus the noise — dims ``(chain, draw, <test>_row)``; the draws
      (``predictive_samples`` of the result, spread evenly over the thinned chain) are one chain,
      so that ``az.plot_ppc`` can compare them with the data. A draw the model could not
      simulate is NaN.
    - ``observed_data``: per test, the measured column.
    - ``constant_data``: per test, ``<test>_time_s``, ``<test>_imposed`` and
      ``<test>_normal_kpa``, as the model was driven.

    Raises :class:`SubfricError` when the result has no posterior, or when arviz is not
    installed.
    """
    if arviz is None:
        arviz = _arviz()
    if arviz is None:
        raise SubfricError(
            "to_inference_data: arviz is not installed (expected `pip install arviz`, "
            "or the package's `arviz` extra)"
        )
    p = result.get("posterior") if isinstance(result, dict) else None
    if not p or "chain" not in p:
        raise SubfricError(
            "to_inference_data: the result has no posterior (expected the result of "
            "subfric.fit(..., posterior=True))"
        )
    chain = p["chain"]
    walkers = int(chain["walker"].max()) + 1
    steps = np.unique(chain["step"])
    # The thinned chain is step after step, every walker at each: (draw, chain) → (chain, draw).
    def per_walker(a):
        return np.asarray(a).reshape(len(steps), walkers).T

    posterior = {k: per_walker(chain[k]) for k in p["parameters"]}
    stats = {"lp": per_walker(p["log_density"])}
    curves = result["curves"]
    predictive, observed, constant, dims = {}, {}, {}, {}
    for name, draws in p["predictive"].items():
        c = curves[name]
        row = f"{name}_row"
        predictive[name] = draws[np.newaxis, :, :]
        observed[name] = np.asarray(c["measured"])
        dims[name] = [row]
        for k in ("time_s", "imposed", "normal_kpa"):
            constant[f"{name}_{k}"] = np.asarray(c[k])
            dims[f"{name}_{k}"] = [row]
    with _warnings.catch_warnings():
        # ArviZ guesses a transposed array when there are more chains than draws; an ensemble
        # of many walkers on a short run has them, by construction.
        _warnings.filterwarnings("ignore", message="More chains", category=UserWarning)
        data = arviz.from_dict(
            posterior=posterior,
            sample_stats=stats,
            posterior_predictive=predictive,
            observed_data=observed,
            constant_data=constant,
            dims=dims,
        )
    # The draws of the chain are its thinned steps (the predictive draws keep their own count).
    data.posterior = data.posterior.assign_coords(draw=steps)
    data.sample_stats = data.sample_stats.assign_coords(draw=steps)
    return data


def diagnose(set, *, seed=1, replicates=1, progress=None):
    """Diagnoses the gap between the calibrated model and the data of one set, exactly as
    ``subfric diagnose``: where the base model misses, which unmodelled effect explains it, and
    how far it shrinks on held-out data. Takes several seconds for a few thousand rows.

    ``set``: a set folder or an :class:`ExperimentSet`. Returns the content of the
    diagnosis.json that ``subfric diagnose`` writes: ``set``, ``verdict`` (``effects``,
    ``effect``, ``held_out_shrink``, ``explanation``, ``extra_parameters``, ``confidence``,
    ``standing`` — ``confident``, ``probable`` or ``uncertain`` — and ``alternatives``) and ``diagnosis`` (everything
    else: the base fit, localisation by test and segment, candidates, selection, evidence).
    ``progress``: None, or a function ``progress(stage, done, total)`` called as each step of
    the diagnosis begins, with the command's words ("diagnosis 2/5: screening every candidate
    form (12/25 forms fitted)"; ``done`` and ``total`` None), as :func:`fit` describes.
    ``replicates``: diagnoses in all, at ``seed`` and the seeds after it, as ``subfric diagnose
    --replicates``: above 1, ``verdict`` also holds ``replicates`` (each seed's verdict, the
    readings with their seeds, ``stable``, and the report's sentence), whether the verdict moves
    with the fits' random start. At most 64; each is a whole diagnosis.
    """
    n = _count("replicates", replicates, 1)
    if n > _MAX_REPLICATES:
        raise SubfricError(f"replicates: {n} is above {_MAX_REPLICATES} (expected an int from 1 to {_MAX_REPLICATES})")
    text, warns = _native.diagnose(
        _set_dir(set), seed=_count("seed", seed, 0), replicates=n, progress=progress
    )
    _warn(warns)
    return json.loads(text)


def check(set):
    """Checks a set exactly as ``subfric check``: returns a dict with ``summary`` (per test:
    rows, control, ranges, noise, rates, holds, steps, reversals, cycles; as the command's
    table), ``text`` (that table as the command prints it), ``artifacts`` (rig artifacts
    recognised: ``test``, ``kind``, ``detail``) and ``warnings`` (plausibility and what the
    reader did: gaps, a spread clock), each also issued as a :class:`SubfricWarning`. A set
    with an error raises :class:`SubfricError` naming the file, the line and the field.
    """
    text, table, warns = _native.check(_set_dir(set))
    _warn(warns)
    result = json.loads(text)
    result["text"] = table
    return result


def import_file(
    file,
    out,
    *,
    test_name="test",
    set_name=None,
    format="auto",
    stage=None,
    rate_unit=None,
    time="time_s",
    time_unit="s",
    slip="slip_mm",
    slip_unit="mm",
    shear=None,
    shear_unit="kPa",
    friction=None,
    normal=None,
    normal_unit="kPa",
    normal_stress=None,
    area=None,
    control="slip",
    delimiter="auto",
    skip=0,
    channels=None,
    keep=None,
):
    """Imports one lab file as a test of the set in ``out`` (created, or added to; nothing in it
    is overwritten), exactly as ``subfric import``, and returns the set as
    :class:`ExperimentSet`. Options as the command's flags: columns by header name or 1-based
    index (``time``, ``slip``, ``shear`` or ``friction``, ``normal`` or ``normal_stress`` in
    kPa) with their units; ``format`` ``"auto"``, ``"delimited"`` or ``"gds"`` (a GDS export,
    its channels found by name: the column options are then not used); ``stage`` the stage to
    keep (by number or name); ``rate_unit`` (``"mm/min"``) for a GDS file that states its rate
    without one; ``channels`` ``{"normal_disp_mm": "Vertical (mm)"}``; ``keep``
    ``"time=120:"``. What the reader did (the stage kept, gaps, units assumed) is issued as
    :class:`SubfricWarning`.
    """
    cols = _mapping("channels", channels, lambda name, v: str(v)) if channels else []
    warns = _native.import_file(
        os.fspath(file),
        os.fspath(out),
        test_name=_text("test_name", test_name),
        set_name=None if set_name is None else _text("set_name", set_name),
        format=_text("format", format),
        stage=None if stage is None else str(stage),
        rate_unit=None if rate_unit is None else _text("rate_unit", rate_unit),
        time=str(time),
        time_unit=_text("time_unit", time_unit),
        slip=str(slip),
        slip_unit=_text("slip_unit", slip_unit),
        shear=None if shear is None else str(shear),
        shear_unit=_text("shear_unit", shear_unit),
        friction=None if friction is None else str(friction),
        normal=None if normal is None else str(normal),
        normal_unit=_text("normal_unit", normal_unit),
        normal_stress=None if normal_stress is None else _number("normal_stress", normal_stress),
        area=None if area is None else _number("area", area),
        control=_text("control", control),
        delimiter=_text("delimiter", delimiter),
        skip=_count("skip", skip, 0),
        channels=cols,
        keep=None if keep is None else _text("keep", keep),
    )
    _warn(warns)
    return load_set(out)


def plan(set, *, out=None, diagnosis=None, seed=1, check=1, setup_hours=0.5, force=False):
    """Plans the next test exactly as ``subfric plan`` and writes the plan to ``out`` (default
    ``fits/<set>/plan``). Returns the content of plan.json (``model``: the verdict on the model
    planned on; ``plan``: the valley, ``proposals`` best first — each with ``narrows``, whether
    it narrows anything; those that do not come last, unranked — and ``rejected``) with
    ``text``, the plan as the command prints it. ``diagnosis``: the diagnosis.json whose model
    to plan on (default: the set's own diagnosis, when there is one).
    """
    text, words = _native.plan(
        _set_dir(set),
        out=None if out is None else os.fspath(out),
        diagnosis=None if diagnosis is None else os.fspath(diagnosis),
        seed=_count("seed", seed, 0),
        check=_count("check", check, 0),
        setup_hours=_number("setup_hours", setup_hours),
        force=_flag("force", force),
    )
    result = json.loads(text)
    result["text"] = words
    return result


def plot(set, *, params=None, out=None, force=False):
    """Draws the overlay figures of a set exactly as ``subfric plot``: per test the measured
    curve, the published one (when the set has reference parameters) and that of the model in
    ``params`` (a fit.json or params.json; default: the set's own ``fits/<set>/fit.json`` when
    there is one), as PNG with an SVG beside each, into ``out`` (default ``fits/<set>/plots``).
    Needs no plotting library. Returns the PNG files written; a curve that cannot be drawn (a
    model that runs away on a test) is issued as a :class:`SubfricWarning`, not dropped
    silently.
    """
    files, notes = _native.plot(
        _set_dir(set),
        params=None if params is None else os.fspath(params),
        out=None if out is None else os.fspath(out),
        force=_flag("force", force),
    )
    _warn(notes)
    return files


# Last: the function takes the name of its module in the package's namespace.
from .campaign import campaign  # noqa: E402
