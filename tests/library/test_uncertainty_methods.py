"""The pipeline on known answers: Sobol' indices of the Ishigami function, a rub probability with a closed
form, the Monte Carlo interval shrinking as 1/sqrt(N), FORM and subset sampling on a small probability.

Every study here goes through the same code as a user's: the study dict, the design, the executor
(analyses/sweeps.run_tasks), the evaluations and the libraries' analyses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import norm

from rotorub_model.analyses.detection import closure, linear_responses
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model
from rotorub_model.uncertainty import run_uq, study_from_dict

SPEED = 3.3


@pytest.fixture(scope="module")
def c_closure():
    """The deterministic 3D closure at SPEED (analyses/detection.py, independently of the study)."""
    m = build_model()
    return float(closure(make_contact(m, "3D"), linear_responses(m, np.array([SPEED * 53.4])))[0])


def ishigami_truth(a: float = 7.0, b: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    pi = math.pi
    v1 = 0.5 * (1 + b * pi**4 / 5) ** 2
    v2 = a * a / 8
    v13 = b * b * pi**8 * (1 / 18 - 1 / 50)
    v = v1 + v2 + v13
    return np.array([v1, v2, 0.0]) / v, np.array([v1 + v13, v2, v13]) / v


def test_ishigami_sobol_indices_within_their_intervals(tmp_path):
    """SALib's sampling, our executor (a process pool), SALib's analysis: every known index inside the
    estimate's 95 % bootstrap interval, and the intervals narrow enough to mean something."""
    u = {"distribution": "uniform", "low": -math.pi, "high": math.pi}
    st = study_from_dict({"study": {"model": "ishigami", "method": "sobol", "n": 4096, "seed": 7},
                          "inputs": {"x1": u, "x2": u, "x3": u}})
    r = run_uq(st, executor=None, out=tmp_path, progress=False)
    si = r.estimates["sobol"]["y"]
    s1, st_ = ishigami_truth()
    assert si["names"] == ["x1", "x2", "x3"]
    for est, conf, true in ((si["S1"], si["S1_conf"], s1), (si["ST"], si["ST_conf"], st_)):
        est, conf = np.array(est), np.array(conf)
        assert np.all(conf < 0.06), conf
        assert np.all(np.abs(est - true) <= conf), (est, conf, true)
    assert r.cost["evaluations"] == 4096 * 5 and r.cost["tasks"] >= 8


def test_rub_probability_against_the_closed_form(c_closure):
    """A normal clearance against the deterministic closure c: P(rub) = Phi((c - mu) / sigma). A 95 % interval
    misses the truth in 5 % of the seeds by design, so its coverage is what is checked: over 20 seeds at least
    17 intervals hold the exact probability (a binomial 95 % coverage falls below 17 of 20 with probability
    1.6 %), for randomised QMC and for plain Monte Carlo's Wilson interval; QMC's intervals are narrower."""
    mu, sd = 1.0e-3, 0.15e-3
    exact = norm.cdf((c_closure - mu) / sd)
    assert 0.05 < exact < 0.2
    base = {"operating": {"speed": SPEED},
            "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": mu, "sd": sd},
                       # friction does not move the first contact: a second coordinate the margin ignores
                       "mu": {"parameter": "contact.mu", "distribution": "uniform", "low": 0.05, "high": 0.3}}}
    width = {}
    for sampler, n in (("qmc", 256), ("mc", 2048)):
        hits, w = 0, []
        for seed in range(20):
            st = study_from_dict({**base, "study": {"method": "montecarlo", "sampler": sampler, "n": n,
                                                    "replicates": 8, "quantities": ["margin", "rub"], "seed": seed}})
            r = run_uq(st, executor="serial", progress=False)
            p = r.estimates["probabilities"]["rub"]
            hits += p["low"] <= exact <= p["high"]
            w.append(p["high"] - p["low"])
        assert hits >= 17, (sampler, hits)
        width[sampler] = float(np.mean(w))
    assert width["qmc"] < width["mc"]  # the same 2048 points: QMC's interval the narrower
    # the clearance curve is the same closed form shifted: Phi((c - g) / sigma) at every build clearance g
    cc = r.estimates["clearance_curve"]
    g = np.asarray(cc["build_clearance_m"])
    truth = norm.cdf((c_closure - g) / sd)
    inside = (np.asarray(cc["low"]) <= truth) & (truth <= np.asarray(cc["high"]))
    assert inside.mean() >= 0.85  # pointwise 95 % intervals on one sample: most points hold the truth
    assert np.max(np.abs(np.asarray(cc["probability"]) - truth)) < 0.03


def test_monte_carlo_interval_shrinks_as_one_over_root_n(c_closure):
    """Plain Monte Carlo: the interval's half-width times sqrt(N) stays put from 512 to 32768 points (slope
    -1/2 in log-log), and every interval holds the exact probability."""
    mu, sd = 1.0e-3, 0.15e-3
    exact = norm.cdf((c_closure - mu) / sd)
    ns = [512, 2048, 8192, 32768]
    half = []
    for n in ns:
        st = study_from_dict({"study": {"method": "montecarlo", "sampler": "mc", "n": n, "quantities": ["rub"],
                                        "seed": 11},
                              "operating": {"speed": SPEED},
                              "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": mu,
                                                "sd": sd}}})
        p = run_uq(st, executor="serial", progress=False).estimates["probabilities"]["rub"]
        assert p["low"] <= exact <= p["high"]
        half.append(0.5 * (p["high"] - p["low"]))
    slope = np.polyfit(np.log(ns), np.log(half), 1)[0]
    assert slope == pytest.approx(-0.5, abs=0.05)
    scaled = np.array(half) * np.sqrt(ns)
    assert scaled.max() / scaled.min() < 1.15
    # and the width is the binomial one: z sqrt(p (1 - p) / N)
    assert half[-1] == pytest.approx(norm.ppf(0.975) * math.sqrt(exact * (1 - exact) / ns[-1]), rel=0.1)


def test_form_is_exact_for_a_linear_limit_state_in_normal_inputs(c_closure, tmp_path):
    """margin = g0 - closure - c: linear in two normals, FORM's Phi(-beta) is the exact probability and its
    importance factors the variance shares; a probability of 1e-6 that Monte Carlo could not see. (The
    closure's accepted range is bounded: its normal is truncated at 10 sd, which moves nothing here.)"""
    pytest.importorskip("openturns", reason="FORM needs the uq extra's OpenTURNS (pip install 'rotorub[uq]')")
    mg, sg, md, sdl = 2.4e-3, 0.2e-3, 0.3e-3, 0.15e-3
    exact = norm.cdf((c_closure - mg + md) / math.hypot(sg, sdl))
    assert 1e-7 < exact < 1e-5
    st = study_from_dict({"study": {"method": "form", "events": ["rub"], "seed": 1},
                          "operating": {"speed": SPEED},
                          "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": mg, "sd": sg},
                                     "closure": {"parameter": "engine.closure", "distribution": "truncnormal",
                                                 "mean": md, "sd": sdl, "low": md - 10 * sdl, "high": md + 10 * sdl}}})
    r = run_uq(st, executor="serial", out=tmp_path, progress=False)
    sp = r.estimates["small_probability"]
    assert sp["probability"] == pytest.approx(exact, rel=1e-4)
    np.testing.assert_allclose(sp["importance_factors"], [sg**2, sdl**2] / np.float64(sg**2 + sdl**2), atol=1e-4)
    assert sp["evaluations"] < 1000  # Monte Carlo: ~1e8 points for a 20 % interval


def test_subset_sampling_holds_a_small_probability_in_its_interval(c_closure):
    pytest.importorskip("openturns", reason="subset sampling needs the uq extra's OpenTURNS "
                                            "(pip install 'rotorub[uq]')")
    mu, sd = 1.5e-3, 0.15e-3
    exact = norm.cdf((c_closure - mu) / sd)
    assert 1e-6 < exact < 1e-4
    st = study_from_dict({"study": {"method": "subset", "n": 2000, "events": ["rub"], "seed": 5},
                          "operating": {"speed": SPEED},
                          "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": mu, "sd": sd},
                                     "angle": {"parameter": "imbalance.angle_deg", "distribution": "uniform",
                                               "low": 0.0, "high": 360.0}}})
    sp = run_uq(st, executor="serial", progress=False).estimates["small_probability"]
    assert sp["low"] <= exact <= sp["high"], (sp, exact)
    assert sp["evaluations"] < 20000  # Monte Carlo would need ~1e7 points for a 20 % interval
