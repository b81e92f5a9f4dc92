"""Flexible casing: elastic thin ring (inextensional in-plane modes) on an isotropic suspension.

Fixed-frame energies, with the ring's radial displacement at fixed-frame angle a
u(a) = sum_n A_n cos(n a) + B_n sin(n a) and the inextensional tangential
displacement w(a) = -(1/n)(A_n sin(n a) - B_n cos(n a)) (so u + dw/da = 0):

* ring mode n: modal mass  m_n = rho A R pi (1 + 1/n^2),
  modal stiffness k_n = E I (n^2 - 1)^2 pi / R^3  (curvature change (u + u'')/R^2),
  which reproduce the thin-ring frequency w_n^2 = E I n^2 (n^2-1)^2 / (rho A R^4 (n^2+1));
* rigid translation (x, y): mass m_c, suspension k_t, c_t;
* rigid tilt (phi about y, -phi about x as for the shaft sections): inertia I_c, k_r, c_r.

The casing does not spin, so in the rotating frame each (cos, sin) pair of harmonic n
turns at -n Omega: Coriolis 2 n Omega M J, softening -n^2 Omega^2 M and circulation
n Omega C J (see :mod:`rotorub_model.structure.frames`).

Ring geometry: mid-surface radius R = blade tip radius + ring thickness / 2 (the
nominal clearance, millimetres, is neglected in the ring's stiffness and mass).
Dof names: casing.t.x/y (translation), casing.r.x/y (tilt as slopes: rotation about
y by r.x, about x by -r.y), casing.n{n}.x/y (ring mode n, cos/sin amplitudes of the
radial displacement in the rotating frame).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .frames import Matrices, axisymmetric_to_rotating, block_diag
from .params import Parameters


def ring_radius(p: Parameters) -> float:
    return p.blades.tip_radius + 0.5 * p.casing.ring_thickness


def ring_modal(p: Parameters, n: int) -> tuple[float, float]:
    """(modal mass, modal stiffness) of the ring mode with n nodal diameters."""
    c = p.casing
    R = ring_radius(p)
    A = c.ring_thickness * c.ring_width
    I = c.ring_width * c.ring_thickness**3 / 12.0
    m = c.rho * A * R * np.pi * (1.0 + 1.0 / n**2)
    k = c.E * I * (n * n - 1) ** 2 * np.pi / R**3
    return m, k


def casing_matrices(p: Parameters, modal: Callable[[int], tuple[float, float, float]] | None = None) -> Matrices:
    """The casing block: rigid translation and tilt on the suspension, then one mode pair per nodal diameter of
    ``p.casing.modes``. ``modal``: n -> (modal mass, modal stiffness, damping ratio) in place of the thin ring's
    (an FE casing's modes, fe/casing_modes.py); the dofs are the same."""
    c, s = p.casing, p.suspension
    one = np.ones((1, 1))
    zero = np.zeros((1, 1))
    parts = [
        axisymmetric_to_rotating(c.mass * one, s.c_translation * one, s.k_translation * one, zero, 1,
                                 ["casing.t.x", "casing.t.y"]),
        axisymmetric_to_rotating(c.tilt_inertia * one, s.c_rotation * one, s.k_rotation * one, zero, 1,
                                 ["casing.r.x", "casing.r.y"]),
    ]
    for n in c.modes:
        m, k, zeta = modal(n) if modal is not None else (*ring_modal(p, n), c.damping_ratio)
        cn = 2.0 * zeta * np.sqrt(k * m)
        parts.append(axisymmetric_to_rotating(m * one, cn * one, k * one, zero, n,
                                              [f"casing.n{n}.x", f"casing.n{n}.y"]))
    return block_diag(parts)


def casing_point_map(p: Parameters, point: np.ndarray, tau: np.ndarray | None = None,
                     zeta: np.ndarray | None = None) -> np.ndarray:
    """Displacement of the casing inner-surface point at rest position ``point``.

    ``point`` = (x, y, z) in the rotating frame with z measured from the blade-tip
    plane. Returns D (3 x n_casing) with displacement = D q_casing: rigid translation,
    tilt about the casing centre of gravity (at z_cg), and ring radial u and
    inextensional tangential w at the point's angle (mid-surface values).
    ``tau``, ``zeta``: an FE casing's tangential and axial ratios of each of p.casing.modes (per unit radial
    amplitude, docs/THEORY.md 9.6) in place of the thin ring's -1/n and 0.
    """
    c = p.casing
    x, y, z = point
    alpha = np.arctan2(y, x)
    e_r = np.array([np.cos(alpha), np.sin(alpha), 0.0])
    e_t = np.array([-np.sin(alpha), np.cos(alpha), 0.0])
    ncol = 4 + 2 * len(c.modes)
    D = np.zeros((3, ncol))
    D[0, 0] = 1.0
    D[1, 1] = 1.0
    arm = np.array([x, y, z - c.z_cg])
    # rotation vector (-r.y, r.x, 0): displacement = theta x arm
    for col, theta in ((2, np.array([0.0, 1.0, 0.0])), (3, np.array([-1.0, 0.0, 0.0]))):
        D[:, col] = np.cross(theta, arm)
    for i, n in enumerate(c.modes):
        u_c, u_s = np.cos(n * alpha), np.sin(n * alpha)
        if tau is None:
            w_c, w_s = -np.sin(n * alpha) / n, np.cos(n * alpha) / n
            D[:, 4 + 2 * i] = u_c * e_r + w_c * e_t
            D[:, 5 + 2 * i] = u_s * e_r + w_s * e_t
        else:  # an FE casing's mode: w = tau_n A sin n(a - a0), v = zeta_n A cos n(a - a0)
            e_z = np.array([0.0, 0.0, 1.0])
            D[:, 4 + 2 * i] = u_c * e_r + tau[i] * u_s * e_t + zeta[i] * u_c * e_z
            D[:, 5 + 2 * i] = u_s * e_r - tau[i] * u_c * e_t + zeta[i] * u_s * e_z
    return D
