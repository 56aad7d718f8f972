"""Campaigns: many sets at once, here or on a Dask cluster, into one table.

The per-set work is ``subfric campaign``'s own (the Rust application layer): each set is fitted
(and diagnosed with ``diagnose=True``) into ``<out>/sets/<set>/``, skipped when its inputs (the
SHA-256 of experiment.json and every CSV) and options match the record its results were
written with; the table (``campaign.csv``, ``campaign.md``) and the figures are then made from
those folders alone. So a local run, a Dask run and a Slurm array
(``subfric campaign --emit-slurm``) write the same files and the same table, byte for byte.

With a Dask client, the plan is written here, each set is one task (``client.map``) that a
worker runs into the campaign folder, and the table is collected here: the workers must see the
sets and the campaign folder at the same paths (a shared file system, as on a cluster; every
path is made absolute). Each task's fit is parallel too (one thread per core of its worker's
machine; ``RAYON_NUM_THREADS`` sets it): give each worker one thread of Dask's and few workers
per machine.
"""

import json
import os
import warnings as _warnings

from . import _native

__all__ = ["campaign"]


def _sets_argument(sets):
    expected = "expected a folder of sets, a manifest file, or a list of set folders"
    try:
        if isinstance(sets, (list, tuple)):
            if not sets:
                raise _native.SubfricError(f"sets: an empty list ({expected})")
            return [os.path.abspath(os.fspath(s)) for s in sets]
        return os.fspath(sets)
    except TypeError:
        raise _native.SubfricError(f"sets: {sets!r} ({expected})") from None


def _run_index(out, index, force):
    """One set of a prepared campaign, on a Dask worker: the run as a dict."""
    from . import _native as native  # imported on the worker

    return json.loads(native.campaign_run_index(out, index, force=force))


def _warn_incomplete(rows):
    from . import SubfricWarning

    for r in rows:
        if r["status"] != "ok":
            why = f": {r['error']}" if r.get("error") else ""
            _warnings.warn(
                f"campaign set {r['set']} {r['status'].replace('-', ' ')}{why}",
                SubfricWarning,
                stacklevel=3,
            )


def campaign(
    sets,
    client=None,
    *,
    out=None,
    diagnose=False,
    seed=1,
    starts=8,
    global_evals=3000,
    profiles=True,
    force=False,
    jobs=None,
    progress=None,
):
    """Fits (and with ``diagnose=True`` diagnoses) every set of a campaign, as
    ``subfric campaign`` does, and writes the campaign table and figures.

    ``sets``: a folder of sets (its sub-folders holding experiment.json), a manifest file
    (``.json`` or ``.toml``: set folders with options of their own, see docs/campaign.md), or a
    list of set folders. ``client``: a ``dask.distributed.Client`` to run the sets on its workers
    (one task per set); ``None`` runs them here, in parallel (``jobs`` sets at once, default one
    per core). ``out``: the campaign folder (default ``campaigns/<name>``). ``seed``,
    ``starts``, ``global_evals``, ``profiles``: the fits' options (a manifest's own win).
    ``force``: replace the results of another campaign in ``out``. ``progress``: None, or a
    function ``progress(stage, done, total)`` called as the campaign starts and as each set ends,
    locally or on the cluster, with ``stage`` "campaign: 3 of 20 sets done", ``done`` 3 and
    ``total`` 20 (a tqdm bar: ``bar.total = total; bar.n = done; bar.refresh()``). Locally it is
    called from the working threads and an exception it raises is raised once the campaign has
    ended; with a client it is called here, and an exception stops the waiting (the tasks go
    on).

    Returns a dict: ``out`` (the campaign folder, absolute), ``rows`` (one dict per set, sorted
    by set: ``set``, ``name``, ``status`` (``ok``, ``failed``, ``not-run``, ``out-of-date``),
    ``error``, the interface metadata, ``normal_stresses_kpa``, ``reduced_chi2``,
    ``parameters`` with their intervals and identifiability, ``verdict``, ``held_out_shrink``, ``confidence``),
    ``runs`` (per set: ``outcome`` ``ran``, ``skipped`` or ``failed`` with its ``error``, and
    ``seconds``) and ``files`` (the table and figures written). A set that failed does not stop
    the others: it is in ``rows`` and ``runs`` and issued as a :class:`SubfricWarning`.
    """
    from . import _count, _flag

    source = _sets_argument(sets)
    if out is not None and not isinstance(out, (str, os.PathLike)):
        raise _native.SubfricError(f"out: {type(out).__name__} {out!r} is not a path (expected a str or a path)")
    options = dict(
        out=None if out is None else os.fspath(out),
        seed=_count("seed", seed, 0),
        starts=_count("starts", starts, 1),
        global_evals=_count("global_evals", global_evals, 0),
        profiles=_flag("profiles", profiles),
        diagnose=_flag("diagnose", diagnose),
        force=_flag("force", force),
    )
    jobs = None if jobs is None else _count("jobs", jobs, 1)
    if client is None:
        if progress is not None and not callable(progress):
            raise TypeError(
                f"progress: a {type(progress).__name__} is not callable (expected a function progress(stage, done, total), or None)"
            )
        result = json.loads(
            _native.campaign_run(source, jobs=jobs, progress=progress, **options)
        )
    else:
        plan = json.loads(_native.campaign_prepare(source, **options))
        futures = client.map(
            _run_index,
            [plan["out"]] * len(plan["sets"]),
            range(len(plan["sets"])),
            force=bool(force),
            pure=False,
        )
        if progress is not None:
            _follow(futures, progress)
        runs = client.gather(futures)
        result = json.loads(_native.campaign_collect(source, **options))
        result["runs"] = runs
    _warn_incomplete(result["rows"])
    return result


def _follow(futures, progress):
    """Calls ``progress`` as the campaign starts and as each of the cluster's ``futures`` ends,
    in the words of a local campaign."""
    from distributed import as_completed

    if not callable(progress):
        raise TypeError(
            f"progress: a {type(progress).__name__} is not callable (expected a function progress(stage, done, total), or None)"
        )
    total = len(futures)
    progress(f"campaign: 0 of {total} sets done", 0, total)
    for done, _ in enumerate(as_completed(futures), 1):
        progress(f"campaign: {done} of {total} sets done", done, total)
