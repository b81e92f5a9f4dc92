"""Shaft (Euler–Bernoulli hollow beam), rigid disks and isotropic bearings.

All three are axisymmetric, so they are built per transverse direction in the
fixed frame and transformed with :func:`rotorub_model.structure.frames.axisymmetric_to_rotating`.
Energies (per direction, Ritz u(z) = sum phi_i(z) a_i):

* beam: T = 1/2 int rho A u'^2 + rho I u_z'^2 dz, V = 1/2 int E I (u'')^2 dz,
  gyroscopic coefficient rho (2I) int phi' phi' (polar = 2 x diametral for a circle);
* disk at z_d: T = 1/2 m u^2 + 1/2 Id u_z^2, gyroscopic coefficient Ip phi'(z_d) phi'(z_d);
* bearing at z_b: V = 1/2 k u(z_b)^2, dissipation 1/2 c u(z_b)^2.

Ritz basis: the n lowest free-vibration modes (per direction, non-rotating) of the
shaft line — beam + disks + bearings + the blades' rigid mass and inertia lumped
on the fan disk — computed once on an auxiliary Legendre basis of N_AUX polynomials
(a component-mode basis). The first of them are the bearing-dominated "suspension"
modes, the next ones bend the shaft. With a plain Legendre basis of degree 4 the
38-dof model put the span-bending critical 20 % too high (526 vs 433 rad/s); the
modal basis gives the converged first two criticals with 5 functions
(tests/test_structure.py checks the convergence).

Dof names: ``shaft.a{i}.x`` / ``shaft.a{i}.y`` — amplitude of Ritz function i along
the rotating x and y axes (each function scaled to a largest displacement of 1 m).
"""

from __future__ import annotations

import numpy as np

from .frames import Matrices, axisymmetric_to_rotating, pair_names
from .params import Parameters
from .ritz import gauss, legendre_basis

N_AUX = 16  # auxiliary Legendre functions for the component-mode basis (converged, see tests)


def shaft_dof_names(n: int) -> list[str]:
    return pair_names("shaft.a", [str(i) for i in range(n)])


def _legendre_matrices(p: Parameters, n_poly: int, fn) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    s = p.shaft
    z, w = gauss(0.0, s.length, n_poly + 4)
    phi = fn(z, 0)
    dphi = fn(z, 1)
    ddphi = fn(z, 2)
    A, I = s.area, s.second_moment
    M1 = s.rho * A * (phi.T * w) @ phi + s.rho * I * (dphi.T * w) @ dphi
    Gp = s.rho * 2 * I * (dphi.T * w) @ dphi
    K1 = s.E * I * (ddphi.T * w) @ ddphi
    C1 = np.zeros((phi.shape[1], phi.shape[1]))
    for d in p.disks:
        f, df = fn(d.z, 0)[0], fn(d.z, 1)[0]
        M1 += d.mass * np.outer(f, f) + d.Id * np.outer(df, df)
        Gp += d.Ip * np.outer(df, df)
    for b in p.bearings:
        f = fn(b.z, 0)[0]
        K1 += b.k * np.outer(f, f)
        C1 += b.c * np.outer(f, f)
    return M1, C1, K1, Gp


_BASIS_CACHE: dict = {}


def shaft_basis_coefficients(p: Parameters) -> np.ndarray:
    """Legendre coefficients (N_AUX x n) of the n component-mode Ritz functions."""
    key = (p.shaft, p.bearings, p.disks, p.blades)
    if key in _BASIS_CACHE:
        return _BASIS_CACHE[key]
    from scipy.linalg import eigh

    L = p.shaft.length
    M1, _, K1, _ = _legendre_matrices(p, N_AUX, lambda z, d: legendre_basis(z, L, N_AUX, d))
    b = p.blades
    m_b = b.count * b.mass
    ip_b = b.count * b.rho * b.area * ((b.tip_radius**3 - b.hub_radius**3) / 3.0)
    f = legendre_basis(p.fan_disk.z, L, N_AUX)[0]
    df = legendre_basis(p.fan_disk.z, L, N_AUX, 1)[0]
    M1 = M1 + m_b * np.outer(f, f) + 0.5 * ip_b * np.outer(df, df)
    _, vec = eigh(K1, M1, subset_by_index=[0, p.shaft.n_ritz - 1])
    zz = np.linspace(0.0, L, 401)
    disp = legendre_basis(zz, L, N_AUX) @ vec
    vec = vec / disp[np.argmax(np.abs(disp), axis=0), np.arange(vec.shape[1])]
    _BASIS_CACHE[key] = vec
    return vec


def shaft_functions(p: Parameters, z: np.ndarray | float, deriv: int = 0) -> np.ndarray:
    """Ritz functions (or their z-derivatives) at z, shape (len(z), n_ritz)."""
    return legendre_basis(z, p.shaft.length, N_AUX, deriv) @ shaft_basis_coefficients(p)


def shaft_per_direction(p: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fixed-frame per-direction matrices (M1, C1, K1, Gp) of shaft + disks + bearings."""
    return _legendre_matrices(p, N_AUX, lambda z, d: shaft_functions(p, z, d))


def shaft_matrices(p: Parameters) -> Matrices:
    """Rotating-frame matrices of the shaft line (harmonic n = 1)."""
    M1, C1, K1, Gp = shaft_per_direction(p)
    return axisymmetric_to_rotating(M1, C1, K1, Gp, 1, shaft_dof_names(p.shaft.n_ritz))


def station_maps(p: Parameters, z: float) -> tuple[np.ndarray, np.ndarray]:
    """Maps from shaft dofs to the translation and rotation of the section at z.

    Returns (T, R), each of shape (3, 2n): translation = T q_shaft (z component 0),
    rotation vector = R q_shaft with rotation (-w', u', 0) (small angles: the section
    turns about y by u' and about x by -w').
    """
    n = p.shaft.n_ritz
    f = shaft_functions(p, z)[0]
    df = shaft_functions(p, z, 1)[0]
    T = np.zeros((3, 2 * n))
    R = np.zeros((3, 2 * n))
    T[0, 0::2] = f
    T[1, 1::2] = f
    R[0, 1::2] = -df
    R[1, 0::2] = df
    return T, R
