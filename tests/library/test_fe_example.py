"""The project's example blade (examples/fan_blade): a twisted fan blade meshed with gmsh, its matrices computed
with CalculiX at rest and at three speeds, imported (rotorub_model/fe/import_blade.py)."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from rotorub_model.fe import fe_bladed_disk_matrices, load_superelement, tip_point_maps
from rotorub_model.structure.params import reference_parameters
from rotorub_model.structure.shaft import shaft_matrices, station_maps

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fan_blade"
COARSE = EXAMPLE / "coarse"


def ccx_reference() -> dict:
    return json.loads((COARSE / "ccx_frequencies.json").read_text())


def test_kept_example_matches_calculix():
    """The kept superelement (14 dofs from 8892) gives CalculiX's own first eight frequencies of the same mesh
    within 0.1 % at rest and at the three speeds (measured: 1.4e-4 at worst)."""
    blade = load_superelement(COARSE / "blade.npz")
    ref = ccx_reference()
    assert ref["units"] == "N-mm-t-s" and len(ref["speeds_rad_s"]) == 4
    for job, w in zip(ref["jobs"], ref["speeds_rad_s"]):
        ccx = np.array(ref["ccx_frequencies_hz"][job][:8])
        assert np.max(np.abs(blade.frequencies(w)[:8] / ccx - 1.0)) < 1e-3, job
    assert blade.m == 14 and blade.info["spin_softening_in_fe_K"] is True
    assert 5.0 < blade.mass < 6.5  # about the reference blade's 5.8 kg


def test_example_in_the_bladed_disk():
    """Ten example blades on the reference rotor: a pure translation of the fan disk carries the ten blades'
    mass, the matrices are symmetric (M, K, D, N2, S2) and antisymmetric (G1), with the shaft's M positive
    definite, and every tip node lies in the tip plane at the reference tip radius and follows the disk's
    translation."""
    p = reference_parameters()
    blade = load_superelement(COARSE / "blade.npz")
    mats = fe_bladed_disk_matrices(p, blade)
    ns = 2 * p.shaft.n_ritz
    n = ns + p.blades.count * blade.m
    assert mats.M.shape == (n, n) and mats.dofs[-1] == f"blade{p.blades.count}.m{blade.m}"
    for key in ("M", "K", "N2", "S2", "D"):
        A = getattr(mats, key)
        assert np.abs(A - A.T).max() <= 1e-10 * np.abs(A).max(), key
    assert np.abs(mats.G1 + mats.G1.T).max() <= 1e-10 * np.abs(mats.G1).max()
    M = mats.M.copy()
    M[:ns, :ns] += shaft_matrices(p).M  # the blades alone see only the disk's six rigid motions of the shaft's ten
    assert np.linalg.eigvalsh(M).min() > 0
    T, R = station_maps(p, p.fan_disk.z)
    d = np.linalg.lstsq(np.vstack([T, R]), np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]), rcond=None)[0]
    assert np.allclose(np.vstack([T, R]) @ d, [1, 0, 0, 0, 0, 0], atol=1e-12)
    assert d @ mats.M[:ns, :ns] @ d == pytest.approx(p.blades.count * blade.mass, rel=1e-12)
    points, Jb = tip_point_maps(p, blade)
    # the tip is ground to the reference casing's 5 deg cone: every tip node's radius is R_tip - z tan(theta), z
    # axial from the disk's station; blade j's are blade 0's turned by 2 pi j / N
    tp = blade.tip_positions
    cone = p.blades.tip_radius - tp[:, 2] * np.tan(np.radians(p.contact.theta_deg))
    assert np.allclose(np.hypot(tp[:, 0], tp[:, 1]), cone, atol=1e-9)
    assert np.ptp(tp[:, 2]) > 0.1  # the chord spans 0.17 m axially: the cone makes a difference of 15 mm
    assert np.allclose(np.linalg.norm(points, axis=-1), np.linalg.norm(blade.tip_positions, axis=-1)[None, :])
    u = np.zeros(n)
    u[:ns] = d
    assert np.allclose(np.einsum("jiak,k->jia", Jb, u), [1.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.slow  # gmsh and CalculiX: four jobs on 8892 dofs and the import, about 40 s on 2 cores
@pytest.mark.skipif(shutil.which("ccx") is None or shutil.which("gmsh") is None,
                    reason="needs the Debian packages calculix-ccx and gmsh (apt-get install -y -q calculix-ccx gmsh)")
def test_example_regenerated_with_calculix(tmp_path):
    """Where gmsh and CalculiX are installed: the script meshes and solves the example again, the import of
    its CalculiX files gives CalculiX's own frequencies within 0.1 % at rest and at the three speeds, and the
    same superelement as the one kept in the repository."""
    sys.path.insert(0, str(EXAMPLE))
    try:
        import make_fan_blade
    finally:
        sys.path.pop(0)
    from rotorub_model.fe.import_blade import import_blade_command

    d = tmp_path / "fe"
    made = make_fan_blade.make(d, mesh_size=ccx_reference()["mesh_size_mm"])
    s = import_blade_command([str(d / j) for j in made["jobs"]], made["units"], str(d / "tip_nodes.txt"),
                             tmp_path / "out", coordinates=str(d / "mesh.inp"), mass_free=str(d / "free"),
                             cutoff_hz=1500.0, variants=False)
    assert max(s["max_error_vs_fe_code"]) < 1e-3
    assert s["verdict"].startswith("OK")
    new, kept = load_superelement(tmp_path / "out" / "blade.npz"), load_superelement(COARSE / "blade.npz")
    if made["dofs"] == ccx_reference()["dofs"]:  # the same mesh (gmsh's version may mesh otherwise)
        for w in made["speeds_rad_s"]:
            assert np.allclose(new.frequencies(w), kept.frequencies(w), rtol=1e-6)
