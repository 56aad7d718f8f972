"""load_set: the tests of a set as NumPy arrays and its metadata, the errors and warnings of the
command's loader."""

import json

import numpy as np
import pytest

import subfric
from conftest import BUNDLED, EXPERIMENTS, GOLDEN, set_cell


def read_csv(path):
    """The CSV's columns by name, parsed here independently of subfric."""
    lines = [l for l in open(path) if not l.startswith("#")]
    header = lines[0].strip().split(",")
    rows = np.array([[float(x) for x in l.split(",")] for l in lines[1:] if l.strip()])
    return {h: rows[:, i] for i, h in enumerate(header)}


@pytest.mark.parametrize("name", BUNDLED)
def test_bundled_sets_load_with_their_columns_and_metadata(name):
    s = subfric.load_set(EXPERIMENTS / name)
    meta = json.load(open(EXPERIMENTS / name / "experiment.json"))
    assert s.name == meta["name"] == name
    assert s.title == meta["title"]
    assert s.reference_parameters == meta["reference_parameters"]
    assert [t.name for t in s] == [t["name"] for t in meta["tests"]]
    assert s.warnings == []
    for t, spec in zip(s, meta["tests"]):
        cols = read_csv(EXPERIMENTS / name / spec["file"])
        assert t.control == spec["control"]
        assert t.normal_stress_kpa == spec["normal_stress_kpa"]
        for c in ("time_s", "slip_mm", "shear_kpa"):
            a = getattr(t, c)
            assert isinstance(a, np.ndarray) and a.dtype == np.float64
            np.testing.assert_array_equal(a, cols[c])
        np.testing.assert_array_equal(t.normal_kpa, np.full(len(t), spec["normal_stress_kpa"]))
        imposed, measured = ("slip_mm", "shear_kpa") if t.control == "slip" else ("shear_kpa", "slip_mm")
        np.testing.assert_array_equal(t.imposed, cols[imposed])
        np.testing.assert_array_equal(t.measured, cols[measured])
        np.testing.assert_allclose(t.friction, cols["shear_kpa"] / spec["normal_stress_kpa"])
        assert s[t.name] is t


def test_a_set_with_several_tests_and_the_command_s_summary(cli):
    s = subfric.load_set(GOLDEN / "pair-01")
    assert len(s) == 4
    out = cli.run("check", GOLDEN / "pair-01").stdout
    for t in s:
        assert t.name in out
        assert str(len(t)) in out, f"{t.name}: {len(t)} rows not in the summary:\n{out}"
    with pytest.raises(KeyError, match="no such test"):
        s["nope"]
    assert "pair-01" in repr(s) and "velocity-steps" in repr(s)


def test_a_bad_cell_raises_subfric_error_with_the_command_s_located_message(cli, copy_set):
    d = copy_set("table1-medium")
    set_cell(d / "monotonic.csv", 11, "slip_mm", "abc")
    with pytest.raises(subfric.SubfricError) as e:
        subfric.load_set(d)
    msg = str(e.value)
    assert "monotonic.csv:11" in msg and "slip_mm" in msg and "expected" in msg, msg
    err = cli.run("check", d, ok=False).stderr
    assert msg in err, f"python: {msg}\ncommand: {err}"
    assert isinstance(e.value, Exception)


def test_a_missing_folder_and_a_broken_experiment_json_are_named(copy_set, tmp_path):
    with pytest.raises(subfric.SubfricError, match="no-such-set"):
        subfric.load_set(tmp_path / "no-such-set")
    d = copy_set("table1-rough")
    (d / "experiment.json").write_text('{"name": "x", "tests": [}')
    with pytest.raises(subfric.SubfricError, match=r"experiment\.json:1"):
        subfric.load_set(d)


def test_implausible_data_warn_naming_the_file_and_column(cli, copy_set):
    d = copy_set("table1-smooth")
    csv = d / "monotonic.csv"
    out = []
    for l in csv.read_text().splitlines():
        if l and l[0].isdigit():
            t, u, s = l.split(",")
            l = f"{t},{u},{float(s) * 1000}"  # shear in Pa, not kPa
        out.append(l)
    csv.write_text("\n".join(out) + "\n")
    with pytest.warns(subfric.SubfricWarning) as w:
        s = subfric.load_set(d)
    texts = [str(x.message) for x in w]
    assert any("monotonic.csv" in t and "shear" in t for t in texts), texts
    assert s.warnings == texts
    err = cli.run("check", d).stderr
    for t in texts:
        assert t in err


def test_a_logger_in_mpa_and_minutes_is_read_in_kpa_and_seconds(tmp_path):
    (tmp_path / "experiment.json").write_text(json.dumps({
        "name": "logger", "title": "t", "source": "made in the test",
        "units": {"stress": "MPa", "time": "min"},
        "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}],
    }))
    (tmp_path / "a.csv").write_text("time_s,slip_mm,shear_kpa\n0,0,0\n1,0.5,0.0425\n2,1.0,0.04025\n")
    t = subfric.load_set(tmp_path)[0]
    np.testing.assert_allclose(t.time_s, [0.0, 60.0, 120.0])
    np.testing.assert_allclose(t.shear_kpa, [0.0, 42.5, 40.25])
    assert t.units == {"stress": "MPa", "displacement": None, "time": "min"}
    assert subfric.load_set(EXPERIMENTS / BUNDLED[0])[0].units is None


def test_gaps_a_coarse_clock_and_further_channels_as_the_command_reads_them(tmp_path):
    (tmp_path / "experiment.json").write_text(json.dumps({
        "name": "logger", "title": "t", "source": "made in the test",
        "tests": [{"name": "a", "file": "a.csv", "control": "slip", "normal_stress_kpa": 100}],
    }))
    # A one-second clock at 2 Hz, a lost shear sample, dilation and a temperature with a gap.
    (tmp_path / "a.csv").write_text(
        "time_s,slip_mm,shear_kpa,normal_disp_mm,temperature_c\n"
        "0,0,0,0,20\n0,0.05,NaN,-0.001,20\n1,0.1,10,-0.002,\n1,0.15,15,-0.003,20.2\n2,0.2,20,-0.004,20.3\n"
    )
    with pytest.warns(subfric.SubfricWarning) as caught:
        t = subfric.load_set(tmp_path)[0]
    said = " ".join(str(w.message) for w in caught)
    assert "1 row without a value" in said and "line 3" in said
    assert "repeats its stamp on 1 row" in said
    np.testing.assert_allclose(t.time_s, [0.0, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(t.channels["normal_disp_mm"], [0.0, -0.002, -0.003, -0.004])
    assert np.isnan(t.channels["temperature_c"][1])
