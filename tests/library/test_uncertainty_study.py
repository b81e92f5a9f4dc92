"""The study file: the example reads, and every kind of bad input is one line naming the key, before any work
(the CLI: exit code 2, nothing written)."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from rotorub_model.app.cli import main
from rotorub_model.errors import ParameterError
from rotorub_model.uncertainty import EXAMPLE_STUDY, load_study, study_from_dict
from rotorub_model.uncertainty.distributions import make_distribution

BASE = {"study": {"method": "montecarlo", "n": 64, "replicates": 4, "quantities": ["margin", "rub"]},
        "operating": {"speed": 3.3},
        "inputs": {"g0": {"parameter": "contact.g0", "distribution": "normal", "mean": 1e-3, "sd": 1e-4}}}


def with_(path: str, value):
    d = copy.deepcopy(BASE)
    *head, last = path.split(".")
    t = d
    for k in head:
        t = t.setdefault(k, {})
    if value is None:
        t.pop(last, None)
    else:
        t[last] = value
    return d


def test_example_study_reads():
    s = load_study(EXAMPLE_STUDY)
    assert s.method == "montecarlo" and s.speed == "first_critical"
    assert [i.target.name for i in s.inputs] == ["contact.g0", "imbalance.me", "imbalance.angle_deg",
                                                 "engine.closure", "engine.offset", "contact.mu"]
    assert {q.name: q.level for q in s.quantities} == {"margin": "detection", "rub": "detection"}


def test_distributions_are_scipys():
    d = make_distribution("x", {"distribution": "lognormal", "mean": 3e-3, "sd": 1.5e-3})
    assert d.mean == pytest.approx(3e-3) and d.variance == pytest.approx(1.5e-3**2)
    t = make_distribution("x", {"distribution": "triangular", "low": 0, "mode": 1, "high": 4})
    # the ends are kept 1e-12 inside the unit interval
    assert t.ppf(np.array([0.0, 0.5, 1.0])).tolist() == pytest.approx([0.0, 4 - 6**0.5, 4.0], abs=1e-5)
    assert t.mean == pytest.approx(5 / 3)


@pytest.mark.parametrize("data, message", [
    (with_("inputs.mu", {"parameter": "contact.mu", "distribution": "normal", "mean": 0.12, "sd": 0.03}),
     r"inputs.mu: a normal distribution has support \(-inf, inf\), which leaves the accepted range of contact.mu, "
     r"\[0, 1\]"),
    (with_("inputs.kr", {"parameter": "contact.k_r", "distribution": "uniform", "low": -1e5, "high": 2e6}),
     r"leaves the accepted range of contact.k_r, \[1000, 1e\+10\]"),
    (with_("inputs.me", {"parameter": "imbalance.me", "distribution": "lognormal", "mean": 1e-3, "sd": 1e-3}), None),
    (with_("inputs.g0.parameter", "contact.gap"), r"inputs.g0.parameter: 'contact.gap': unknown parameter; accepted "
                                                  r"fields here: .*g0"),
    (with_("inputs.g0.parameter", "rotor.g0"), r"'rotor.g0' unknown; accepted: section.field"),
    (with_("inputs.g0.parameter", "bearings.middle.k"), r"no bearing named 'middle'; accepted: front, rear"),
    (with_("inputs.g0.parameter", "blades.count"), r"not a real-valued parameter"),
    (with_("inputs.g0.parameter", "engine.ovalization"), r"not available: the casing's distortion"),
    (with_("inputs.g0.distribution", "gauss"), r"inputs.g0.distribution: 'gauss' unknown; accepted: normal, "
                                               r"truncnormal, uniform, lognormal, triangular, fixed"),
    (with_("inputs.g0.sd", 0.0), r"inputs.g0.sd: 0 out of range; accepted range \(0, inf\)"),
    (with_("inputs.g0.sigma", 1.0), r"inputs.g0.sigma: unknown key"),
    (with_("study.method", "lhs"), r"study.method: 'lhs' unknown"),
    (with_("study.quantities", ["margin", "stress"]), r"study.quantities: 'stress' unknown"),
    (with_("study.events", ["peak_force >> 3"]), r"not understood"),
    (with_("study.replicates", 1), r"study.replicates: 1; a randomised-QMC interval needs at least 2"),
    (with_("study.n", 1000), r"study.n: 1000; the qmc sampler takes a power of 2"),
    (with_("study.quantiles", [0.999]), r"study.n: 256 points are too few for a 0.95 interval of the 0.999 quantile"),
    (with_("operating.speed", 40.0), r"operating.speed: 40.0 out of range"),
    (with_("operating.speeds", [3.0, 4.0]), r"operating: give one of speed"),
    (with_("study.quantities", ["amp_linear"]), r"add a \[mistuning\] table"),
    (with_("inputs.off", {"parameter": "engine.offset", "distribution": "uniform", "low": 0, "high": 1e-4})
     | {"study": {**BASE["study"], "quantities": ["static_max_force"]}}, r"engine.offset .* no static solution"),
    (with_("mistuning", {"kind": "frequency", "sd": 0.02, "distribution": "normal"}),
     r"mistuning.distribution: normal has support"),
    (with_("mistuning", {"sd": 0.02, "correlation": 1.5}), r"mistuning.correlation: 1.5 out of range"),
])
def test_bad_input_is_one_line(data, message):
    if message is None:  # a lognormal is positive: within imbalance.me's [0, inf)
        study_from_dict(data)
        return
    with pytest.raises(ParameterError, match=message) as e:
        study_from_dict(data)
    assert "\n" not in str(e.value)


def test_sobol_refuses_zero_variance_and_small_samples():
    d = {"study": {"method": "sobol", "n": 256, "quantities": ["margin"]}, "operating": {"speed": 3.3},
         "inputs": {"g0": BASE["inputs"]["g0"], "mu": {"parameter": "contact.mu", "distribution": "fixed",
                                                       "value": 0.12}}}
    with pytest.raises(ParameterError, match=r"inputs.mu: zero variance .* a Sobol' index of an input that does not "
                                             r"vary is undefined"):
        study_from_dict(d)
    d["inputs"].pop("mu")
    d["study"]["n"] = 32
    with pytest.raises(ParameterError, match=r"study.n: 32; Sobol' indices take a base sample N that is a power of 2, "
                                             r"at least 64"):
        study_from_dict(d)


def test_form_without_a_limit_state_is_refused():
    pytest.importorskip("openturns", reason="the form method needs the uq extra's OpenTURNS")
    d = with_("study", {"method": "form", "quantities": ["static_unstable"]})
    with pytest.raises(ParameterError, match=r"form needs a limit state"):
        study_from_dict(d)


def test_cli_bad_study_exit_2_one_line_nothing_written(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text('[study]\nmethod = "sobol"\nn = 128\nquantities = ["margin"]\n[operating]\nspeed = 3.3\n'
                 '[inputs.mu]\nparameter = "contact.mu"\ndistribution = "fixed"\nvalue = 0.1\n'
                 '[inputs.g0]\nparameter = "contact.g0"\ndistribution = "uniform"\nlow = 0\nhigh = 1e-3\n')
    out = tmp_path / "out"
    assert main(["uq", str(f), "--out", str(out), "--executor", "dask"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rotorub uq: error: bad.toml: inputs.mu: zero variance") and "\n" not in err
    assert not out.exists()
    f.write_text("[study\n")
    assert main(["uq", str(f), "--out", str(out)]) == 2
    assert "not valid TOML" in capsys.readouterr().err
    assert not out.exists()


def test_parameter_file_next_to_the_study_and_the_cli_override(tmp_path):
    from rotorub_model.structure.params import reference_parameters, to_toml

    (tmp_path / "engine.toml").write_text(to_toml(reference_parameters().replace(contact={"mu": 0.3})))
    (tmp_path / "other.toml").write_text(to_toml(reference_parameters().replace(contact={"mu": 0.2})))
    f = tmp_path / "study.toml"
    f.write_text('[study]\nparams = "engine.toml"\nn = 16\nreplicates = 2\nquantiles = [0.5]\n'
                 '[operating]\nspeed = 3.3\n[inputs.g0]\nparameter = "contact.g0"\ndistribution = "uniform"\n'
                 'low = 0.5e-3\nhigh = 1e-3\n')
    assert load_study(f).params.contact.mu == 0.3
    assert load_study(f, params=tmp_path / "other.toml").params.contact.mu == 0.2
    (tmp_path / "engine.toml").unlink()
    with pytest.raises(ParameterError, match=r"engine.toml': cannot be read"):
        load_study(f)
