"""Studies on a user's configuration: the divergence verdict against the static solution's eigenvalue,
and the transient point picked from the configuration's own maps (issue 18.3, 18.4)."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.app.studies import (
    DIVERGENCE_GROWTH,
    default_grid,
    diverging,
    envelope_growth,
    pick_transient_point,
    point_status,
    run_transient_study,
)
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import from_dict, reference_parameters, to_dict


def _moved_disk():
    """The fan disk 0.15 m behind the shaft end: the first critical moves from 3.3 to about 4.9."""
    d = to_dict(reference_parameters())
    d["disks"][0]["z"] = 0.15
    return from_dict(d)


# ------------------------------------------------------------------------------------------- the measure
def test_growth_is_read_where_the_ringing_has_gone():
    """A mode growing at 0.15 1/s under ringing 10^3 times larger at 2 s that decays at 2 1/s: the old
    measure (end over 2 s) called it settled; the fit over the second half finds the rate."""
    t = np.arange(0.0, 20.0, 1e-3)
    y = np.abs(100.0 * np.exp(-2.0 * t) * np.cos(170 * t) + 1e-3 * np.exp(0.15 * t) * np.cos(183 * t))
    g = envelope_growth(t, y)
    assert g["rate_per_s"] == pytest.approx(0.15, rel=0.02)
    assert g["window_s"][0] >= 10.0 and diverging(g)
    decaying = envelope_growth(t, np.abs(np.exp(-0.05 * t) * np.cos(170 * t)))
    assert decaying["rate_per_s"] == pytest.approx(-0.05, rel=0.05) and not diverging(decaying)
    # a limit cycle: a flat envelope, whatever its level, is not a divergence
    assert not diverging(envelope_growth(t, np.abs(3.0 * np.cos(170 * t) + 0.3 * np.cos(23 * t))))
    assert envelope_growth(t[t < 3.0], y[t < 3.0])["factor"] is None  # too short to say


# --------------------------------------------------- the verdict against the static solution's eigenvalue
@pytest.fixture(scope="module")
def eighteen_blades(tmp_path_factory):
    model = build_model(reference_parameters().replace(blades={"count": 18}))
    st = point_status(model, 3.3, 0.8e-3)
    s = run_transient_study(model, tmp_path_factory.mktemp("b18"), progress=False)
    return st, s


def test_eighteen_blades_diverge_at_the_rate_of_their_eigenvalue(eighteen_blades):
    """Issue 18.4: the 2D transient's envelope grew 10x from 5 to 20 s at the static solution's +0.16 1/s
    and the summary said it had not diverged. The point is the paper's (it qualifies for 18 blades)."""
    st, s = eighteen_blades
    assert (s["speed"], s["g0_mm"]) == (3.3, pytest.approx(0.8))
    lam2, lam3 = st["2D"]["stability"].max_real, st["3D"]["stability"].max_real
    assert lam2 > 0.1 and lam3 < 0  # the oracle: 2D unstable, 3D stable (measured +0.160, -0.029)
    g2, g3 = s["envelope_growth"]["2D"], s["envelope_growth"]["3D"]
    assert g2["rate_per_s"] == pytest.approx(lam2, rel=0.1)  # measured 0.163
    assert g2["factor"] > DIVERGENCE_GROWTH and s["diverged_2d"]
    assert g3["rate_per_s"] < 0 and not s["diverged_3d"] and s["settled_3d"]


# ------------------------------------------------------------------------------------- the point picked
def test_moved_disk_point_comes_from_its_own_maps(tmp_path):
    """Issue 18.3: with the disk moved the first critical goes to ~4.9, and the transient ran at the
    paper's 3.3, outside its own maps. The point must lie on this configuration's grid and have an
    unstable 2D and a stable 3D static solution, at a rate the run can show."""
    model = build_model(_moved_disk())
    speeds, g0s = default_grid(model, quick=True)
    assert speeds[0] > 3.3  # the paper's speed is off this configuration's maps
    speed, g0 = pick_transient_point(model)
    assert speeds[0] <= speed <= speeds[-1] and 0 < g0 <= g0s[-1]
    st = point_status(model, speed, g0)
    assert st["2D"]["static"].n_contact > 0 and st["3D"]["static"].n_contact > 0
    assert st["2D"]["stability"].max_real > 2 * np.log(DIVERGENCE_GROWTH) / 20.0
    assert st["3D"]["stability"].stable


def test_a_configuration_without_a_point_says_so():
    """Friction 0.3: no cell of its maps has an unstable 2D and a stable 3D solution (measured on its
    quick grid); the study refuses with the reason instead of running somewhere."""
    model = build_model(reference_parameters().replace(contact={"mu": 0.3}))
    with pytest.raises(ParameterError, match="no cell of this configuration's stability maps"):
        pick_transient_point(model)


def _small_imbalance():
    """A newcomer's configuration (issue 18, its own review): a tenth of the imbalance, a sharper friction
    regularisation, validity up to 6. The old picker took (3.49, 0.163 mm) from its clearance search, 2D unstable at
    +0.028 1/s: a 20 s run grows 1.3-fold, and the study reported diverged_2d false without a word."""
    return reference_parameters().replace(imbalance={"me": 2.0e-3}, contact={"slip_velocity": 0.01},
                                          normalisation={"speed_max": 6.0})


def test_the_point_picked_has_an_instability_the_run_shows(tmp_path):
    """The chosen point's 2D eigenvalue is at least twice the rate the verdict can see in the run, so the 2D run
    is seen to diverge and the 3D one to settle; the summary says where the point came from."""
    model = build_model(_small_imbalance())
    s = run_transient_study(model, tmp_path, progress=False)
    pt = s["point"]
    assert pt["instability_visible"] and pt["max_real_2d_per_s"] >= 4 * np.log(DIVERGENCE_GROWTH) / 20.0
    assert pt["source"] in ("paper point", "stability maps") or pt["source"].startswith("clearance search")
    assert s["diverged_2d"] is True and s["diverged_3d"] is False and s["settled_3d"]


def test_a_run_too_short_to_judge_gets_no_verdict(tmp_path):
    """A 2 s run (the imbalance ramp and one second): the growth cannot be fitted, so diverged is None with the
    reason, not False (the 2D solution here is unstable: False would be wrong)."""
    s = run_transient_study(build_model(), tmp_path, 3.3, 0.3347658066492542e-3, t_end=2.0, progress=False)
    assert s["diverged_2d"] is None and s["diverged_3d"] is None and "shorter than 4 s" in s["verdict_note"]
    assert s["static_2d"]["max_real_part"] > 0.1


# ------------------------------------------------------------------------------------------- the law's note
def test_law_note_names_the_formulation_that_stayed_short_of_the_knee():
    """A bilinear knee of 0.2 mm, a 2D run 0.176 mm deep and a 3D run 0.274 mm deep (configuration A of a user:
    18 blades, mu 0.2): the note over both said nothing, yet the 2D run is the penalty law's."""
    from types import SimpleNamespace

    from rotorub_model.app.studies import _law_note

    c = reference_parameters().replace(contact={"law": "bilinear", "knee": 2e-4}).contact

    def run(depth):
        return SimpleNamespace(outputs={"gap": np.array([[1e-3, -depth], [2e-4, 0.0]])})

    note = _law_note(c, {"2D": run(1.76e-4), "3D": run(2.74e-4)})
    assert note.startswith("2D: the bilinear law's knee (0.2 mm) was never reached (deepest penetration 0.176 mm)")
    assert "3D" not in note
    assert _law_note(c, {"2D": run(3e-4), "3D": run(2.74e-4)}) == ""
    both = _law_note(c, {"2D": run(1e-4), "3D": run(1.5e-4)})
    assert not both.startswith(("2D", "3D")) and "deepest penetration 0.15 mm" in both
    assert _law_note(reference_parameters().contact, {"2D": run(1e-4), "3D": run(1e-4)}) == ""  # no knee
    assert _law_note(None, {"2D": run(1e-4)}) == ""


def test_the_picker_solves_on_one_blas_thread(monkeypatch):
    """The picker's static solutions and eigenvalues (small dense problems) run on one BLAS thread: with OpenBLAS's
    thread per core on a loaded machine the picking of an 18-blade configuration took 44.6 s instead of 5.5 s."""
    from threadpoolctl import threadpool_info, threadpool_limits

    import rotorub_model.app.studies as studies

    seen = []
    real = studies.point_status

    def spy(model, speed, g0):
        seen.append({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})
        return real(model, speed, g0)

    monkeypatch.setattr(studies, "point_status", spy)
    with threadpool_limits(limits=2):  # a user's process: a thread per core (the suite's conftest pins one)
        studies.choose_transient_point(build_model())
    assert seen and all(s <= {1} for s in seen), seen


def test_a_run_stopped_by_the_penetration_limit_gets_no_short_run_note(tmp_path):
    """A user's 18-blade fan with a bilinear law (knee 0.025 mm) at its picked point (3.3, 0.3815 mm): the 2D run hits
    the penetration limit at 6.3 s. It has no growth fit, and the study's note said "a run shorter than 4 s gets no
    growth verdict: diverged is null" about a run that is diverged and ran 6.3 s."""
    p = reference_parameters().replace(
        blades={"count": 18, "width": 0.16, "thickness": 0.0099}, casing={"E": 9.1e10},
        contact={"mu": 0.2, "chord": 0.16, "g0": 0.5e-3, "law": "bilinear", "knee": 0.025e-3})
    s = run_transient_study(build_model(p), tmp_path, speed=3.3, g0=0.38146673364111827e-3, progress=False)
    assert s["penetration_limit_hit"]["2D"] is True and s["diverged_2d"] is True
    assert "shorter than 4 s" not in s["verdict_note"], s["verdict_note"]
    assert s["verdicts"]["2D"].startswith("diverged at t = ")
