"""diagnose: the content of the diagnosis.json that `subfric diagnose` writes. A diagnosis takes
seconds, so there are few of them here."""

import pytest

import subfric
from conftest import EXPERIMENTS, GOLDEN, set_cell


def without_wall_times(v):
    """The diagnosis records its wall time (`elapsed_s`): the one thing two runs differ in."""
    if isinstance(v, dict):
        return {k: without_wall_times(x) for k, x in v.items() if k != "elapsed_s"}
    if isinstance(v, list):
        return [without_wall_times(x) for x in v]
    return v


@pytest.fixture(scope="module")
def diagnosed_with_progress():
    """One whole diagnosis (four lab-style tests, 6 500 rows, an effect the base model lacks)
    through the package, with a progress callback: each takes seconds, so the tests of what it
    returns and of what it reports share it."""
    stages = []
    got = subfric.diagnose(
        subfric.load_set(GOLDEN / "pair-01"),
        seed=2,
        progress=lambda stage, done, total: stages.append((stage, done, total)),
    )
    return got, stages


def test_diagnose_returns_what_the_command_writes_to_diagnosis_json(cli, tmp_path, diagnosed_with_progress):
    d = GOLDEN / "pair-01"
    out = tmp_path / "diag"
    cli.run("diagnose", d, "--out", out, "--seed", "2")
    want = cli.json(out / "diagnosis.json")
    # Reporting progress changes nothing in what the diagnosis returns.
    got, _ = diagnosed_with_progress
    assert set(got) == {"set", "verdict", "diagnosis"}
    assert got["set"] == "pair-01"
    assert "elapsed_s" in got["diagnosis"]
    assert without_wall_times(got) == without_wall_times(want)
    v = got["verdict"]
    assert isinstance(v["effect"], str) and v["effect"]
    assert isinstance(v["held_out_shrink"], float)
    # The word the report leads with follows the confidence.
    c = v["confidence"]
    assert v["standing"] == ("confident" if c >= 0.9 else "probable" if c >= 0.5 else "uncertain")


def test_diagnose_reports_its_steps_in_the_command_s_words(diagnosed_with_progress):
    d, stages = diagnosed_with_progress
    assert d["set"] == "pair-01"
    words = [s for s, _, _ in stages]
    assert words[0] == "diagnosis: preparing the tests", words
    assert any(w.startswith("diagnosis 2/5: screening every candidate form (") for w in words), words
    assert words[-1].startswith("diagnosis 5/5"), words
    assert all(done is None and total is None for _, done, total in stages)


def test_a_bad_set_is_refused_with_the_command_s_message(copy_set, cli):
    d = copy_set("pair-01", GOLDEN)
    set_cell(d / "velocity-steps.csv", 30, "time_s", "-1")
    with pytest.raises(subfric.SubfricError) as e:
        subfric.diagnose(d)
    msg = str(e.value)
    assert "velocity-steps.csv:30" in msg and "time_s" in msg, msg
    err = cli.run("diagnose", d, "--out", d.parent / "out", ok=False).stderr
    assert msg in err, f"python: {msg}\ncommand: {err}"


def test_replicates_hold_each_seeds_verdict_and_the_second_is_the_diagnosis_at_its_seed():
    # Table 4's set: a second a diagnosis, and the confidence it states moves from seed 1 to 2.
    s = EXPERIMENTS / "table4-two-way"
    got = subfric.diagnose(s, seed=1, replicates=2)
    r = got["verdict"]["replicates"]
    assert [x["seed"] for x in r["runs"]] == [1, 2]
    assert r["runs"][0]["confidence"] == got["verdict"]["confidence"]
    at_2 = subfric.diagnose(s, seed=2)
    assert "replicates" not in at_2["verdict"]
    assert r["runs"][1]["confidence"] == at_2["verdict"]["confidence"]
    assert r["stable"] == (r["runs"][0]["effects"] == r["runs"][1]["effects"])
    for bad in (0, 65, 1.0, True):
        with pytest.raises(subfric.SubfricError, match="replicates"):
            subfric.diagnose(s, replicates=bad)
