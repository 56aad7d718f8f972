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
    for k in ("chain", "log_density", "predictive_samples", "predictive"):
        del p[k]
    del r["inference_data"]
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


def test_the_posterior_is_an_arviz_inference_data_with_the_chains_the_densities_and_the_predictive():
    import arviz as az

    r, _ = quick_posterior()
    p, data = r["posterior"], r["inference_data"]
    assert isinstance(data, az.InferenceData)
    for g in ("posterior", "sample_stats", "posterior_predictive", "observed_data", "constant_data"):
        assert g in data.groups(), (g, data.groups())
    chain = p["chain"]
    walkers = p["convergence"]["walkers"]
    steps = np.unique(chain["step"])
    # One chain per walker, one draw per thinned step: every sample where the chain puts it.
    for k in FREE:
        assert data.posterior[k].shape == (walkers, len(steps)), k
    for i in range(0, p["chain_samples"], 37):
        at = dict(chain=chain["walker"][i], draw=chain["step"][i])
        assert data.posterior["mu_s"].sel(**at).item() == chain["mu_s"][i]
        assert data.sample_stats["lp"].sel(**at).item() == p["log_density"][i]
    assert np.all(np.isfinite(p["log_density"]))
    # The predictive sample: draws × rows per test, with the noise (wider than the band of the
    # model curve alone), and the data it is compared with.
    c = r["curves"]["monotonic"]
    rows = len(c["time_s"])
    draws = p["predictive"]["monotonic"]
    assert draws.shape == (len(p["predictive_samples"]), rows)
    pp = data.posterior_predictive["monotonic"]
    assert pp.shape == (1, draws.shape[0], rows)
    assert np.array_equal(data.observed_data["monotonic"].values, c["measured"])
    assert np.array_equal(data.constant_data["monotonic_time_s"].values, c["time_s"])
    lo, hi = np.percentile(draws, [2.5, 97.5], axis=0)
    assert np.mean(hi - lo) > 1.5 * np.mean(c["band_hi"] - c["band_lo"])
    inside = np.mean((lo <= c["measured"]) & (c["measured"] <= hi))
    assert inside > 0.8, inside
    # ArviZ's own summaries read it.
    table = az.summary(data, kind="stats")
    assert list(table.index) == FREE


def test_to_inference_data_refuses_a_result_without_a_posterior():
    r = subfric.fit(EXPERIMENTS / "table1-medium", **QUICK)
    assert "inference_data" not in r
    with pytest.raises(subfric.SubfricError, match="no posterior"):
        subfric.to_inference_data(r)
