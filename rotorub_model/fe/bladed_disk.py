"""The bladed disk of imported blades: the same :class:`~rotorub_model.structure.frames.Matrices` as the
built-in beams (structure/blades.py, ``bladed_disk_matrices``), from a :class:`ReducedBlade`.

Blade j sits at alpha_j = 2 pi j / N, its frame the blade frame turned by alpha_j about e_z. The root's rigid
motion in blade j's frame is [t; theta] = A_j q_shaft, A_j = [Rz(alpha_j)^T T; Rz(alpha_j)^T R] with (T, R)
the fan disk's station maps (structure/shaft.py), and blade j's extended coordinates are
[t; theta; q_j] = J_j q. Every term of the built-in derivation (structure/blades.py) then reads:

* M += J_j^T basis_mass J_j, G1 += J_j^T basis_coriolis J_j, N2 += J_j^T basis_softening J_j,
  E1 += J_j^T basis_euler J_j, f_euler += J_j^T basis_euler_load;
* S2, shaft-shaft: -R_j^T (sym(P C) - tr(P C) I) R_j (centrifugal tilt terms, C the second moments);
  shaft-blade: -R_j^T W (centrifugal coupling of disk tilt with the blade); blade-blade: the stress
  stiffening K1 + Phi^T M P Phi;
* E1, shaft-shaft: R_j^T sym(Z C) R_j; shaft-blade: R_j^T Y;
* K, D: the blade's K0 and modal damping on its own block; and ``S4`` (Omega^4 term of the prestressed
  stiffness, K2): an extra the built-in blades do not have (their prestress is linear in Omega^2).

With R_j = Rz(alpha_j)^T R. Blade dof names ``blade{j}.m{k}`` (k-th reduced mode of blade j, tip-normalised).

The contact contract (:func:`tip_point_maps`): for every blade and tip node, the rest position in the
rotating frame and the 3 x n map from the bladed disk's dofs to the node's displacement (disk translation
and tilt plus the blade's own deflection), as ``contact.geometry.ContactGeometry.points`` / ``Jb`` hold them
for the built-in tips.
"""

from __future__ import annotations

import numpy as np

from ..structure.frames import Matrices
from ..structure.params import Parameters
from ..structure.shaft import shaft_dof_names, station_maps
from ..structure.tips import tip_node_maps
from .blade import ReducedBlade
from .rotating import P3, Z3


def rz(alpha: float) -> np.ndarray:
    c, s = np.cos(alpha), np.sin(alpha)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def fe_blade_dof_names(count: int, m: int) -> list[str]:
    return [f"blade{j + 1}.m{k + 1}" for j in range(count) for k in range(m)]


def fe_bladed_disk_matrices(p: Parameters, blade: ReducedBlade) -> Matrices:
    """Matrices of ``p.blades.count`` imported blades on the dofs [shaft dofs, blade dofs], coupled through
    the fan disk (``p.blades`` gives the count only; the blade itself is ``blade``). ``f_euler`` and ``S4``
    are attached as attributes (as ``bladed_disk_matrices`` attaches f_euler)."""
    ns = 2 * p.shaft.n_ritz
    m = blade.m
    N = p.blades.count
    n = ns + N * m
    T, Rm = station_maps(p, p.fan_disk.z)
    C = blade.second_moments
    PC = P3 @ C
    Q_ss = 0.5 * (PC + PC.T) - np.trace(PC) * np.eye(3)
    ZC = Z3 @ C
    H_ss = 0.5 * (ZC + ZC.T)
    S2_bb = blade.stress_stiffening
    D_bb = blade.D
    out = {k: np.zeros((n, n)) for k in ("M", "D", "K", "G1", "C1", "N2", "S2", "E1", "S4")}
    f_euler = np.zeros(n)
    for j in range(N):
        alpha = 2.0 * np.pi * j / N
        R = rz(alpha)
        A = np.vstack([R.T @ T, R.T @ Rm])
        Jj = np.zeros((6 + m, n))
        Jj[:6, :ns] = A
        sl = slice(ns + j * m, ns + (j + 1) * m)
        Jj[6:, sl] = np.eye(m)
        out["M"] += Jj.T @ blade.basis_mass @ Jj
        out["G1"] += Jj.T @ blade.basis_coriolis @ Jj
        out["N2"] += Jj.T @ blade.basis_softening @ Jj
        out["E1"] += Jj.T @ blade.basis_euler @ Jj
        f_euler += Jj.T @ blade.basis_euler_load
        Rj = R.T @ Rm
        S2 = out["S2"]
        S2[:ns, :ns] -= Rj.T @ Q_ss @ Rj
        X = Rj.T @ blade.centrifugal_coupling
        S2[:ns, sl] -= X
        S2[sl, :ns] -= X.T
        S2[sl, sl] += S2_bb
        E1 = out["E1"]
        E1[:ns, :ns] += Rj.T @ H_ss @ Rj
        Y = Rj.T @ blade.euler_coupling
        E1[:ns, sl] += Y
        E1[sl, :ns] += Y.T
        out["K"][sl, sl] += blade.K0
        out["D"][sl, sl] += D_bb
        out["S4"][sl, sl] += blade.K2
    names = shaft_dof_names(p.shaft.n_ritz) + fe_blade_dof_names(N, m)
    mats = Matrices(dofs=names, **{k: out[k] for k in ("M", "D", "K", "G1", "C1", "N2", "S2", "E1")})
    mats.f_euler = f_euler
    mats.S4 = out["S4"]  # K(Omega) gains Omega^4 S4 (zero for a prestress linear in Omega^2)
    return mats


def tip_point_maps(p: Parameters, blade: ReducedBlade) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, n_t, 3), Jb (N, n_t, 3, n)): every tip node's rest position in the rotating frame (origin at
    the fan disk's centre, z axial from the disk's station) and the map from the bladed disk's dofs [shaft,
    blades] to its displacement: t + theta x rho0 + Rz(alpha_j) (tip_recovery @ q_j) (the contact's own,
    :func:`rotorub_model.structure.tips.tip_node_maps`, which the contact reads)."""
    return tip_node_maps(p, blade)
