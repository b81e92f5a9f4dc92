"""The result object: its figures (each drawn from the study's numbers), its JSON, its verdict and report
section; Morris screening through SALib; the main job's quick version."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.structure.model import build_model
from rotorub_model.uncertainty import run_uq, run_uq_quick, study_from_dict

TOL = {"operating": {"speed": 3.3},
       "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": 1e-3, "sd": 0.15e-3},
                  "me": {"parameter": "imbalance.me", "distribution": "lognormal", "mean": 0.022, "sd": 0.005},
                  "mu": {"parameter": "contact.mu", "distribution": "uniform", "low": 0.05, "high": 0.3}}}


def test_montecarlo_result_saves_its_figures_and_json(tmp_path):
    st = study_from_dict({**TOL, "study": {"method": "montecarlo", "n": 128, "replicates": 4, "seed": 2,
                                           "quantities": ["margin", "rub"], "events": ["rub", "margin < 0.2e-3"]}})
    r = run_uq(st, executor="serial", progress=False)
    s = r.save(tmp_path)
    assert r.figures == ["distributions", "rub_vs_clearance"]
    for k in r.figures:
        assert (tmp_path / f"uq_{k}.png").stat().st_size > 10_000
    on_disk = json.loads((tmp_path / "uq_summary.json").read_text())
    assert on_disk["verdict"] == s["verdict"] and s["verdict"].startswith("P(rub) at speed 3.3 Ω_ref (3D) = ")
    p = on_disk["estimates"]["probabilities"]
    assert p["rub"]["probability"] <= p["margin < 0.2e-3"]["probability"]  # the events are nested
    z = np.load(tmp_path / "uq_samples.npz")
    assert z["inputs"].shape == (512, 3) and list(z["input_names"]) == ["g0", "me", "mu"]
    np.testing.assert_array_equal(z["q_rub"], (z["q_margin"] < 0).astype(float))
    md = r.markdown()
    assert "| rub |" in md and "**Verdict:**" in md and "| detection | 512 |" in md
    with pytest.raises(Exception, match="figure: 'sobol' unknown"):
        r.figure("sobol")


def test_morris_ranks_the_imbalance_first_and_friction_last(tmp_path):
    st = study_from_dict({**TOL, "study": {"method": "morris", "n": 20, "seed": 3, "quantities": ["margin"]}})
    r = run_uq(st, executor="serial", progress=False)
    mo = r.estimates["morris"]["margin"]
    assert mo["names"] == ["g0", "me", "mu"]
    ms = np.array(mo["mu_star"])
    assert ms[2] == 0.0  # friction does not move the first contact: no elementary effect at all
    assert ms[1] > ms[0] > 0  # the imbalance (lognormal 22 +- 5 kg mm) before the clearance (+- 0.15 mm)
    r.save(tmp_path)
    assert (tmp_path / "uq_morris.png").exists()


def test_run_uq_quick_gives_a_result_and_a_report_section(tmp_path):
    res, md = run_uq_quick(build_model(), tmp_path)
    assert set(res) == {"tolerances", "mistuning"}
    t = res["tolerances"].estimates["probabilities"]["rub"]
    # the reference's damaged-fan imbalance closes 6 mm at the first critical against a 1 mm clearance: it
    # always rubs, and the curve says how much clearance that imbalance would need
    assert t["probability"] == 1.0 and 0.99 < t["low"] <= t["high"] == 1.0
    # between the closure of the file's imbalance (6.1 mm) and that of its 99.9 % quantile (2.5 x: 15 mm)
    assert 6.1e-3 < res["tolerances"].clearance_for() < 15e-3
    m = res["mistuning"].estimates["mistuning"]["amp_contact"]
    assert m["points"] == 64 and m["pearson"] is not None
    assert md.startswith("## Will it rub?") and md.count("**Verdict:**") == 2
    for name in ("tolerances", "mistuning"):
        assert (tmp_path / name / "uq_summary.json").exists()
    assert (tmp_path / "mistuning" / "uq_mistuning.png").exists()


def test_sobol_takes_the_mistuning_pattern_as_one_index():
    """SALib's groups: the ten blades' coordinates are one index, 'mistuning'. At a fixed point of the rub the
    clearance sets the largest force and the mistuning the contact amplification factor, not the reverse."""
    st = study_from_dict({"study": {"method": "sobol", "n": 64, "seed": 5,
                                    "quantities": ["static_max_force", "amp_contact"]},
                          "operating": {"speed": 3.3},
                          "inputs": {"g0": {"parameter": "contact.g0", "distribution": "uniform", "low": 0.3e-3,
                                            "high": 0.4e-3}},
                          "mistuning": {"kind": "frequency", "sd": 0.02}})
    r = run_uq(st, executor="serial", progress=False)
    assert r.cost["evaluations"] == 64 * 4  # N (groups + 2): two groups
    f, a = r.estimates["sobol"]["static_max_force"], r.estimates["sobol"]["amp_contact"]
    assert f["names"] == a["names"] == ["g0", "mistuning"]
    assert f["ST"][0] > 0.5 and f["ST"][1] < 0.01
    assert a["ST"][1] > 0.5 and a["ST"][0] < 0.01
