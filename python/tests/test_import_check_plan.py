"""import_file, check, plan and plot: the same files and words as `subfric import`, `check`,
`plan` and `plot`, on lab files each test writes."""

import math
import os

import pytest

import subfric
from conftest import EXPERIMENTS


def gds_ini(path):
    """A GDS .ini export: an aborted 5-row stage, then the real one; a rate without a unit."""
    stage, h, v, f = [], [], [], []
    for i in range(5):
        stage.append("1"), h.append(f"{0.01 * i:.3f}"), v.append("0"), f.append(f"{0.05 * i:.4f}")
    for i in range(120):
        x = 0.05 * i
        stage.append("2")
        h.append(f"{x:.3f}")
        v.append(f"{0.2 * (1 - math.exp(-x / 2)):.4f}")
        f.append(f"{0.216 * (1 - math.exp(-x / 0.4)):.4f}")
    n = len(stage)
    path.write_text(
        "[Test Data]\nArea=\"3600\"\nRate=\"0.5\"\n"
        f"Stage Number=\"{','.join(stage)}\"\nHorizontal Displacement=\"{','.join(h)}\"\n"
        f"Vertical Displacement=\"{','.join(v)}\"\nShear Force=\"{','.join(f)}\"\n"
        f"Normal Stress=\"{','.join(['100'] * n)}\"\n"
    )
    return path


def test_import_file_reads_a_gds_export_as_the_command_does(cli, tmp_path):
    lab = gds_ini(tmp_path / "DS-1.ini")
    # The rate states no unit and the file has no time: refused, naming the rate's line.
    with pytest.raises(subfric.SubfricError, match=r"DS-1.ini:3: field `Rate`.*rate_unit|--rate-unit"):
        subfric.import_file(lab, tmp_path / "refused")
    assert not (tmp_path / "refused").exists()
    # Delimiter and control read by the words the command takes, and refused with them.
    with pytest.raises(subfric.SubfricError, match=r"delimiter: unknown delimiter `pipe` \(expected comma"):
        subfric.import_file(lab, tmp_path / "refused", rate_unit="mm/min", delimiter="pipe")
    with pytest.raises(subfric.SubfricError, match=r"control: unknown control `torque` \(expected `slip` or `shear`\)"):
        subfric.import_file(lab, tmp_path / "refused", rate_unit="mm/min", control="torque")
    assert not (tmp_path / "refused").exists()
    with pytest.warns(subfric.SubfricWarning, match="stage 2 is kept, the one with the longest shear travel"):
        s = subfric.import_file(lab, tmp_path / "py", test_name="ds1", rate_unit="mm/min")
    t = s["ds1"]
    assert len(t) == 120 and t.time_s[1] == pytest.approx(6.0)
    assert list(t.channels) == ["normal_disp_mm", "shear_force_kn"]
    cli.run("import", lab, "--out", tmp_path / "cli", "--test-name", "ds1", "--rate-unit", "mm/min")
    assert (tmp_path / "py" / "ds1.csv").read_text() == (tmp_path / "cli" / "ds1.csv").read_text()


def test_check_returns_the_command_s_table_and_its_warnings(cli, tmp_path):
    r = subfric.check(EXPERIMENTS / "table1-medium")
    out = cli.run("check", EXPERIMENTS / "table1-medium").stdout
    assert r["text"].strip() in out
    assert r["summary"]["name"] == "table1-medium"
    assert isinstance(r["artifacts"], list) and isinstance(r["warnings"], list)
    with pytest.raises(subfric.SubfricError, match="does not exist"):
        subfric.check(tmp_path / "nowhere")


def test_plan_returns_what_the_command_writes_to_plan_json(cli, tmp_path):
    r = subfric.plan(EXPERIMENTS / "table1-medium", out=tmp_path / "py", check=0)
    cli.run("plan", EXPERIMENTS / "table1-medium", "--out", tmp_path / "cli", "--check", "0")
    written = cli.json(tmp_path / "cli" / "plan.json")
    assert {k: v for k, v in r.items() if k != "text"} == written
    assert r["text"].startswith("verdict: ")
    narrows = [p["narrows"] for p in r["plan"]["proposals"]]
    # Those that narrow nothing come last.
    assert narrows == sorted(narrows, reverse=True)


def test_plot_writes_the_figures_the_command_writes(cli, tmp_path):
    files = subfric.plot(EXPERIMENTS / "table1-medium", out=tmp_path / "py")
    cli.run("plot", EXPERIMENTS / "table1-medium", "--out", tmp_path / "cli")
    names = sorted(os.path.basename(f) for f in files)
    assert names and all(n.endswith(".png") for n in names)
    assert names == sorted(p.name for p in (tmp_path / "cli").glob("*.png"))
    for f in files:
        assert open(f, "rb").read(8) == b"\x89PNG\r\n\x1a\n"
        assert os.path.exists(f[: -len(".png")] + ".svg")
    # The same figure, drawn by the same code: the SVGs are identical.
    for n in names:
        stem = n[: -len(".png")]
        assert (tmp_path / "py" / f"{stem}.svg").read_text() == (tmp_path / "cli" / f"{stem}.svg").read_text()
    with pytest.raises(subfric.SubfricError, match="does not exist"):
        subfric.plot(tmp_path / "nowhere")
