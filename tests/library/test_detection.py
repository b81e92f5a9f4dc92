"""Contact detection maps (detection.py): exactness of the closure construction and the
paper's facts 2-4 (MODEL-NOTES section 4) on the reference configuration."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.analyses.detection import (
    CHORDS_M,
    THETAS_DEG,
    closure,
    contact_map,
    linear_responses,
    paper_facts,
    run_detection,
    speed_grid,
)
from rotorub_model.analyses.linear import linear_response
from rotorub_model.app.cli import main
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model


@pytest.fixture(scope="module")
def model():
    return build_model()


@pytest.fixture(scope="module")
def det(model):
    return run_detection(model, progress=False)


@pytest.fixture(scope="module")
def summary(det):
    return det.summary()


# ------------------------------------------------------------------ the construction


def test_batched_responses_match_linear_response(model):
    w = np.array([10.0, 150.0, 186.0, 400.0])
    Q = linear_responses(model, w)
    for wi, q in zip(w, Q):
        np.testing.assert_allclose(q, linear_response(model, wi), rtol=1e-10, atol=1e-18)


@pytest.mark.parametrize("form, variant", [("2D", "full"), ("3D", "full"), ("3D", "geometry_only")])
def test_closure_map_equals_brute_force(model, form, variant):
    """{g0 < c(Omega)} is exactly the set where some gap of ContactModel.gaps is negative."""
    speeds = np.linspace(0.5, 9.5, 23)
    Q = linear_responses(model, speeds * model.params.normalisation.omega_ref)
    base = make_contact(model, form, variant)
    c = closure(base, Q)
    g0 = np.concatenate([np.linspace(0.0, 1.2 * c.max(), 37), c * (1 - 1e-9), c * (1 + 1e-9)])
    fast = contact_map(c, g0)
    brute = np.array([[np.any(base.with_clearance(g).gaps(q) < 0) for g in g0] for q in Q])
    np.testing.assert_array_equal(fast, brute)
    assert fast.any() and (~fast).any()


def test_grid_contains_the_critical_speeds(det, summary):
    for c in det.critical_speeds:
        assert np.any(det.speeds == c)
    assert len(det.critical_speeds) == 2
    assert summary["grid_spacing_at_first_critical"] < 0.1 * summary["base_grid_spacing"]
    g = speed_grid([3.5], 1.0, 5.0, 50)
    assert g[0] == 1.0 and g[-1] == 5.0 and 3.5 in g and np.all(np.diff(g) > 0)


def test_map_shape_and_bad_input(model, det):
    assert det.map("3D").shape == (det.speeds.size, det.g0.size) == (det.speeds.size, 400)
    with pytest.raises(ParameterError, match="n_g0"):
        run_detection(model, n_g0=1, progress=False)
    with pytest.raises(ParameterError, match="g0_max"):
        run_detection(model, g0_max=-1e-3, progress=False)
    with pytest.raises(ParameterError, match="speed"):
        run_detection(model, speed_min=5.0, speed_max=1.0, progress=False)
    with pytest.raises(ParameterError, match="label"):
        det.map("4D")


# ------------------------------------------------------------------ fact 2


def test_contact_at_every_speed_at_zero_clearance(det, summary):
    for k in ("2D", "3D", "3D kinematics only", "3D geometry only"):
        assert np.all(det.closures[k] > 0), k
        assert det.map(k)[:, 0].all()  # g0 = 0 is the first column of the map
    assert summary["contact_at_every_speed_at_g0_zero"] is True


def test_3d_map_contains_2d_map(det, summary):
    assert np.all(det.closures["3D"] >= det.closures["2D"])
    assert np.all(det.map("3D") | ~det.map("2D"))
    assert summary["map_3d_contains_2d"]


def test_largest_closure_at_first_critical(det, summary):
    """Both maxima sit at the first critical speed within the uniform grid spacing (the
    closure peaks a little above the amplitude peak, ~0.1 % in speed: near resonance
    the response direction turns and the max over 10 blades follows it)."""
    crit = summary["first_critical_speed"]
    assert crit == pytest.approx(3.5, abs=0.2)
    for form in ("2D", "3D"):
        s = summary["speed_of_max_closure"][form]
        assert abs(s - crit) <= summary["base_grid_spacing"], (form, s, crit)
    assert summary["closure_3d_max_mm"] > summary["closure_2d_max_mm"] > 1.0


def test_3d_minus_2d_at_first_critical(summary):
    assert summary["closure_diff_3d_2d_at_first_critical_mm"] == pytest.approx(1.3, abs=0.4)
    # the difference is largest at the first critical (the disk tilt peaks there)
    assert summary["closure_diff_3d_2d_max_mm"] == pytest.approx(summary["closure_diff_3d_2d_at_first_critical_mm"])


# ------------------------------------------------------------------ fact 3


def test_degraded_variants_close_to_2d(det, summary):
    for lab, key in (("3D kinematics only", "closure_diff_kinematics_only_mm"),
                     ("3D geometry only", "closure_diff_geometry_only_mm")):
        d = np.abs(det.closures[lab] - det.closures["2D"]) * 1e3
        assert d.max() < 0.1, (lab, d.max())
        assert summary[key] == pytest.approx(d.max())
    assert summary["closure_diff_full_3d_mm"] > 0.9  # only the full 3D gives the ~1.3 mm


# ------------------------------------------------------------------ fact 4


def test_theta_matters_more_than_chord(summary):
    th = list(summary["theta_sweep"].values())
    ch = list(summary["chord_sweep"].values())
    assert list(summary["theta_sweep"]) == ["0", "5", "10", "20", "30"]
    assert list(summary["chord_sweep"]) == ["1", "5", "10", "20", "30"]
    assert max(th) - min(th) > max(ch) - min(ch)
    assert summary["theta_sweep"]["5"] == summary["chord_sweep"]["20"] == summary["closure_3d_max_mm"]


@pytest.mark.parametrize("sweep", ["theta", "chord"])
def test_sweeps_widen_the_detection_area(det, summary, sweep):
    """Monotone non-decreasing: the largest closure, the map area, and the map itself
    (each step's map contains the previous one at every speed)."""
    labels = ([det.theta_label(t) for t in det.thetas_deg] if sweep == "theta"
              else [det.chord_label(c) for c in det.chords_m])
    maxes = [det.closures[k].max() for k in labels]
    assert np.all(np.diff(maxes) >= 0)
    for a, b in zip(labels, labels[1:]):
        assert np.all(det.closures[b] >= det.closures[a]), (a, b)
    d = summary[f"{sweep}_sweep_detail"]
    assert d["area_monotone"] and d["max_monotone"] and d["nested_every_speed"]


def test_paper_facts_hold(summary):
    facts = paper_facts(summary)
    assert [f["id"] for f in facts] == [2, 3, 4]
    assert all(f["holds"] for f in facts), [f["id"] for f in facts if not f["holds"]]


def test_paper_facts_conditions_print_rounded_speeds(summary):
    """The report's and the verdict's "ours" read "first critical 3.492", not the float's 16 digits."""
    ours = [c["ours"] for c in paper_facts(summary)[0]["conditions"] if "first critical" in c["ours"]]
    assert ours and all(len(o.split("first critical ")[1]) <= 6 for o in ours), ours


# ------------------------------------------------------------------ CLI


def test_cli_detect(tmp_path, capsys):
    out = tmp_path / "det"
    assert main(["detect", "--out", str(out), "--n-speeds", "200", "--n-g0", "100"]) == 0
    s = json.loads((out / "summary.json").read_text())
    for key in (
        "closure_2d_max_mm", "closure_3d_max_mm", "speed_of_max_closure", "closure_diff_3d_2d_at_first_critical_mm",
        "closure_diff_kinematics_only_mm", "closure_diff_geometry_only_mm", "closure_diff_definition",
        "theta_sweep", "chord_sweep", "contact_at_every_speed_at_g0_zero",
    ):
        assert key in s, key
    assert set(s["speed_of_max_closure"]) == {"2D", "3D"}
    for study in ("2d_3d", "variants", "theta", "chord"):
        png = out / f"detection_{study}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with np.load(out / "detection.npz") as z:
        assert z["map_3d"].shape == (z["speeds"].size, 100)


def test_cli_detect_bad_args(tmp_path, capsys):
    assert main(["detect", "--out", str(tmp_path), "--n-g0", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--n-g0" in err[0] and "[2, inf)" in err[0]
    assert main(["detect", "--out", str(tmp_path), "--g0-max-mm", "-2"]) == 2
    assert "g0_max" in capsys.readouterr().err


def test_the_sweeps_hold_the_configurations_own_cone_and_chord(det):
    """The paper's sweeps (theta 0-30 deg, chord 1-30 cm) plus the configuration's own values: a newcomer's 0.5 m
    chord and 15 deg cone were not among the sweeps of its own detection study. The reference's are (5 deg, 20 cm)."""
    from rotorub_model.structure.params import reference_parameters

    assert det.thetas_deg == THETAS_DEG and det.chords_m == CHORDS_M
    m = build_model(reference_parameters().replace(contact={"chord": 0.5, "theta_deg": 15.0}))
    r = run_detection(m, n_speeds=40, n_g0=20, progress=False)
    assert r.chords_m == (*CHORDS_M, 0.5) and 15.0 in r.thetas_deg and len(r.thetas_deg) == len(THETAS_DEG) + 1
