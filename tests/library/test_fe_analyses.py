"""The example's imported blades (examples/fan_blade/example.toml: ten CalculiX blades reduced to 14 modes, the tip
ground to the casing's 5 deg cone, 158 dofs) through every analysis of the library: modes and Campbell (cyclic
blocks, tuned and mistuned), detection, static solutions and stability, the maps' rows and contact-set starts (per
blade over its tip's segments), continuation, transients, wear by station, the uncertainty studies' mistuning, and
the commands with --params."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rotorub_model.analyses.continuation.branch import continue_static
from rotorub_model.analyses.continuation.equilibria import Equilibria
from rotorub_model.analyses.detection import paper_facts, run_detection
from rotorub_model.analyses.linear import _free_modes, first_order, run_campbell, run_modes
from rotorub_model.analyses.maps import ContactSetStarts, map_row
from rotorub_model.analyses.stability import stability_of
from rotorub_model.analyses.static import solve_static
from rotorub_model.analyses.transient import run_transient
from rotorub_model.analyses.wear import run_wear
from rotorub_model.contact import make_contact
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model, load_model, save_model
from rotorub_model.structure.params import load_parameters, to_dict
from rotorub_model.uncertainty.mistuning import blade_tip_deflections, mistuned_model

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fan_blade" / "example.toml"
SPEED = 3.4  # normalised: near the example's first critical speed (3.48)


@pytest.fixture(scope="module")
def model():
    return build_model(load_parameters(EXAMPLE))


def w(model, speed: float = SPEED) -> float:
    return speed * model.params.normalisation.omega_ref


def _dense_frequencies(model, omega: float) -> np.ndarray:
    lam = np.linalg.eigvals(first_order(model, omega))
    return np.sort(lam.imag[lam.imag > 1e-6])


def test_the_example_is_assembled_with_its_imported_blades(model):
    """14 modes a blade, the Omega^4 term of the prestress kept, the blade damping the parameter file's."""
    assert model.n_dofs == 10 + 10 * 14 + 8 and model.blade_dofs == 14
    assert model.S4 is not None and np.abs(model.S4).max() > 0
    assert model.fe_blade.damping_ratio == model.params.blades.damping_ratio
    assert model.block_layout == (10, 10, 14, 8)


@pytest.mark.parametrize("speed", [0.0, 12.0])
def test_modes_by_cyclic_blocks_equal_the_dense_problem(model, speed):
    """The contact-open model solved by travelling-wave blocks (with the Omega^4 term) equals the dense eigen-problem
    at rest and at the top speed; leaving out the Omega^4 term would move the top speed's by 1e-4 or more."""
    omega = w(model, speed)
    lam = np.concatenate([x for x, _ in _free_modes(model, np.array([omega]))])
    blocks = np.sort(lam.imag[lam.imag > 1e-6])
    dense = _dense_frequencies(model, omega)
    assert blocks.shape == dense.shape
    assert np.abs(blocks - dense).max() <= 1e-9 * dense.max()
    assert len(model.cyclic.blocks) > 10  # it does split: the blades' waves by nodal diameter
    if speed:
        S4, model.S4 = model.S4, None
        try:
            without = _dense_frequencies(model, omega)
        finally:
            model.S4 = S4
        assert np.abs(without / dense - 1.0).max() > 1e-4


def test_mistuned_disk_of_imported_blades(model):
    """A mistuned disk: build_model(mistuning=) and the studies' mistuned_model give the same matrices to the bit;
    its cyclic blocks merge and still give the dense problem's frequencies."""
    delta = np.linspace(-0.03, 0.03, 10)
    built = build_model(model.params, mistuning=delta)
    scaled = mistuned_model(model, delta)
    assert np.array_equal(built.K, scaled.K) and np.array_equal(built.D, scaled.D)
    lam = np.concatenate([x for x, _ in _free_modes(built, np.array([w(built)]))])
    f = np.sort(lam.imag[lam.imag > 1e-6])
    assert np.abs(f - _dense_frequencies(built, w(built))).max() <= 1e-9 * f.max()
    assert len(built.cyclic.blocks) < len(model.cyclic.blocks)
    q = np.linalg.solve(model.K_omega(w(model)), model.force(w(model)))
    assert blade_tip_deflections(model, q).shape == (10,)


def test_a_study_input_on_a_beam_field_is_refused_for_an_imported_blade(model):
    """blades.thickness means nothing to an imported blade (its stiffness is its superelement's): a study that varies
    it would report a spread of zero; it is refused in one line that names the input and what is accepted."""
    from rotorub_model.uncertainty.targets import resolve_target

    with pytest.raises(ParameterError, match=r"inputs.t: 'blades.thickness' is a field of the built-in beam blade.*"
                                             r"accepted for an imported blade: blades.damping_ratio"):
        resolve_target("inputs.t", "blades.thickness", model.params)
    assert resolve_target("inputs.z", "blades.damping_ratio", model.params).field == "damping_ratio"
    assert resolve_target("inputs.t", "blades.thickness", build_model().params).field == "thickness"  # beam: fine


def test_modes_and_campbell_are_labelled(model):
    r = run_modes(model, 3.0)
    c = run_campbell(model, 10.0, 20)
    assert r.fixed_frame_hz.size == model.n_dofs and c.fixed_frame_hz.shape[0] == 20
    assert set(np.unique(np.abs(r.harmonic))) >= {0, 1, 2, 5}


def test_detection_uses_the_imported_tip_and_skips_the_beam_studies(model, tmp_path):
    det = run_detection(model, n_speeds=60, n_g0=30, progress=False)
    s = det.save(tmp_path)
    assert set(det.closures) == {"2D", "3D", *(f"theta={t:g}" for t in (0, 5, 10, 20, 30))}
    assert set(s["skipped"]) == {"variants", "chord"} and s["closure_diff_kinematics_only_mm"] is None
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["detection_2d_3d.png", "detection_theta.png"]
    assert s["closure_3d_max_mm"] > s["closure_2d_max_mm"] > 1.0  # the tilt and the flexure add to the disk's orbit
    assert s["defaults_3d"]["chord"] == pytest.approx(make_contact(model, "3D").geometry.chord)
    assert [f["id"] for f in paper_facts(s)] == [2]  # the beam studies' facts (3, 4) are not claimed
    c = make_contact(model, "3D")
    q = np.linalg.solve(model.K_omega(w(model)), model.force(w(model)))
    i = int(np.argmin(np.abs(det.speeds - SPEED)))
    assert det.closures["3D"][i] == pytest.approx(float(-c.with_clearance(0.0).gaps(
        np.linalg.solve(model.K_omega(w(model, det.speeds[i])), model.force(w(model, det.speeds[i])))).min()), rel=1e-9)
    assert float(-c.with_clearance(0.0).gaps(q).min()) > 0


def test_static_solution_and_its_stability(model):
    c = make_contact(model, "3D", g0=0.5e-3)
    st = solve_static(model, c, w(model))
    assert st.converged and st.residual < 1e-9 and st.n_contact >= 1
    assert st.fractions.shape == (10,) and 0 < st.fractions.max() <= 1
    # balanced: K(Omega) q = F_nl + F
    R = model.K_omega(w(model)) @ st.q - c.forces(st.q, w(model)) - model.force(w(model))
    assert np.abs(R).max() <= 1e-8 * np.abs(model.force(w(model))).max()
    sb = stability_of(model, c, w(model), st.q)
    assert np.isfinite(sb.max_real)


def test_contact_set_starts_per_blade_over_the_segments(model):
    """A contact set's law is assembled blade by blade from the segments of each blade's tip: with every blade in
    full contact it is the whole contact's law (forces and Jacobian), and a set found consistent is an
    equilibrium the solver polishes."""
    base = make_contact(model, "3D")
    omega = w(model)
    st = ContactSetStarts(model, base, omega)
    assert st.J.shape == (10, model.n_dofs, model.n_dofs)
    whole = base.with_clearance(-1.0)
    z = np.zeros(model.n_dofs)
    assert np.allclose(st.J.sum(axis=0), whole.jacobian(z, omega), rtol=0, atol=1e-9 * np.abs(st.J).max())
    assert np.allclose(-st.h.sum(axis=0), whole.forces(z, omega), rtol=0, atol=1e-9 * np.abs(st.h).max())
    found, absent = st.find(0.5e-3, None)
    assert found is not None and found.converged and not absent


def test_map_row_rebuilds_the_model_from_its_parameters(model):
    """A map's rows run in workers that rebuild the model from its parameters: the superelement's path travels in
    them (absolute, resolved from the parameter file) and the row equals the solves done here."""
    pj = json.dumps(to_dict(model.params), sort_keys=True)
    assert Path(json.loads(pj)["fe_blade"]["superelement"]).is_absolute()
    g0s = [0.0, 0.5e-3, 10e-3]
    row = map_row(pj, "3D", "full", SPEED, g0s)
    st = solve_static(model, make_contact(model, "3D", g0=0.5e-3), w(model))
    assert row["n_contact"][1] == st.n_contact and row["n_contact"][2] == 0
    assert row["chord_total"][1] == pytest.approx(float(np.sum(st.fractions)), rel=1e-6)


def test_continuation_branch_in_clearance(model):
    """A static branch in g0 at the study speed: its first contact event located where the 3D closure is."""
    eq = Equilibria(model, "3D")
    closure = float(-make_contact(model, "3D", g0=0.0).gaps(np.linalg.solve(model.K_omega(w(model)),
                                                                            model.force(w(model)))).min())
    b = continue_static(eq, "g0", w(model), 1.2 * closure, 0.8 * closure, h_max=0.1)
    assert b.complete and len(b.points) > 5
    contacts = b.of_kind("contact")
    assert contacts and abs(max(s.point.g0 for s in contacts) - closure) <= 1e-6 * closure


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_transient(model, formulation):
    c = make_contact(model, formulation, g0=0.5e-3)
    tr = run_transient(model, c, w(model), t_end=1.5, record_dt=1e-3)
    assert not tr.diverged and tr.outputs["F_N"].shape[1] == 10 and tr.outputs["F_N"].max() > 10.0


def test_wear_by_station(model, tmp_path):
    """The liner's rows are the tip's chord stations (12), its band the tip's axial extent; the 3D run wears it and
    writes its figures and summary."""
    r = run_wear(model, "3D", SPEED, 0.3e-3, t_end=1.5, yield_force=50.0)
    s = r.save(tmp_path)
    depth = r.wear["depth"]
    c = make_contact(model, "3D")
    assert depth.shape[0] == c.n_rows == 12
    assert s["depth_max_mm"] > 0 and s["removed_volume_mm3"] > 0
    assert (tmp_path / "wear_map.png").exists() and (tmp_path / "wear.json").exists()


def test_saved_model_keeps_the_imported_blade(model, tmp_path):
    """save_model / load_model (the pythonfmu FMU's): S4 and the tip's arrays, so the loaded model's contact is the
    built one's to the bit, without the superelement file."""
    save_model(model, tmp_path / "m.npz")
    m = load_model(tmp_path / "m.npz")
    assert np.array_equal(m.S4, model.S4) and m.fe_blade.m == 14
    a, b = make_contact(model, "3D").geometry, make_contact(m, "3D").geometry
    for k in ("G", "A", "B", "S", "points", "normals"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert np.array_equal(a.tips.g_off, b.tips.g_off) and a.tips.tip_area == b.tips.tip_area


def test_the_report_says_which_blade(model):
    """The main job's summary and report on an imported blade: its superelement, dofs and frequencies, in place of
    the built-in blades' Ritz study."""
    from rotorub_model.app.report import _imported_blade_section
    from rotorub_model.app.reproduce import imported_blade_summary

    d = imported_blade_summary(model)
    assert d["dofs_per_blade"] == 14 and d["tip_stations"] == 12
    assert d["clamped_frequencies_at_rest_hz"][0] == pytest.approx(25.85, abs=0.05)  # CalculiX: 25.849 Hz
    text = "\n".join(_imported_blade_section(d))
    assert "14 dofs a blade" in text and "not run on an imported blade" in text
