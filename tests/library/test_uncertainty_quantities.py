"""Each quantity against the analysis it claims to come from, called directly (uncertainty/evaluate.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from rotorub_model.analyses.detection import closure, linear_responses
from rotorub_model.analyses.static import solve_static
from rotorub_model.analyses.transient import run_transient
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters, to_dict
from rotorub_model.uncertainty.evaluate import evaluate_chunk

SPEED = 3.3


def spec(targets, quantities, speeds=(SPEED,), params=None, **kw):
    d = {"model": "rotorub", "params": to_dict(params or reference_parameters()), "formulation": "3D",
         "speeds": list(speeds), "quantities": quantities, "targets": targets, "t_end": 1.5, "t_ramp": 1.0}
    return json.dumps({**d, **kw}, sort_keys=True)


@pytest.fixture(scope="module")
def model():
    return build_model()


def test_margin_is_clearance_minus_the_detection_closure(model):
    c = closure(make_contact(model, "3D"), linear_responses(model, np.array([SPEED * 53.4])))[0]
    g0 = [0.5e-3, 0.9e-3, 1.2e-3]
    r = evaluate_chunk(spec(["contact.g0"], ["margin", "rub"]), [[g] for g in g0])
    np.testing.assert_allclose(r["margin"], np.array(g0) - c, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(r["rub"], (np.array(g0) < c).astype(float))


def test_imbalance_magnitude_and_angle_match_a_rebuilt_model(model):
    """me and the angle enter as force directions (no rebuild): the margin of a model built with them."""
    p = reference_parameters().replace(imbalance={"me": 0.011, "angle_deg": 17.0})
    m = build_model(p)
    c = closure(make_contact(m, "3D"), linear_responses(m, np.array([SPEED * 53.4])))[0]
    r = evaluate_chunk(spec(["imbalance.me", "imbalance.angle_deg"], ["margin"]), [[0.011, 17.0]])
    assert r["margin"][0] == pytest.approx(p.contact.g0 - c, abs=1e-15)
    # the discrete blades make the closure depend on the angle, period 36 deg: it must move
    r2 = evaluate_chunk(spec(["imbalance.me", "imbalance.angle_deg"], ["margin"]), [[0.011, 0.0]])
    assert r2["margin"][0] != pytest.approx(r["margin"][0], abs=1e-9)


def test_engine_closure_and_offset_shift_the_margin_exactly(model):
    n = make_contact(model, "3D").geometry.normals.reshape(-1, 3)
    nr = np.hypot(n[:, 0], n[:, 1])
    assert np.allclose(nr, math.cos(math.radians(5.0)))  # the cone's normal: radial part cos(theta)
    s = spec(["engine.closure", "engine.offset"], ["margin"])
    base = evaluate_chunk(s, [[0.0, 0.0]])["margin"][0]
    r = evaluate_chunk(s, [[0.2e-3, 0.0], [0.0, 0.1e-3]])["margin"]
    assert r[0] == pytest.approx(base - 0.2e-3, abs=1e-15)
    assert r[1] == pytest.approx(base - 0.1e-3 * nr.max(), abs=1e-12)


def test_run_up_margin_is_the_worst_speed(model):
    speeds = np.linspace(3.0, 4.0, 41)
    c = closure(make_contact(model, "3D"), linear_responses(model, speeds * 53.4))
    r = evaluate_chunk(spec(["contact.g0"], ["margin"], speeds=speeds.tolist()), [[1e-3]])
    assert r["margin"][0] == pytest.approx(1e-3 - c.max(), abs=1e-15)


def test_static_quantities_are_solve_static_and_its_eigenvalues(model):
    from rotorub_model.analyses.stability import stability_indicators

    g0 = 0.335e-3
    c = make_contact(model, "3D", g0=g0, mu=0.2)
    st = solve_static(model, c, SPEED * 53.4)
    mr = stability_indicators(model, c, SPEED * 53.4, st.q)[0]
    r = evaluate_chunk(spec(["contact.g0", "contact.mu"], ["static_max_force", "static_blades_in_contact",
                                                           "static_max_real", "static_unstable"]), [[g0, 0.2]])
    assert st.converged and st.n_contact > 0
    assert r["static_max_force"][0] == st.forces_N.max()
    assert r["static_blades_in_contact"][0] == st.n_contact
    assert r["static_max_real"][0] == mr
    assert r["static_unstable"][0] == float(mr > 1e-6)
    assert r["seconds_static"][0] > 0


def test_transient_peak_force_is_run_transient(model):
    g0 = 0.335e-3
    run = run_transient(model, make_contact(model, "3D", g0=g0), SPEED * 53.4, t_end=1.5, t_ramp=1.0)
    r = evaluate_chunk(spec(["contact.g0"], ["peak_force"]), [[g0]])
    assert run.outputs["F_N"].max() > 0
    assert r["peak_force"][0] == run.outputs["F_N"].max()


def test_a_structural_input_rebuilds_the_model():
    """bearings.front.k is neither a gap, a force nor the contact: the model is assembled again per sample."""
    p = reference_parameters()
    k = 2.0 * p.bearings[0].k
    m = build_model(p.replace(bearings=[{**to_dict(p)["bearings"][0], "k": k}, to_dict(p)["bearings"][1]]))
    c = closure(make_contact(m, "3D"), linear_responses(m, np.array([SPEED * 53.4])))[0]
    r = evaluate_chunk(spec(["bearings.front.k"], ["margin"]), [[k]])
    assert r["margin"][0] == pytest.approx(p.contact.g0 - c, abs=1e-15)


def test_transient_with_a_casing_offset_runs_against_the_offset_liner(model):
    from rotorub_model.contact.liner import Liner

    g0, e = 0.335e-3, 0.1e-3
    c = make_contact(model, "3D", g0=g0)
    run = run_transient(model, c, SPEED * 53.4, t_end=1.5, t_ramp=1.0,
                        liner=Liner.for_model(model, c, wears=False, offset=(e, 0.0)))
    r = evaluate_chunk(spec(["contact.g0", "engine.offset"], ["peak_force"]), [[g0, e], [g0, 0.0]])
    assert r["peak_force"][0] == run.outputs["F_N"].max()
    assert r["peak_force"][0] > r["peak_force"][1]  # the offset casing presses one side harder


def test_wear_depth_is_run_wears(model):
    from rotorub_model.analyses.wear import run_wear

    g0 = 0.335e-3
    w = run_wear(model, "3D", SPEED, g0, t_end=1.5, t_ramp=1.0, yield_force=50.0)
    p = reference_parameters().replace(abradable={"yield_force": 50.0})
    r = evaluate_chunk(spec(["contact.g0"], ["wear_depth", "peak_force"], params=p), [[g0]])
    assert w.summary()["depth_max_mm"] > 0
    assert r["wear_depth"][0] * 1e3 == pytest.approx(w.summary()["depth_max_mm"], rel=1e-12)
    assert r["peak_force"][0] == pytest.approx(float(w.transient.outputs["F_N"].max()), rel=1e-12)


def test_diverged_is_the_section_6_verdict():
    """At the section-6 point the 2D static solution is unstable and its 8 s run diverges; the 3D one settles.
    A run under 4 s that stays within the liner gets no verdict (NaN), as app/studies.py says."""
    s2 = spec(["contact.g0"], ["diverged"], formulation="2D", t_end=8.0)
    s3 = spec(["contact.g0"], ["diverged"], t_end=8.0)
    assert evaluate_chunk(s2, [[0.335e-3]])["diverged"][0] == 1.0
    assert evaluate_chunk(s3, [[0.335e-3]])["diverged"][0] == 0.0
    assert np.isnan(evaluate_chunk(spec(["contact.g0"], ["diverged"], t_end=2.0), [[0.335e-3]])["diverged"][0])
