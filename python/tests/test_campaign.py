"""subfric.campaign: here, through a Dask LocalCluster of two worker processes, and by the
subfric program: the same per-set files and the same table, byte for byte."""

import os
import shutil

import pytest

import subfric
from conftest import EXPERIMENTS, set_cell

# Three interface pairs of one sand at three roughness levels (Table 1): fits of about a second.
SETS = ["table1-smooth", "table1-medium", "table1-rough"]


@pytest.fixture
def lab(tmp_path):
    root = tmp_path / "lab"
    for s in SETS:
        shutil.copytree(EXPERIMENTS / s, root / s)
    return root


def read(folder, name):
    return (folder / name).read_bytes()


def test_a_dask_cluster_a_local_run_and_the_program_write_the_same_table(lab, tmp_path, cli):
    from dask.distributed import Client, LocalCluster, get_task_stream

    def follow(calls):
        return lambda stage, done, total: calls.append((stage, done, total))

    def followed_every_set(calls):
        # Once as it starts, once as each set ends, in the same words here and on a cluster.
        assert sorted(d for _, d, _ in calls) == [0, 1, 2, 3], calls
        assert all(s == f"campaign: {d} of 3 sets done" and t == 3 for s, d, t in calls), calls

    local_calls = []
    local = subfric.campaign(lab, out=tmp_path / "local", progress=follow(local_calls))
    followed_every_set(local_calls)
    assert [r["set"] for r in local["rows"]] == sorted(SETS)
    assert [r["status"] for r in local["rows"]] == ["ok"] * 3
    assert [r["outcome"] for r in local["runs"]] == ["ran"] * 3
    # The metadata of the interface and R_max/D50 (µm over µm) are in the rows.
    rough = next(r for r in local["rows"] if r["set"] == "table1-rough")
    assert rough["d50_mm"] == 0.18 and rough["roughness_rmax_um"] == 9.8
    assert rough["rmax_over_d50"] == pytest.approx(9.8 / 180.0)
    assert rough["normal_stresses_kpa"] == [78.4]

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        workers = set(client.scheduler_info()["workers"])
        assert len(workers) == 2
        dask_calls = []
        with get_task_stream(client) as stream:
            dask = subfric.campaign(lab, client, out=tmp_path / "dask", progress=follow(dask_calls))
        followed_every_set(dask_calls)
        ran_on = {t["worker"] for t in stream.data if t["key"].startswith("_run_index")}
        # Every set ran as a task on the cluster's worker processes, none here.
        assert ran_on and ran_on <= workers, (ran_on, workers)
        assert len([t for t in stream.data if t["key"].startswith("_run_index")]) == 3
        pids = set(client.run(os.getpid).values())
        assert os.getpid() not in pids
        assert [r["outcome"] for r in dask["runs"]] == ["ran"] * 3
        # Run again on the cluster: every set is current, nothing is fitted.
        again = subfric.campaign(lab, client, out=tmp_path / "dask")
        assert [r["outcome"] for r in again["runs"]] == ["skipped"] * 3

    cli.run("campaign", lab, "--out", tmp_path / "cli", "--progress", "never")
    local_dir = tmp_path / "local"
    for other in [tmp_path / "dask", tmp_path / "cli"]:
        for f in ["campaign.csv", "campaign.md", "campaign.html", "figures/mu-vs-roughness.png"]:
            assert read(other, f) == read(local_dir, f), f"{other}/{f}"
        for s in SETS:
            assert read(other, f"sets/{s}/fit.json") == read(local_dir, f"sets/{s}/fit.json")
    assert local["rows"] == dask["rows"]


def test_a_failing_set_is_warned_the_others_are_fitted_and_a_second_run_skips_them(lab, tmp_path):
    set_cell(lab / "table1-rough" / "monotonic.csv", 5, "shear_kpa", "abc")
    out = tmp_path / "campaign"
    with pytest.warns(subfric.SubfricWarning, match=r"(?s)table1-rough failed: .*monotonic.csv:5: field `shear_kpa`"):
        first = subfric.campaign([lab / s for s in SETS], out=out, profiles=False)
    status = {r["set"]: r["status"] for r in first["rows"]}
    assert status == {"table1-medium": "ok", "table1-rough": "failed", "table1-smooth": "ok"}
    assert (out / "sets" / "table1-medium" / "fit.json").is_file()
    # Without profiles the parameters have no intervals: the table says so by empty cells.
    mu_s = next(p for p in first["rows"][0]["parameters"] if p["name"] == "mu_s")
    assert mu_s["lo"] is None and mu_s["status"] == "not profiled"
    with pytest.warns(subfric.SubfricWarning, match="table1-rough failed"):
        second = subfric.campaign([lab / s for s in SETS], out=out, profiles=False)
    outcomes = {r["id"]: r["outcome"] for r in second["runs"]}
    assert outcomes == {"table1-medium": "skipped", "table1-rough": "failed", "table1-smooth": "skipped"}
    with pytest.raises(subfric.SubfricError, match="expected a folder of sets, a manifest file"):
        subfric.campaign(42, out=out)
