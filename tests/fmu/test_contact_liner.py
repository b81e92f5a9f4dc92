"""The liner and the engine's inputs through both FMU flavours (issue 19.4): the same numbers as the library,
a rollback that un-wears, the closure and the offset where the gap says they are."""

from __future__ import annotations

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="the FMU tests drive the FMU with fmpy (pip install -e '.[fmu]')")
pytest.importorskip("pythonfmu", reason="building the FMU needs pythonfmu (pip install -e '.[fmu]')")

from fmu_src.masters.fmi2 import Slave  # noqa: E402
from rotorub_model.analyses.transient import run_transient  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402
from rotorub_model.contact.liner import Liner  # noqa: E402

NB = 10
WEAR = ["wear.depth_max", "wear.depth_mean", "wear.volume", "wear.plastic_work",
        *(f"wear.harmonic[{h}]" for h in range(1, 9)), "clearance_effective"]
GAPS = [f"blade[{j}].gap_LE" for j in range(1, NB + 1)]
LINER = {"liner": "abradable", "yield_force": 60.0, "hardening": 1e5, "n_sectors": 360}


@pytest.fixture(scope="module", params=["pythonfmu", "native"])
def fmu(request):
    return request.getfixturevalue("contact_fmu" if request.param == "pythonfmu" else "native_fmu")


def _library_run(model, formulation, g0, omega, t_end, closure=0.0, offset=(0.0, 0.0)):
    c = make_contact(model, formulation, g0=g0)
    p = model.params
    liner = Liner(c, LINER["yield_force"], LINER["hardening"], p.abradable.thickness, LINER["n_sectors"], wears=True,
                  closure=closure, offset=offset, radius=p.blades.tip_radius,
                  band=p.contact.chord * np.cos(np.radians(p.blades.stagger_deg)),
                  tip_area=p.blades.thickness * p.contact.chord)
    r = run_transient(model, c, omega, t_end=t_end, t_ramp=0.0, me=p.imbalance.me, record_dt=1e-3, hold=1e-3,
                      liner=liner)
    return r, liner


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_wear_outputs_equal_the_librarys(fmu, ref_model, formulation):
    """A rub at the imbalance held from t = 0, against an abradable liner with an offset casing and a closing
    clearance: every wear output of the FMU (both flavours) equals the library's liner summary to 1e-10."""
    p = ref_model.params
    omega, g0, t_end = 3.3 * p.normalisation.omega_ref, 0.4e-3, 1.0
    closure, offset = 0.1e-3, (0.05e-3, -0.02e-3)
    lib, liner = _library_run(ref_model, formulation, g0, omega, t_end, closure, offset)
    with Slave(fmu, g0=g0, Omega=omega, imbalance=p.imbalance.me, formulation=formulation, clearance_closure=closure,
               **{"casing_offset.x": offset[0], "casing_offset.y": offset[1]}, **LINER) as s:
        for _ in range(int(round(t_end / 1e-3))):
            s.step(None, 1e-3)
        got = s.get_reals(WEAR)
        lobes = s.get("wear.lobes")
        gaps = s.get_reals(GAPS)
    sm = liner.summary()
    want = [sm[k] for k in ("depth_max", "depth_mean", "volume", "plastic_work")]
    want += [sm[f"harmonic_{h}"] for h in range(1, 9)] + [sm["clearance_effective"]]
    assert sm["depth_max"] > 10e-6, "the scenario must wear the liner"
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10 * max(abs(w) for w in want))
    assert lobes == sm["lobes"]
    np.testing.assert_allclose(gaps, lib.outputs["gap"][-1, :, 0], rtol=1e-10, atol=1e-13)
    assert got[-1] == pytest.approx(g0 - closure + sm["depth_mean"], rel=1e-12)


def test_a_rollback_un_wears(fmu, ref_model):
    """A state saved before the rub, restored after it (in memory and from bytes): the profile, volume and
    plastic work are the saved ones, and the run from there repeats bit for bit."""
    p = ref_model.params
    omega = 3.3 * p.normalisation.omega_ref
    with Slave(fmu, g0=0.3e-3, Omega=omega, imbalance=p.imbalance.me, **LINER) as s:
        for _ in range(50):
            s.step(None, 1e-3)
        before = s.get_reals(WEAR)
        state = s.get_state()
        blob = s.serialize(state)
        rows = []
        for _ in range(400):
            s.step(None, 1e-3)
            rows.append(s.get_reals(WEAR))
        assert rows[-1][0] > before[0] + 10e-6, "the rub must wear the liner after the snapshot"
        for restore in (lambda: s.set_state(state), lambda: s.set_state(s.deserialize(blob))):
            restore()
            np.testing.assert_array_equal(s.get_reals(WEAR), before)
            again = []
            for _ in range(400):
                s.step(None, 1e-3)
                again.append(s.get_reals(WEAR))
            np.testing.assert_array_equal(again, rows)
        s.free_state(state)


def test_closure_and_offset_move_the_gaps_as_said(fmu, ref_model):
    """At rest (no spin, no imbalance: the rotor stays centred), a closure c and an offset (e, 0) make blade j's
    gap g0 - c + n_r e cos(alpha_j) (alpha_j its angle, n_r the radial part of the casing normal: 1 in 2D)."""
    g0, c, e = 1e-3, 0.3e-3, 0.2e-3
    with Slave(fmu, g0=g0, Omega=0.0, imbalance=0.0, formulation="2D", clearance_closure=c,
               **{"casing_offset.x": e}) as s:
        s.step(None, 1e-3)
        gaps = np.array(s.get_reals(GAPS))
        assert s.get("clearance_effective") == pytest.approx(g0 - c)
    alpha = 2 * np.pi * np.arange(NB) / NB
    np.testing.assert_allclose(gaps, g0 - c + e * np.cos(alpha), atol=1e-9)
