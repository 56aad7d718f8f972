"""fit(..., posterior=True): the posterior of `subfric fit --posterior`, its chain and bands as
arrays, the not-converged warning, and the prior file's errors as SubfricError."""

import numpy as np
import pytest

import subfric
from conftest import EXPERIMENTS

# A fit and a budget small enough for a test (the sampler cannot converge in 3000 runs).
QUICK = dict(global_evals=100, starts=2, profiles=False)
BUDGET = 3000
FREE = ["mu_s", "mu_k", "kappa", "xi", "u_tilde"]


def quick_posterior(name="table1-medium", **kw):
    with pytest.warns(subfric.SubfricWarning, match="NOT converged") as caught:
        r = subfric.fit(EXPERIMENTS / name, posterior=True, max_evals=BUDGET, **QUICK, **kw)
    return r, [str(w.message) for w in caught]


def test_the_posterior_is_what_the_command_writes_plus_its_chain_and_bands(cli, tmp_path):
    r, warned = quick_posterior()
    p = r["posterior"]
    # Not converged in so few runs: said in the result and as a warning naming max_evals.
    assert p["converged"] is False
    need = p["max_evals_needed"]
    assert need > BUDGET
    assert any(f"max_evals={need}" in w for w in warned), warned
    # The summary beside the profile intervals, as fit.json has it.
    assert [s["name"] for s in p["summary"]] == FREE == p["parameters"]
    for s in p["summary"]:
        assert s["lo"] <= s["median"] <= s["hi"]
        assert "profile_interval" in s and "identifiability" in s
    assert np.allclose(np.diag(np.array(p["correlation"])), 1.0)
    # The thinned chain as arrays, the columns of posterior-chain.csv.
    chain = p["chain"]
    assert list(chain) == ["step", "walker", *FREE]
    n = p["chain_samples"]
    for k, a in chain.items():
        assert isinstance(a, np.ndarray) and a.shape == (n,), k
    assert chain["step"].dtype.kind == "i" and chain["walker"].max() < p["convergence"]["walkers"]
    assert np.all(chain["mu_k"] <= chain["mu_s"])
    # A band per test around the posterior median, row by row.
    c = r["curves"]["monotonic"]
    rows = len(c["time_s"])
    for k in ("band_lo", "band_median", "band_hi"):
        assert c[k].shape == (rows,), k
    assert np.all(c["band_lo"] <= c["band_median"]) and np.all(c["band_median"] <= c["band_hi"])
    # The same as the command's fit.json, chain and curves aside.
    out = tmp_path / "cli"
    cli.run(
        "fit", EXPERIMENTS / "table1-medium", "--global-evals", 100, "--starts", 2,
        "--no-profiles", "--posterior", "--max-evals", BUDGET, "--out", out,
    )
    written = cli.json(out / "fit.json")
    del p["chain"]
    assert {k: v for k, v in r.items() if k != "curves"} == written


def test_a_prior_file_is_used_and_its_errors_are_located(tmp_path):
    good = tmp_path / "priors.toml"
    good.write_text('[kappa]\ndist = "log-uniform"\nlo = 20\nhi = 50\n')
    r, _ = quick_posterior(priors=good)
    kappa = r["posterior"]["summary"][2]
    assert kappa["prior"] == "log-uniform(20, 50) (given)"
    assert np.all((r["posterior"]["chain"]["kappa"] >= 20) & (r["posterior"]["chain"]["kappa"] <= 50))
    bad = tmp_path / "bad.json"
    bad.write_text('{"kappa": {"dist": "uniform", "lo": 5, "hi": 1},\n "xi": {"dist": "gamma"}}\n')
    with pytest.raises(subfric.SubfricError) as e:
        subfric.fit(EXPERIMENTS / "table1-medium", posterior=True, priors=bad, **QUICK)
    msg = str(e.value)
    assert f"{bad}:1: field `kappa" in msg and f"{bad}:2: field `xi.dist`" in msg, msg
    with pytest.raises(subfric.SubfricError, match="cannot read the prior file"):
        subfric.fit(EXPERIMENTS / "table1-medium", posterior=True, priors=tmp_path / "no.toml")


def test_posterior_options_without_the_posterior_or_with_bad_values_are_refused():
    s = EXPERIMENTS / "table1-medium"
    with pytest.raises(subfric.SubfricError, match="priors, max_evals: options of the posterior"):
        subfric.fit(s, priors="p.toml", max_evals=1000, **QUICK)
    with pytest.raises(subfric.SubfricError, match="residuals: unknown residual model `gaussian`"):
        subfric.fit(s, posterior=True, residuals="gaussian", **QUICK)
    with pytest.raises(subfric.SubfricError, match="expected at least 64"):
        subfric.fit(s, posterior=True, max_evals=10, **QUICK)
