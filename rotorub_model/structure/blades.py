"""Flexible blades clamped on the fan disk, written in the rotating frame.

Each blade j sits at angle alpha_j = 2 pi j / N (rotating frame), is clamped at the
hub radius r_d and bends with deflection v(s) = sum psi_k(s) b_k along its flexible
direction n_j = cos(beta) e_t + sin(beta) e_z (beta: stagger from the axis).

The functions psi_k: the ``n_ritz`` clamped-free polynomials of degree 2..n_ritz+1 when all are kept (the
paper's (s/l)^(k+1) up to three, the same space in a well-conditioned form beyond: structure/ritz.py); with
``n_modes < n_ritz``, a fixed-interface component-mode reduction of those polynomials (the blade root
moves with the disk, so its rigid motion is in the kinematics already and fixed-interface modes complete
it): the lowest cantilever modes at rest and at the top of the speed range (:func:`_two_speed_modes`).
More functions make the kept ones more accurate; the functions left out are the high ones, which carry
no physics of interest and would set the explicit time step (5 polynomials: 4 kHz against the
reference's 0.3 kHz, 13x the steps).

The blade is a line of point masses dm at Gauss points s; each point's position is

    r = d + (I + Theta + Theta^2 / 2) (rho0 + v n - chi e_r),   rho0 = (r_d + s) e_r,

with d, Theta the fan-disk translation and (skew) rotation taken from the shaft
dofs, and chi = 1/2 int_0^s v'^2 the radial foreshortening. The kinetic energy
T = 1/2 sum dm |r' + Omega e_z x r|^2 expanded to second order in q gives

* M  = sum dm J^T J                      (J = dr/dq at q = 0)
* G  = Omega * 2 sum dm J^T Z J           (Coriolis, Z = [e_z x])
* N  = -Omega^2 sum dm J^T P J            (spin softening, P = diag(1, 1, 0))
* Ks = -Omega^2 sum dm rho0 . d2r/dq2     (stress stiffening: foreshortening against
  the centrifugal field, plus the centrifugal coupling of disk tilt with blade and
  with the blade ring's own inertia),
* E1 = sum dm [J^T Z J + (Z rho0) . d2r/dq2] and the load -sum dm J^T Z rho0, both
  multiplied by dOmega/dt (Euler force of a changing spin speed),

and the elastic energy V = 1/2 int E I v''^2 ds gives K. The rigid part of the
blades (their mass and inertia carried by the disk) comes out of the same sums,
so disk parameters must not include the blades.

Blade damping acts in the rotating frame: stiffness-proportional, tuned to the
requested ratio on the first bending mode at rest.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from .frames import Matrices
from .params import BladeParams, Parameters
from .ritz import blade_foreshortening_polynomials, blade_polynomials, gauss
from .shaft import station_maps

Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
P = np.diag([1.0, 1.0, 0.0])


def blade_angles(p: Parameters) -> np.ndarray:
    N = p.blades.count
    return 2.0 * np.pi * np.arange(N) / N


def blade_frame(alpha: float, stagger: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(e_r, e_t, e_z, n) of a blade at angle alpha with stagger (rad)."""
    e_r = np.array([np.cos(alpha), np.sin(alpha), 0.0])
    e_t = np.array([-np.sin(alpha), np.cos(alpha), 0.0])
    e_z = np.array([0.0, 0.0, 1.0])
    n = np.cos(stagger) * e_t + np.sin(stagger) * e_z
    return e_r, e_t, e_z, n


def blade_dof_names(p: Parameters) -> list[str]:
    return [f"blade{j + 1}.b{k + 1}" for j in range(p.blades.count) for k in range(p.blades.dofs)]


def blade_basis(p: Parameters) -> np.ndarray | None:
    """(n_ritz, dofs) coefficients of the kept blade functions on the polynomials, or None when every
    polynomial is kept as it is (n_modes >= n_ritz). See :func:`_two_speed_modes`."""
    b = p.blades
    return _two_speed_modes(b, p.normalisation.speed_max * p.normalisation.omega_ref)


@lru_cache(maxsize=32)
def _two_speed_modes(b: BladeParams, omega_top: float) -> np.ndarray | None:
    """The lowest cantilever modes of the n_ritz polynomials at rest and at the top of the speed range.

    A blade of this kind stiffens fivefold over the speed range (the reference's first flap mode: 25 Hz
    at rest, 132 Hz at 12 omega_ref), so no fixed set of rest modes represents it everywhere: two rest
    modes put the first flap frequency 1.9 % off at the top speed. Modes at both ends of the range span
    the shapes in between: n_modes functions are the ceil(n_modes / 2) lowest modes at rest and the
    floor(n_modes / 2) lowest at omega_top (the blade clamped, rotating: elastic plus centrifugal
    stiffness), made M-orthonormal and rotated to the modes of the reduced blade at rest, each scaled to
    a unit tip deflection. Measured on the reference blade against 8 polynomials (docs/THEORY.md): 2
    functions hold the first flap frequency within 0.13 % over 0..omega_top (the paper's 2 polynomials:
    3.7 %), 4 hold the first two within 1.5e-4, and the highest frequency stays that of a physical mode
    (the explicit step is not set by spurious high functions: 5 polynomials reach 4 kHz).
    """
    if b.n_modes >= b.n_ritz:
        return None
    from scipy.linalg import eigh

    s, w = gauss(0.0, b.length, b.n_ritz + 8)
    psi = blade_polynomials(s, b.length, b.n_ritz)
    ddpsi = blade_polynomials(s, b.length, b.n_ritz, 2)
    dm = b.rho * b.area * w
    K = b.E * b.second_moment * (ddpsi.T * w) @ ddpsi
    M = (psi.T * dm) @ psi
    # the blade's own centrifugal stiffness (the blade-blade block of S2 + N2 in bladed_disk_matrices)
    fs = blade_foreshortening_polynomials(s, b.length, b.n_ritz)
    R = b.hub_radius + s
    KS = np.einsum("g,gkl->kl", dm * R, fs) - np.cos(np.radians(b.stagger_deg)) ** 2 * M
    n_rest = (b.n_modes + 1) // 2
    cols = [eigh(K, M)[1][:, :n_rest], eigh(K + omega_top**2 * KS, M)[1][:, : b.n_modes - n_rest]]
    V = np.linalg.qr(np.hstack(cols))[0]
    _, z = eigh(V.T @ K @ V, V.T @ M @ V)  # the reduced blade's modes at rest
    phi = V @ z
    tip = blade_polynomials(b.length, b.length, b.n_ritz)[0] @ phi
    return phi / tip


def blade_functions(p: Parameters, s, deriv: int = 0) -> np.ndarray:
    """The kept blade functions (or their derivatives) at s, shape (len(s), p.blades.dofs)."""
    b = p.blades
    psi = blade_polynomials(s, b.length, b.n_ritz, deriv)
    phi = blade_basis(p)
    return psi if phi is None else psi @ phi


def blade_foreshortening(p: Parameters, s) -> np.ndarray:
    """int_0^s psi_k' psi_m' ds' of the kept functions, shape (len(s), dofs, dofs)."""
    b = p.blades
    fs = blade_foreshortening_polynomials(s, b.length, b.n_ritz)
    phi = blade_basis(p)
    return fs if phi is None else np.einsum("ki,gkl,lm->gim", phi, fs, phi)


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def check_mistuning(p: Parameters, mistuning: Sequence[float] | np.ndarray | None) -> tuple[float, ...] | None:
    """The per-blade stiffness deviations delta_j as a tuple (None, or empty: a tuned disk), checked: one finite
    value per blade, each > -1 (the blade's stiffness factor 1 + delta_j stays positive)."""
    if mistuning is None or len(mistuning) == 0:
        return None
    from ..errors import ParameterError

    d = np.asarray(mistuning, dtype=float).ravel()
    if d.size != p.blades.count:
        raise ParameterError(f"mistuning: {d.size} values for {p.blades.count} blades; accepted: one stiffness "
                             "deviation per blade (blades.count), or none (a tuned disk)")
    for j, v in enumerate(d):
        if not (np.isfinite(v) and v > -1.0):
            raise ParameterError(f"mistuning[{j}]: {float(v)!r} out of range; accepted range (-1, inf) "
                                 f"(blade {j + 1}'s stiffness factor 1 + delta must stay positive)")
    return tuple(float(v) for v in d)


def bladed_disk_matrices(p: Parameters, n_quad: int | None = None,
                         mistuning: Sequence[float] | np.ndarray | None = None) -> Matrices:
    """Matrices of the blades on the dofs [shaft dofs, blade dofs] (coupled through the disk).

    ``mistuning``: per-blade stiffness deviations delta_j (one per blade; None or empty: tuned). Blade j's
    bending stiffness K_b and its stiffness-proportional damping D_b are scaled by (1 + delta_j): its
    frequencies at rest by sqrt(1 + delta_j), its damping ratio likewise; mass, centrifugal stiffening and the
    disk coupling are the tuned blade's (docs/THEORY.md section 10)."""
    b = p.blades
    scale = check_mistuning(p, mistuning)
    ns = 2 * p.shaft.n_ritz
    nb = b.dofs
    N = b.count
    n = ns + N * nb
    beta = np.radians(b.stagger_deg)
    T, Rm = station_maps(p, p.fan_disk.z)
    s, w = gauss(0.0, b.length, n_quad or (b.n_ritz + 8))
    psi = blade_functions(p, s)
    ddpsi = blade_functions(p, s, 2)
    fs = blade_foreshortening(p, s)
    rhoA = b.rho * b.area
    EI = b.E * b.second_moment
    Kb = EI * (ddpsi.T * w) @ ddpsi
    Mb_rest = rhoA * (psi.T * w) @ psi
    w1 = np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(Mb_rest, Kb)).real))
    Db = (2.0 * b.damping_ratio / w1) * Kb

    M = np.zeros((n, n))
    G1 = np.zeros((n, n))
    N2 = np.zeros((n, n))
    S2 = np.zeros((n, n))
    K = np.zeros((n, n))
    D = np.zeros((n, n))
    E1 = np.zeros((n, n))
    f_euler = np.zeros(n)
    for j, alpha in enumerate(blade_angles(p)):
        e_r, e_t, _, nv = blade_frame(alpha, beta)
        sl = slice(ns + j * nb, ns + (j + 1) * nb)
        K[sl, sl] += Kb if scale is None else (1.0 + scale[j]) * Kb
        D[sl, sl] += Db if scale is None else (1.0 + scale[j]) * Db
        for g in range(s.size):
            R = b.hub_radius + s[g]
            rho0 = R * e_r
            dm = rhoA * w[g]
            Jg = np.zeros((3, n))
            Jg[:, :ns] = T - skew(rho0) @ Rm
            Jg[:, sl] = np.outer(nv, psi[g])
            M += dm * Jg.T @ Jg
            G1 += 2.0 * dm * Jg.T @ Z @ Jg
            N2 -= dm * Jg.T @ P @ Jg
            Q = np.zeros((n, n))
            Q[:ns, :ns] = Rm.T @ (np.outer(rho0, rho0) - R * R * np.eye(3)) @ Rm
            # rho0 . (theta x v n) = v theta . (n x rho0) = R sin(beta) (theta . e_t) v
            X = R * np.sin(beta) * np.outer(Rm.T @ e_t, psi[g])
            Q[:ns, sl] += X
            Q[sl, :ns] += X.T
            Q[sl, sl] += -R * fs[g]
            S2 -= dm * Q
            # Euler term: d/dt(dr/dq . Omega Z r) gives dOmega/dt [J^T Z J + (Z r0) . d2r/dq2] q plus the
            # load -dOmega/dt J^T Z r0; (Z r0) = R e_t: tilt-tilt part R^2 sym(e_t e_r^T) and
            # e_t . (theta x v n) = -sin(beta) (theta . e_r) v
            Hz = np.zeros((n, n))
            Hz[:ns, :ns] = R * R * Rm.T @ (0.5 * (np.outer(e_t, e_r) + np.outer(e_r, e_t))) @ Rm
            Y = -R * np.sin(beta) * np.outer(Rm.T @ e_r, psi[g])
            Hz[:ns, sl] += Y
            Hz[sl, :ns] += Y.T
            E1 += dm * (Jg.T @ Z @ Jg + Hz)
            f_euler -= dm * Jg.T @ (Z @ rho0)
    names = [f"shaft.a{i}.{c}" for i in range(p.shaft.n_ritz) for c in ("x", "y")] + blade_dof_names(p)
    mats = Matrices(dofs=names, M=M, D=D, K=K, G1=G1, C1=np.zeros((n, n)), N2=N2, S2=S2, E1=E1)
    mats.f_euler = f_euler  # load per unit angular acceleration (blades lag when the spin speeds up)
    return mats


def blade_tip_map(p: Parameters, j: int) -> np.ndarray:
    """psi(l_b) n_j on blade j's dofs: tip displacement = map @ q_blade_j, shape (3, dofs per blade)."""
    beta = np.radians(p.blades.stagger_deg)
    nv = blade_frame(blade_angles(p)[j], beta)[3]
    psi_tip = blade_functions(p, p.blades.length)[0]
    return np.outer(nv, psi_tip)
