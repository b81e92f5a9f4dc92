"""Flexible blades clamped on the fan disk, written in the rotating frame.

Each blade j sits at angle alpha_j = 2 pi j / N (rotating frame), is clamped at the
hub radius r_d and bends with deflection v(s) = sum psi_k(s) b_k along its flexible
direction n_j = cos(beta) e_t + sin(beta) e_z (beta: stagger from the axis).

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

import numpy as np

from .frames import Matrices
from .params import Parameters
from .ritz import cantilever_basis, cantilever_foreshortening, gauss
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
    return [f"blade{j + 1}.b{k + 1}" for j in range(p.blades.count) for k in range(p.blades.n_ritz)]


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def bladed_disk_matrices(p: Parameters, n_quad: int | None = None) -> Matrices:
    """Matrices of the blades on the dofs [shaft dofs, blade dofs] (coupled through the disk)."""
    b = p.blades
    ns = 2 * p.shaft.n_ritz
    nb = b.n_ritz
    N = b.count
    n = ns + N * nb
    beta = np.radians(b.stagger_deg)
    T, Rm = station_maps(p, p.fan_disk.z)
    s, w = gauss(0.0, b.length, n_quad or (nb + 8))
    psi = cantilever_basis(s, b.length, nb)
    ddpsi = cantilever_basis(s, b.length, nb, 2)
    fs = cantilever_foreshortening(s, b.length, nb)
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
        K[sl, sl] += Kb
        D[sl, sl] += Db
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
    """psi(l_b) n_j on blade j's dofs: tip displacement = map @ q_blade_j, shape (3, n_ritz)."""
    beta = np.radians(p.blades.stagger_deg)
    nv = blade_frame(blade_angles(p)[j], beta)[3]
    psi_tip = cantilever_basis(p.blades.length, p.blades.length, p.blades.n_ritz)[0]
    return np.outer(nv, psi_tip)
