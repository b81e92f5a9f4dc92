"""The casing from an FE modal model (rotorub_model/fe/casing_modes.py): a thin ring written as an FE model
(rotorub_model/fe/ring_model.py) reproduces the built-in ring (structure/casing.py)."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.errors import FEImportError
from rotorub_model.fe.casing_modes import (
    casing_from_matrices,
    casing_from_modes,
    fe_casing_matrices,
    fe_casing_point_map,
)
from rotorub_model.fe.coordinates import read_coordinates
from rotorub_model.fe.matrix_market import read_dof_map, read_mm
from rotorub_model.fe.ring_model import write_ring
from rotorub_model.structure.casing import casing_matrices, casing_point_map, ring_modal
from rotorub_model.structure.params import reference_parameters


def fe_ring(p, folder, n_elements):
    info = write_ring(p, folder, n_elements)
    K, M = read_mm(info["stiffness"]), read_mm(info["mass"])
    nodes, comps = read_dof_map(info["dofs"])
    ids, xyz = read_coordinates(info["coordinates"])
    return casing_from_matrices(K, M, nodes, comps, ids, xyz, info["circle_nodes"], keep=(2, 3, 4))


def closed_form_hz(p, n):
    m, k = ring_modal(p, n)
    return np.sqrt(k / m) / (2 * np.pi)


def test_thin_fe_ring_is_the_builtin_ring(tmp_path):
    """A thin ring (the reference's, a tenth as thick: h/R = 0.013) of 360 frame elements: frequencies within
    1e-4 of omega_n^2 = E I n^2 (n^2 - 1)^2 / (rho A R^4 (n^2 + 1)) for n = 2, 3, 4, modal mass and stiffness
    per unit radial amplitude within 1e-4 of rho A R pi (1 + 1/n^2) and E I (n^2 - 1)^2 pi / R^3, tangential
    ratio -1/n, no axial motion; the casing block and the contact point map are the ring's within 1e-4."""
    p = reference_parameters().replace(casing={"ring_thickness": 0.0135})
    cas = fe_ring(p, tmp_path, 360)
    for md in cas.modes:
        m, k = ring_modal(p, md.n)
        assert md.frequency_hz == pytest.approx(closed_form_hz(p, md.n), rel=1e-4)
        assert md.modal_mass == pytest.approx(m, rel=1e-4) and md.modal_stiffness == pytest.approx(k, rel=1e-4)
        assert md.tau == pytest.approx(-1.0 / md.n, rel=1e-4) and abs(md.zeta) < 1e-9
    a, b = fe_casing_matrices(p, cas), casing_matrices(p)
    assert a.dofs == b.dofs
    for key in ("M", "K", "D", "G1", "N2", "C1", "E1"):
        B = getattr(b, key)
        assert np.abs(getattr(a, key) - B).max() <= 1e-4 * np.abs(B).max(), key
    for pt in (np.array([0.3, 0.9, 0.05]), np.array([-1.0, 0.2, -0.1])):
        assert np.abs(fe_casing_point_map(p, cas, pt) - casing_point_map(p, pt)).max() < 1e-4


def test_fe_ring_converges_like_its_facets(tmp_path):
    """Halving the elements' length divides the frequency error by four (straight facets on a circle, O(h^2)):
    the small differences above are the discretisation, not the import."""
    p = reference_parameters().replace(casing={"ring_thickness": 0.0135})
    err = [abs(fe_ring(p, tmp_path / str(ne), ne).mode(2).frequency_hz / closed_form_hz(p, 2) - 1.0)
           for ne in (90, 180)]
    assert 3.0 < err[0] / err[1] < 5.0


def test_reference_ring_differs_by_its_extensibility(tmp_path):
    """The reference ring is thick (h/R = 0.126): the FE frame, extensible, is 0.17 % (n = 2) to 0.23 % (n = 4)
    below the inextensional closed form, the order of (h/R)^2 / 12 = 1.3e-3 -- the built-in ring's own error."""
    p = reference_parameters()
    cas = fe_ring(p, tmp_path, 180)
    errs = [cas.mode(n).frequency_hz / closed_form_hz(p, n) - 1.0 for n in (2, 3, 4)]
    assert all(-4e-3 < e < 0.0 for e in errs), errs


def test_casing_modes_refused():
    """Modes not of one nodal diameter (a casing that is not axisymmetric), points off one circle, a nodal
    diameter asked for and not found: one line each."""
    a = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    pts = np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)])
    e_r = pts.copy()
    mixed = (np.cos(2 * a) + 0.6 * np.cos(3 * a))[:, None] * e_r
    with pytest.raises(FEImportError, match="not one nodal diameter"):
        casing_from_modes([50.0], mixed[None], pts)
    with pytest.raises(FEImportError, match="not on one circle"):
        casing_from_modes([50.0], mixed[None], pts * np.linspace(1.0, 1.1, 24)[:, None])
    pure = np.cos(2 * a)[:, None] * e_r
    with pytest.raises(FEImportError, match="no mode with 3 nodal diameters"):
        casing_from_modes([50.0], pure[None], pts, keep=(2, 3))
    cas = casing_from_modes([50.0], pure[None], pts, mass_norms=[2.0])
    assert cas.mode(2).modal_mass == pytest.approx(2.0) and cas.radius == pytest.approx(1.0)


# ----------------------------------------------------------------------------- [fe_casing] in the model


@pytest.fixture(scope="module")
def thin(tmp_path_factory):
    """The reference with a thin ring (h/R = 0.013), and the same ring as 360 FE frames through [fe_casing]."""
    from rotorub_model.structure.model import build_model

    d = tmp_path_factory.mktemp("ring")
    p = reference_parameters().replace(casing={"ring_thickness": 0.0135})
    f = fe_ring(p, d, 360).save(d / "casing.json")
    return build_model(p), build_model(p.replace(fe_casing={"model": str(f)}))


def test_saved_casing_model_round_trips(tmp_path):
    from rotorub_model.fe.casing_modes import load_fe_casing

    p = reference_parameters().replace(casing={"ring_thickness": 0.0135})
    cas = fe_ring(p, tmp_path, 180)
    back = load_fe_casing(cas.save(tmp_path / "c.json"))
    assert back.radius == cas.radius and back.modes == cas.modes


def test_fe_ring_in_the_model_gives_the_rings_results(thin):
    """The thin ring as FE frames in place of the built-in ring (casing block, the contact's casing maps with the
    FE tangential ratio): the contact rows to 1e-5, static solutions to 1e-5 and 2 s transients to 3e-4 of the
    largest force, 2D and 3D (measured 6e-6 and 2e-5 to 2e-4: the frames' discretisation); the casing's damping is
    [casing]'s."""
    from rotorub_model.analyses.static import solve_static
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact

    ring, fe = thin
    assert fe.casing_ratios is not None and ring.casing_ratios is None
    assert np.abs(fe.casing_ratios[0] * np.array(fe.params.casing.modes) + 1.0).max() < 1e-4  # tau_n = -1/n
    cs = ring.slices["casing"]
    assert np.abs(fe.D[cs, cs] - ring.D[cs, cs]).max() <= 1e-4 * np.abs(ring.D[cs, cs]).max()
    omega = 3.3 * ring.params.normalisation.omega_ref
    for f in ("2D", "3D"):
        a, b = make_contact(ring, f, g0=0.5e-3), make_contact(fe, f, g0=0.5e-3)
        assert np.abs(a.G - b.G).max() <= 1e-12 and np.abs(a.S - b.S).max() <= 1e-5 * np.abs(a.S).max()
        sa, sb = solve_static(ring, a, omega), solve_static(fe, b, omega)
        assert sa.converged and sb.converged and sa.forces_N.max() > 50.0
        assert np.abs(sa.forces_N - sb.forces_N).max() <= 1e-4 * sa.forces_N.max()
        ta, tb = run_transient(ring, a, omega, t_end=2.0), run_transient(fe, b, omega, t_end=2.0)
        Fa, Fb = ta.outputs["F_N"], tb.outputs["F_N"]
        assert np.abs(Fa - Fb).max() <= 1e-3 * Fa.max(), f


def test_fe_casing_bad_input(tmp_path):
    """A missing file, a file of another format, nodal diameters the model has not, a circle far from the tips:
    one line each naming the parameter or the file."""
    from rotorub_model.errors import ParameterError
    from rotorub_model.structure.model import build_model

    p = reference_parameters().replace(casing={"ring_thickness": 0.0135})
    good = fe_ring(p, tmp_path, 90)
    f = good.save(tmp_path / "c.json")
    (tmp_path / "other.json").write_text('{"format": "ansys-modes", "units": "SI"}')
    (tmp_path / "far.json").write_text(f.read_text().replace(f'"radius": {good.radius!r}', '"radius": 2.0'))
    for model, cls, words in (
            (tmp_path / "none.json", ParameterError, r"fe_casing.model: .*none.json: no such file"),
            (tmp_path / "other.json", FEImportError, r"format 'ansys-modes'; accepted: 'rotorub-casing-1' in 'SI'"),
            (tmp_path / "far.json", ParameterError, r"its contact circle has radius 2 m, the blade tips are at 1 m")):
        with pytest.raises(cls, match=words):
            build_model(p.replace(fe_casing={"model": str(model)}))
    with pytest.raises(ParameterError, match=r"casing.modes: \[2, 5\] but .* has modes of \[2, 3, 4\] nodal"):
        build_model(p.replace(casing={"modes": [2, 5]}, fe_casing={"model": str(f)}))
