"""simulate: the same model as `subfric simulate`, row for row."""

import json
import threading
import time

import numpy as np
import pytest

import subfric
from conftest import BUNDLED, EXPERIMENTS

SCENARIOS = {
    # slip control: a slide, a hold, a slide, two-way cycles
    "table1-medium": {
        "name": "shs",
        "control": "slip",
        "normal_stress_kpa": 78.4,
        "dt_s": 0.5,
        "stages": [
            {"type": "slide", "rate_mm_s": 0.01, "distance_mm": 2},
            {"type": "hold", "duration_s": 100},
            {"type": "slide", "rate_mm_s": 0.01, "distance_mm": 1},
            {"type": "cycles", "amplitude_mm": 1, "rate_mm_s": 0.01, "count": 2},
        ],
    },
    # traction control: pulsating loading below the friction capacity
    "table3-pulsating": {
        "name": "puls",
        "control": "shear",
        "normal_stress_kpa": 100,
        "dt_s": 0.5,
        "stages": [{"type": "pulsating", "max_kpa": 30, "period_s": 60, "count": 3}],
    },
}


@pytest.mark.parametrize("set_name", sorted(SCENARIOS))
def test_simulate_gives_the_command_s_scenario_output_exactly(set_name, cli, tmp_path):
    sc = tmp_path / "sc.json"
    sc.write_text(json.dumps(SCENARIOS[set_name]))
    params = EXPERIMENTS / set_name / "experiment.json"
    cli.run("simulate", "--scenario", sc, "--params", params, "--out", tmp_path / "out")
    out = subfric.load_set(tmp_path / "out")
    (t,) = out.tests
    assert len(t) > 100
    ref = json.load(open(params))["reference_parameters"]
    for p in (ref, params, str(params)):  # a dict, a path, a str
        predicted, mu, r = subfric.simulate(p, t.time_s, t.imposed, t.normal_kpa, t.control)
        # The program writes every number with the digits that read back to the same double.
        np.testing.assert_array_equal(predicted, t.measured)
        assert mu.shape == r.shape == predicted.shape
        assert np.all((r >= 0) & (r <= 1))
        assert np.all((mu >= ref["mu_k"] - 1e-12) & (mu <= ref["mu_s"] + 1e-12))
    # One number for the normal stress of every row; a list; NumPy scalars among the parameters.
    p2, _, _ = subfric.simulate(ref, t.time_s, list(t.imposed), float(t.normal_kpa[0]), t.control)
    np.testing.assert_array_equal(p2, t.measured)
    ref_np = {k: (np.float64(v) if isinstance(v, float) else v) for k, v in ref.items()}
    ref_np["alpha_t"] = np.int64(ref["alpha_t"])
    p3, _, _ = subfric.simulate(ref_np, t.time_s, t.imposed, t.normal_kpa, t.control)
    np.testing.assert_array_equal(p3, t.measured)


@pytest.mark.parametrize("name", BUNDLED)
def test_simulate_follows_the_command_on_the_bundled_sets(name, cli, tmp_path):
    """`subfric simulate <set>` drives the model with the imposed column as it conditions it
    (reversals found with a hysteresis, isotonic within monotone runs, holds flat); on these
    reconstructed curves that changes the imposed slip only in its last digits, so the command
    and the package agree to 1e-8 of the curve's scale. Both reproduce the published curves at
    their noise level (0.3 %)."""
    params = EXPERIMENTS / name / "experiment.json"
    cli.run("simulate", EXPERIMENTS / name, "--params", params, "--out", tmp_path / "sim")
    sim = subfric.load_set(tmp_path / "sim")
    data = subfric.load_set(EXPERIMENTS / name)
    for t, s in zip(data, sim):
        predicted, mu, r = subfric.simulate(
            data.reference_parameters, t.time_s, t.imposed, t.normal_kpa, t.control,
            initial_slip=t.slip_mm[0],
        )
        scale = np.max(np.abs(t.measured))
        gap = np.max(np.abs(predicted - s.measured)) / scale
        assert gap < 1e-8, f"{name}/{t.name}: {gap:.2e} of the scale from the command's curve"
        noise = np.sqrt(np.mean((predicted - t.measured) ** 2)) / scale
        assert 0.002 < noise < 0.004, f"{name}/{t.name}: {noise:.2e} of the scale from the data"


def test_bad_input_names_the_row_and_field():
    p = json.load(open(EXPERIMENTS / "table1-medium" / "experiment.json"))["reference_parameters"]
    t = np.array([0.0, 1.0, 1.0, 2.0])
    with pytest.raises(subfric.SubfricError, match=r"row 2: field `time_s`"):
        subfric.simulate(p, t, [0, 0.01, 0.02, 0.03], 100)
    with pytest.raises(subfric.SubfricError, match=r"field `imposed`: column has 2 rows"):
        subfric.simulate(p, [0, 1, 2], [0, 0.01], 100)
    with pytest.raises(subfric.SubfricError, match=r"normal_kpa"):
        subfric.simulate(p, [0, 1, 2], [0, 0.01, 0.02], [100, 0, 100])
    with pytest.raises(subfric.SubfricError, match=r"mu_k = 0\.9 \(expected"):
        subfric.simulate(dict(p, mu_k=0.9), [0, 1], [0, 0.01], 100)
    with pytest.raises(subfric.SubfricError, match=r"field `kappa` is missing"):
        subfric.simulate({k: v for k, v in p.items() if k != "kappa"}, [0, 1], [0, 0.01], 100)
    with pytest.raises(subfric.SubfricError, match=r"control: unknown control `sideways`"):
        subfric.simulate(p, [0, 1], [0, 0.01], 100, control="sideways")
    with pytest.raises(subfric.SubfricError, match=r"runaway sliding"):
        subfric.simulate(p, [0, 1, 2], [0, 10, 200], 100, control="shear")
    with pytest.raises(subfric.SubfricError, match=r"no-such\.json"):
        subfric.simulate("no-such.json", [0, 1], [0, 0.01], 100)
    with pytest.raises(subfric.SubfricError, match="initial"):
        subfric.simulate(p, [0, 1], [0, 0.01], 100, initial={"kind": "flying"})


def test_a_sliding_start_and_a_loaded_start():
    p = json.load(open(EXPERIMENTS / "table1-medium" / "experiment.json"))["reference_parameters"]
    t = np.linspace(0, 10, 11)
    u = 0.01 * t
    rest, _, r0 = subfric.simulate(p, t, u, 100, initial="rest")
    plain, _, _ = subfric.simulate(p, t, u, 100)
    np.testing.assert_array_equal(rest, plain)
    assert rest[0] == 0 and r0[0] == 0
    sl, mu, r = subfric.simulate(p, t, u, 100, initial={"kind": "sliding", "shear_kpa": 31.0, "rate_mm_s": 0.01})
    assert sl[0] == 31.0 and r[0] == 1.0
    ld, _, r = subfric.simulate(p, t, u, 100, initial={"kind": "loaded", "shear_kpa": 10.0})
    assert ld[0] == 10.0 and 0 < r[0] < 1


def test_a_long_simulation_releases_the_gil():
    p = json.load(open(EXPERIMENTS / "table1-medium" / "experiment.json"))["reference_parameters"]
    n = 3_000_000
    t = np.arange(n, dtype=float) * 0.01
    u = 0.5 * np.sin(2 * np.pi * t / 200)
    done = {}
    th = threading.Thread(target=lambda: done.setdefault("r", subfric.simulate(p, t, u, 100)))
    ticks = 0
    t0 = time.perf_counter()
    th.start()
    while th.is_alive():
        ticks += 1
        time.sleep(0.001)
    elapsed = time.perf_counter() - t0
    assert len(done["r"][0]) == n
    # With the GIL held the loop could not run while the model steps.
    assert elapsed > 0.05 and ticks > 10, f"{ticks} ticks in {elapsed:.2f} s"


# Issue 25, items 7 and 8: a start or a slip the model cannot take raises, naming the argument,
# what was given and what is allowed, instead of returning NaN, inf or a wrong number.


def _table1():
    return json.load(open(EXPERIMENTS / "table1-medium" / "experiment.json"))["reference_parameters"]


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), float("-inf")])
@pytest.mark.parametrize("control", ["shear", "slip"])
def test_a_non_finite_initial_slip_raises_naming_it(bad, control):
    imposed = [0.0, 10.0, 20.0] if control == "shear" else [0.0, 0.01, 0.02]
    with pytest.raises(subfric.SubfricError, match=r"`initial_slip`: expected a finite slip") as e:
        subfric.simulate(_table1(), [0, 1, 2], imposed, 100, control, initial_slip=bad)
    assert str(bad) in str(e.value).lower()


@pytest.mark.parametrize(
    "initial, field, said",
    [
        # mu_s = 0.37 at 100 kPa: a capacity of 37 kPa.
        ({"kind": "loaded", "shear_kpa": 1000.0}, "initial.shear_kpa", "capacity 37.0"),
        ({"kind": "sliding", "shear_kpa": 1e308, "rate_mm_s": 1.0}, "initial.shear_kpa", "capacity"),
        ({"kind": "sliding", "shear_kpa": 30.0, "rate_mm_s": -1.0}, "initial.rate_mm_s", ">= 0"),
        ({"kind": "sliding", "shear_kpa": 30.0, "rate_mm_s": float("nan")}, "initial.rate_mm_s", "finite"),
        ({"kind": "sliding", "shear_kpa": float("inf"), "rate_mm_s": 0.01}, "initial.shear_kpa", "finite"),
        ({"kind": "loaded", "shear_kpa": float("nan")}, "initial.shear_kpa", "finite"),
    ],
)
def test_a_start_the_model_cannot_hold_raises_with_what_is_allowed(initial, field, said):
    t = np.linspace(0, 10, 11)
    with pytest.raises(subfric.SubfricError) as e:
        subfric.simulate(_table1(), t, 0.01 * t, 100, initial=initial)
    message = str(e.value)
    # Non-finite numbers are refused as the dict is read (`initial["shear_kpa"]: nan`), the
    # others by the model (`field `initial.shear_kpa``): the key is named either way.
    key = field.split(".")[1]
    assert key in message and said in message and "expected" in message, message


def test_a_slip_far_from_the_origin_gives_the_shifted_shear_or_raises_naming_the_row():
    """The model depends on slip differences only; where doubles are too far apart to carry the
    elastic slip (Table 1's 2000 kN/mm^3: 1.5e-8 mm at its capacity) it must refuse, not
    answer 0 kPa for 23.5."""
    p = _table1()
    # Loading, elastic unloading by 2e-9 mm (4 kPa) steps, sliding back.
    d = np.concatenate([np.arange(0, 0.05, 1e-4), 0.05 - 2e-9 * np.arange(1, 7), 0.05 - 1e-4 * np.arange(1, 300)])
    t = np.arange(len(d), dtype=float)
    near, _, _ = subfric.simulate(p, t, d, 78.4)
    tolerance = 2 * 1e-3 * p["mu_s"] * 78.4
    for origin in [1e3, 1e9, 1e11]:
        try:
            far, _, _ = subfric.simulate(p, t, origin + d, 78.4)
        except subfric.SubfricError as e:
            assert origin > 1e3, f"{origin:g}: {e}"
            assert "row 0: field `imposed`" in str(e) and "subtract a constant" in str(e), str(e)
            continue
        assert origin == 1e3, f"origin {origin:g} mm computed instead of refused"
        assert np.max(np.abs(far - near)) <= tolerance
