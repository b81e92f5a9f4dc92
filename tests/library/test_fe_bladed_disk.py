"""The loop closed: the built-in beam blade written as an FE model, imported and reduced, reproduces the
built-in bladed disk (rotorub_model/fe/bladed_disk.py against structure/blades.py)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy.linalg import cholesky, solve_triangular

from rotorub_model.fe import (
    fe_bladed_disk_matrices,
    load_superelement,
    read_matrix_market,
    reduce_blade,
    tip_point_maps,
)
from rotorub_model.fe.beam_blade import write_beam_blade
from rotorub_model.fe.blade import _check_tip, _frame_of, assemble_superelement
from rotorub_model.structure.blades import blade_tip_map, bladed_disk_matrices
from rotorub_model.structure.params import reference_parameters
from rotorub_model.structure.ritz import blade_polynomials
from rotorub_model.structure.shaft import shaft_matrices, station_maps

N_CONVERGED = 8  # the built-in's converged blade basis (docs/THEORY.md 3.2)


def undamped():
    p = reference_parameters()
    return p.replace(bearings=[{"name": b.name, "z": b.z, "k": b.k, "c": 0.0} for b in p.bearings],
                     blades={"damping_ratio": 0.0})


def top_speed(p) -> float:
    return p.normalisation.speed_max * p.normalisation.omega_ref


def read(info, **kw):
    return read_matrix_market(info["mass"], info["stiffness"], info["dofs"], info["coordinates"], "SI",
                              info["speeds"], mass_dofs=info["mass_dofs"], **kw)


@pytest.fixture(scope="module")
def beam(tmp_path_factory):
    """The reference blade as 120 Euler-Bernoulli elements, stiffness at rest, half and top speed."""
    p = undamped()
    w = top_speed(p)
    info = write_beam_blade(p, tmp_path_factory.mktemp("beam"), speeds=(0.0, w / 2, w), n_elements=120)
    fe = read(info)
    blade = reduce_blade(fe, [info["tip_node"]], cutoff_hz=3000.0, axis_direction=info["axis_direction"],
                         damping_ratio=0.0)  # the default basis: modes at rest, the top speed's condensed
    return p, info, fe, blade


def rotor_frequencies(p, mats, omega: float, n: int = 16) -> np.ndarray:
    """The lowest rotating-frame frequencies [Hz] of shaft + blades (undamped, gyroscopic), from the
    M-orthonormalised first-order form (the 8-polynomial basis' mass matrix is ill-conditioned)."""
    sh = shaft_matrices(p)
    ns, N = len(sh.dofs), len(mats.dofs)

    def full(k):
        A = getattr(mats, k).copy()
        A[:ns, :ns] += getattr(sh, k)
        return A

    M, K, D, G1, N2, S2, C1 = (full(k) for k in ("M", "K", "D", "G1", "N2", "S2", "C1"))
    Kw = K + omega**2 * (S2 + N2) + omega * C1 + omega**4 * getattr(mats, "S4", 0.0)
    L = cholesky(M, lower=True)

    def congruent(A):
        return solve_triangular(L, solve_triangular(L, A, lower=True).T, lower=True).T

    A = np.block([[np.zeros((N, N)), np.eye(N)], [-congruent(Kw), -congruent(D + omega * G1)]])
    lam = np.linalg.eigvals(A)
    return np.sort(lam.imag[lam.imag > 1e-6])[:n] / (2 * np.pi)


def test_coupling_terms_equal_builtin_on_the_same_basis(tmp_path):
    """With FE nodes at the built-in blade's quadrature points (its point masses) and the built-in's eight
    polynomials (its own functions, blade_polynomials) as the basis, every matrix of the bladed disk but the
    blade's own stiffness is the built-in's
    to rounding: rigid mass and inertia, Coriolis, spin softening, the centrifugal and Euler couplings of disk
    tilt with the blade, and the blades' inertia load under angular acceleration."""
    p = undamped().replace(blades={"n_ritz": N_CONVERGED, "n_modes": N_CONVERGED})
    w = top_speed(p)
    info = write_beam_blade(p, tmp_path, speeds=(0.0, w / 2, w), layout="gauss")
    fe = read(info)
    frame = _frame_of(fe, (0.0, 0.0, 0.0), info["axis_direction"], None)
    tips, rows = _check_tip(fe, [info["tip_node"]])
    s = fe.coordinates_of(fe.dof_nodes)[:, 0] - p.blades.hub_radius
    V = np.where((fe.dof_components == 2)[:, None], blade_polynomials(s, p.blades.length, N_CONVERGED),
                 blade_polynomials(s, p.blades.length, N_CONVERGED, 1))
    blade = assemble_superelement(fe, frame, V, tips, rows, 2, True, 0.0)
    fm, bi = fe_bladed_disk_matrices(p, blade), bladed_disk_matrices(p)
    ns = 2 * p.shaft.n_ritz
    for key in ("M", "G1", "N2", "E1", "S2"):
        A, B = getattr(fm, key), getattr(bi, key)
        d = np.abs(A - B)
        if key == "S2":  # the blade's own stress stiffening comes from the FE prestress (tested below)
            for j in range(p.blades.count):
                sl = slice(ns + N_CONVERGED * j, ns + N_CONVERGED * (j + 1))
                d[sl, sl] = 0.0
        assert d.max() < 1e-12 * np.abs(B).max(), key
    assert np.abs(fm.f_euler - bi.f_euler).max() < 1e-12 * np.abs(bi.f_euler).max()
    # the tip map: the FE tip node's displacement is the built-in's tip map on the same functions
    points, Jb = tip_point_maps(p, blade)
    T, R = station_maps(p, p.fan_disk.z)
    for j in (0, 3):
        tip = blade_tip_map(p, j)
        assert np.allclose(Jb[j, 0, :, ns + N_CONVERGED * j:ns + N_CONVERGED * (j + 1)], tip, atol=1e-12)
        a = 2 * np.pi * j / p.blades.count
        assert np.allclose(points[j, 0], p.blades.tip_radius * np.array([np.cos(a), np.sin(a), 0.0]))


def test_frequencies_of_the_bladed_disk_match_builtin(beam):
    """At rest and at the top speed (Coriolis, stiffening, softening, disk coupling all in), the 16 lowest
    frequencies of shaft + ten imported blades are the converged built-in's (8 polynomials) within 1e-4;
    measured 4.4e-5, the lumped-mass discretisation of 120 elements (O(h^2))."""
    p, _, _, blade = beam
    p8 = p.replace(blades={"n_ritz": N_CONVERGED, "n_modes": N_CONVERGED})
    fm, bi = fe_bladed_disk_matrices(p, blade), bladed_disk_matrices(p8)
    for w in (0.0, top_speed(p)):
        f_fe, f_bi = rotor_frequencies(p, fm, w), rotor_frequencies(p8, bi, w)
        assert np.max(np.abs(f_fe / f_bi - 1.0)) < 1e-4, (w, f_fe, f_bi)


def test_a_wrong_coupling_term_fails_the_frequency_check(beam):
    """Each coupling term matters at the top speed: its sign flipped, or the blade's rigid mass or inertia 1 %
    off, the frequencies leave the 1e-4 band of the check above (by 1.6e-3 at least)."""
    p, _, _, blade = beam
    p8 = p.replace(blades={"n_ritz": N_CONVERGED, "n_modes": N_CONVERGED})
    w = top_speed(p)
    ref = rotor_frequencies(p8, bladed_disk_matrices(p8), w)

    def error(b):
        return np.max(np.abs(rotor_frequencies(p, fe_bladed_disk_matrices(p, b), w) / ref - 1.0))

    assert error(blade) < 1e-4
    for key in ("centrifugal_coupling", "second_moments", "basis_coriolis", "basis_softening", "K1"):
        b = copy.deepcopy(blade)
        setattr(b, key, -getattr(b, key))
        assert error(b) > 1e-3, key
    for block in ((slice(0, 3), slice(0, 3)), (slice(3, 6), slice(3, 6))):
        b = copy.deepcopy(blade)
        b.basis_mass = b.basis_mass.copy()
        b.basis_mass[block] *= 1.01
        assert error(b) > 1e-3, block
    b = copy.deepcopy(blade)
    b.basis_mass = b.basis_mass.copy()
    b.basis_mass[:6, 6:] *= -1.0
    b.basis_mass[6:, :6] *= -1.0
    assert error(b) > 1e-3


def test_blade_alone_matches_full_fe_and_builtin(beam, tmp_path):
    """The reduced blade's clamped frequencies are the full FE model's within 1e-4 at every speed given
    (7 modes at rest, the top speed's condensed); against the built-in's converged ones the first is
    within 1e-4, and the second's difference
    (1.1e-4 at rest, 1.7e-4 at the top speed with 120 elements) is the lumped masses' O(h^2): it falls
    threefold or more with twice the elements, to 5e-5."""
    p, _, fe, blade = beam
    ref = blade.reference
    for k in range(3):
        full, red = ref[f"full_{k}_hz" if k else "full_rest_hz"][:3], ref[f"reduced_{k}_hz"][:3]
        assert np.max(np.abs(red / full - 1.0)) < 1e-4
    from rotorub_model.analyses.discretisation import frequencies

    p8 = p.replace(blades={"n_ritz": N_CONVERGED, "n_modes": N_CONVERGED})
    w = top_speed(p)
    info = write_beam_blade(p, tmp_path, speeds=(0.0, w / 2, w), n_elements=240)
    fine = reduce_blade(read(info), [info["tip_node"]], cutoff_hz=3000.0,
                        axis_direction=info["axis_direction"], damping_ratio=0.0)
    for omega in (0.0, w):
        f_bi = frequencies(p8, omega)[:2] / (2 * np.pi)
        err = blade.frequencies(omega)[:2] / f_bi - 1.0
        err_fine = fine.frequencies(omega)[:2] / f_bi - 1.0
        assert abs(err[0]) < 1e-4
        assert err[1] / err_fine[1] > 3.0 and abs(err_fine[1]) < 6e-5
    assert blade.mass == pytest.approx(p.blades.mass, rel=1e-12)
    assert blade.info["spin_softening_in_fe_K"] is True


def test_spin_softening_convention_is_measured(tmp_path, beam):
    """An FE code that leaves the spin softening out of K(Omega) gives the same blade: the importer measures
    the convention on the matrices and adds -Phi^T M P Phi where it is missing."""
    p, info0, _, blade = beam
    w = top_speed(p)
    info = write_beam_blade(p, tmp_path, speeds=(0.0, w / 2, w), n_elements=120, spin_softening=False)
    b2 = reduce_blade(read(info), [info["tip_node"]], cutoff_hz=3000.0,
                        axis_direction=info["axis_direction"], damping_ratio=0.0)
    assert b2.info["spin_softening_in_fe_K"] is False
    # not to rounding: the condensed directions come from the top speed's modes, of another K(Omega)
    assert np.allclose(b2.frequencies(w), blade.frequencies(w), rtol=1e-6)
    from rotorub_model.errors import FEImportError

    with pytest.raises(FEImportError, match="declared spin_softening_in_K = True"):
        reduce_blade(read(info, spin_softening_in_K=True), [info["tip_node"]], axis_direction=info["axis_direction"])


def test_superelement_round_trip(tmp_path, beam):
    """The superelement file gives back the same bladed disk, bit for bit."""
    p, _, _, blade = beam
    path = blade.save(tmp_path / "blade.npz")
    again = load_superelement(path)
    a, b = fe_bladed_disk_matrices(p, blade), fe_bladed_disk_matrices(p, again)
    for key in ("M", "D", "K", "G1", "N2", "S2", "E1", "S4"):
        assert np.array_equal(getattr(a, key), getattr(b, key)), key
    assert a.dofs == b.dofs and a.dofs[2 * p.shaft.n_ritz] == "blade1.m1"


def test_one_stiffness_keeps_the_spin_softening_only(tmp_path):
    """From the rest stiffness alone the blade gets the spin softening from M and the coordinates, exactly the
    built-in's -cos^2(beta) M on the flap direction, and no stress stiffening (it needs the prestress)."""
    p = undamped()
    info = write_beam_blade(p, tmp_path, speeds=(0.0,), n_elements=60)
    blade = reduce_blade(read(info), [info["tip_node"]], axis_direction=info["axis_direction"])
    assert blade.info["order"] == 0
    assert np.abs(blade.stress_stiffening).max() < 1e-12 * np.abs(blade.K0).max()
    beta = np.radians(p.blades.stagger_deg)
    assert np.allclose(blade.K1, -np.cos(beta) ** 2 * blade.M, rtol=1e-12, atol=1e-12 * np.abs(blade.M).max())
