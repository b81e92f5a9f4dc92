"""The blade frame and the rotating-frame operators built from an FE model's mass matrix and coordinates.

Blade frame (what every imported quantity is expressed in): origin on the spin axis at the fan disk's
station, e_z the spin axis (spin positive about +e_z), e_x the radial direction through the blade's centre of
mass, e_y = e_z x e_x (the spin direction at the blade). Blade j of the disk is this frame turned by
alpha_j = 2 pi j / N about e_z, exactly as the built-in blades (structure/blades.py).

Operators on a dof vector (the file's axes; Z = [e_z x], P = I - e_z e_z^T):

* rigid-body modes of the blade about the frame's origin (6 columns: translations along e_x, e_y, e_z,
  rotations about them): translation rows t + theta x (X - o), rotation rows theta;
* the nodewise maps Z_n, P_n: the 3 x 3 map applied to each node's translation, rotation rows left at zero.

Why nodewise maps are exact for solids: when every displacement component of an element uses the same
scalar shape functions (solid elements, lumped masses), the field Z u is interpolated by the nodal values
Z u_i, so int rho a . (Z b) dV = a^T M Z_n b exactly. Rotational dofs (beams, shells) get no rotating-frame
inertia terms (their rows of Z_n, P_n are zero): the rotary inertia of beam and shell sections is counted in
the mass and in the blade's rigid inertia, not in its Coriolis or spin-softening terms (an approximation of
the order of (section size / span)^2, that the mesh does not refine away; exact for beams with lumped
translational masses).

K(Omega) from stiffness at several speeds: K = K0 + Omega^2 K1 + Omega^4 K2, least squares on the reduced
matrices (:func:`identify_speed_terms`). Whether the FE code's K(Omega) holds the spin softening
-Omega^2 M P is measured on the matrices (:func:`spin_softening_fraction`): K1 applied to a uniform
translation is zero for the stress stiffening (a rigid translation does not strain), so away from the root it
is -M P applied to that translation if the softening is in, zero if not. CalculiX's is in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import FEImportError

Z3 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
P3 = np.diag([1.0, 1.0, 0.0])


def skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@dataclass(frozen=True)
class BladeFrame:
    """origin (3,) [m] and axes (3, 3), rows e_x, e_y, e_z, both in the file's axes (SI)."""

    origin: np.ndarray
    axes: np.ndarray

    def to_blade(self, xyz: np.ndarray) -> np.ndarray:
        """Positions (.., 3) in the file's axes -> blade frame."""
        return (np.asarray(xyz) - self.origin) @ self.axes.T


def blade_frame(coords: np.ndarray, masses: np.ndarray, axis_origin=(0.0, 0.0, 0.0),
                axis_direction=(0.0, 0.0, 1.0), radial_direction=None) -> BladeFrame:
    """The blade frame from the spin axis (a point on it at the disk's station and its direction, file axes,
    SI) and the blade's centre of mass (``masses``: a nodal mass per coordinate row), or a given radial
    direction."""
    a = np.asarray(axis_direction, dtype=float)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise FEImportError(f"axis_direction: {axis_direction!r}; accepted: a non-zero 3-vector")
    ez = a / np.linalg.norm(a)
    o = np.asarray(axis_origin, dtype=float)
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise FEImportError(f"axis_origin: {axis_origin!r}; accepted: a 3-vector")
    if radial_direction is None:
        if masses.sum() <= 0:
            raise FEImportError("mass: the blade's mass is not positive")
        c = (masses[:, None] * coords).sum(0) / masses.sum() - o
        where = "the blade's centre of mass"
    else:
        c = np.asarray(radial_direction, dtype=float)
        where = "radial_direction"
    r = c - (c @ ez) * ez
    if np.linalg.norm(r) < 1e-9 * max(1.0, np.abs(coords).max()):
        raise FEImportError(f"{where} lies on the spin axis: no radial direction (check axis_origin, axis_direction)")
    ex = r / np.linalg.norm(r)
    return BladeFrame(origin=o, axes=np.vstack([ex, np.cross(ez, ex), ez]))


def node_rows(nodes: np.ndarray, comps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each distinct node with translations: (unique nodes, (U, 3) row index of its x, y, z, -1 if absent)."""
    un, inv = np.unique(nodes, return_inverse=True)
    rows = -np.ones((un.size, 3), dtype=np.int64)
    t = comps <= 3
    rows[inv[t], comps[t] - 1] = np.flatnonzero(t)
    return un, rows


def nodewise(A: np.ndarray, nodes: np.ndarray, comps: np.ndarray) -> sp.csr_matrix:
    """The sparse map applying the 3 x 3 A (file axes) to each node's translation; rotation rows zero."""
    _, rows = node_rows(nodes, comps)
    I, J, V = [], [], []
    for a in range(3):
        for b in range(3):
            if A[a, b] == 0.0:
                continue
            ok = (rows[:, a] >= 0) & (rows[:, b] >= 0)
            I.append(rows[ok, a])
            J.append(rows[ok, b])
            V.append(np.full(ok.sum(), A[a, b]))
    n = nodes.size
    if not I:
        return sp.csr_matrix((n, n))
    return sp.csr_matrix((np.concatenate(V), (np.concatenate(I), np.concatenate(J))), shape=(n, n))


def field(values: np.ndarray, nodes: np.ndarray, comps: np.ndarray, node_index: dict[int, int]) -> np.ndarray:
    """Dof vector of a nodal vector field: ``values`` (N, 3) per coordinate row (file axes), translation rows."""
    out = np.zeros(nodes.size)
    t = comps <= 3
    idx = np.array([node_index[int(k)] for k in nodes[t]], dtype=np.int64)
    out[t] = values[idx, comps[t] - 1]
    return out


def rigid_modes(frame: BladeFrame, nodes: np.ndarray, comps: np.ndarray, xyz_rows: np.ndarray) -> np.ndarray:
    """(n, 6) rigid-body modes about the frame's origin: translations along e_x, e_y, e_z, rotations about them
    (file components). ``xyz_rows``: (n, 3) the position of each row's node (file axes, SI)."""
    R = np.zeros((nodes.size, 6))
    t = comps <= 3
    c = comps - 1
    for k in range(3):
        e = frame.axes[k]
        R[t, k] = e[c[t]]
        # rotation about e: translation e x (X - o), rotation rows e
        disp = np.cross(e, xyz_rows[t] - frame.origin)
        R[t, 3 + k] = disp[np.arange(disp.shape[0]), c[t]]
        R[~t, 3 + k] = e[c[~t] - 3]
    return R


def frame_operators(frame: BladeFrame, nodes: np.ndarray, comps: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Z_n, P_n (nodewise, file axes) for the spin axis e_z of ``frame``."""
    ez = frame.axes[2]
    return nodewise(skew(ez), nodes, comps), nodewise(np.eye(3) - np.outer(ez, ez), nodes, comps)


def spin_softening_fraction(K0: sp.spmatrix, Kw: sp.spmatrix, omega: float, M: sp.spmatrix, Pn: sp.spmatrix,
                            frame: BladeFrame, nodes: np.ndarray, comps: np.ndarray) -> float:
    """How much of -Omega^2 M P is in K(Omega) - K0: 1 when the FE code put the spin softening in its
    stiffness, 0 when not (least squares over the rows away from the root, both in-plane directions).
    ``M``, ``Pn``: the mass and the nodewise P on the stiffness' (free) dofs."""
    num = den = 0.0
    Kscale = abs(K0).max()
    t = comps <= 3
    for k in range(2):  # the two in-plane directions of the blade frame
        v = np.zeros(nodes.size)
        v[t] = frame.axes[k][comps[t] - 1]
        if not v.any():
            continue
        free = np.abs(K0 @ v) < 1e-9 * Kscale * np.abs(v).max()  # away from the root: a translation loads nothing
        r = ((Kw - K0) @ v)[free]
        m = -(omega**2) * (M @ (Pn @ v))[free]
        num += r @ m
        den += m @ m
    if den == 0.0:
        raise FEImportError("spin softening: no row away from the root to measure it on (a blade of one element?)")
    return float(num / den)


def identify_speed_terms(speeds: np.ndarray, Ks: list[np.ndarray], order: int) -> list[np.ndarray]:
    """[K0, K1(, K2)] with K(Omega) = sum_k Omega^(2k) K_k, least squares over the given speeds (exact for
    order + 1 speeds). ``Ks``: the (reduced) stiffness at each speed."""
    need = order + 1
    if len(speeds) < need:
        raise FEImportError(f"speeds: {len(speeds)} stiffness matrices ({', '.join(f'{w:g}' for w in speeds)} rad/s) "
                            f"cannot identify K0 + Omega^2 K1{' + Omega^4 K2' if order == 2 else ''}; accepted: "
                            f"{need} or more speeds (or rotating.order = {order - 1})")
    w2 = np.asarray(speeds, dtype=float) ** 2
    scale = w2.max() if w2.max() > 0 else 1.0
    V = np.vander(w2 / scale, need, increasing=True)
    stack = np.stack([np.asarray(K) for K in Ks])
    coef, *_ = np.linalg.lstsq(V, stack.reshape(len(Ks), -1), rcond=None)
    return [coef[k].reshape(stack.shape[1:]) / scale**k for k in range(need)]
