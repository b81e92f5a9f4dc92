"""The finite-element model as read from a code's files, in SI, checked.

:class:`FEModel` is what every reader returns and what the reduction takes: sparse mass and stiffness
matrices with a dof map (node id and component of every row), node coordinates, and optionally the
stiffness at several spin speeds (the FE code's prestressed modal steps).

Dof map convention: component 1, 2, 3 are the translations along the file's x, y, z axes, 4, 5, 6 the
rotations about them (beam and shell nodes). The stiffness rows are the *free* dofs: the blade's root is
clamped and its dofs are left out, as every FE code does. The mass matrix may have more rows than the
stiffness (``mass_dofs`` a superset of ``dofs``): a mass matrix of the unconstrained blade, whose extra
rows are the root's, which move with the disk. Without it the root nodes' share of the blade's mass is
missing from the blade's rigid mass and inertia on the disk (the importer reports how the blade's mass
was counted).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import FEImportError
from .units import UnitSystem

COMPONENTS = (1, 2, 3, 4, 5, 6)
SYMMETRY_TOL = 1e-8  # |A - A^T| / |A| accepted as rounding of a symmetric matrix written with a few digits


@dataclass
class FEModel:
    """A finite-element model in SI units (see the module docstring for the dof conventions)."""

    M: sp.csr_matrix  # (n_mass, n_mass) on mass_dofs [kg, kg m, kg m^2]
    stiffness: tuple[tuple[float, sp.csr_matrix], ...]  # ((Omega [rad/s], K(Omega)) ...) ascending, K on dofs
    dof_nodes: np.ndarray  # (n,) node id of each stiffness row
    dof_components: np.ndarray  # (n,) component 1..6 of each stiffness row
    node_ids: np.ndarray  # (N,) ids of the nodes with coordinates
    coordinates: np.ndarray  # (N, 3) node positions [m], the file's axes
    mass_nodes: np.ndarray = field(default=None)  # type: ignore[assignment]  # (n_mass,), default: dof_nodes
    mass_components: np.ndarray = field(default=None)  # type: ignore[assignment]
    source: str = ""
    units: str = "SI"
    spin_softening_in_K: bool | None = None  # does K(Omega) hold -Omega^2 M P (CalculiX: yes); None: not known

    def __post_init__(self) -> None:
        if self.mass_nodes is None:
            self.mass_nodes = self.dof_nodes
            self.mass_components = self.dof_components

    @property
    def n_dofs(self) -> int:
        return int(self.dof_nodes.size)

    @property
    def K0(self) -> sp.csr_matrix:
        """The stiffness at rest (the first speed must be 0)."""
        return self.stiffness[0][1]

    @property
    def speeds(self) -> np.ndarray:
        return np.array([w for w, _ in self.stiffness])

    def free_in_mass(self) -> np.ndarray:
        """Index into the mass rows of each stiffness row."""
        key = {(int(n), int(c)): i for i, (n, c) in enumerate(zip(self.mass_nodes, self.mass_components))}
        return np.array([key[(int(n), int(c))] for n, c in zip(self.dof_nodes, self.dof_components)])

    @property
    def M_free(self) -> sp.csr_matrix:
        """The mass matrix on the stiffness' (free) dofs."""
        if self.mass_nodes is self.dof_nodes:
            return self.M
        i = self.free_in_mass()
        return self.M[i][:, i].tocsr()

    def coordinates_of(self, nodes: np.ndarray) -> np.ndarray:
        """(len(nodes), 3) coordinates of the given node ids."""
        order = np.argsort(self.node_ids)
        pos = np.searchsorted(self.node_ids, nodes, sorter=order)
        return self.coordinates[order[np.clip(pos, 0, len(order) - 1)]]


def symmetric_from_triangle(i: np.ndarray, j: np.ndarray, v: np.ndarray, n: int, where: str) -> sp.csr_matrix:
    """A symmetric matrix from entries (0-based) of one triangle, or of both (then they must agree)."""
    if i.size and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n):
        bad = int(max(i.max(), j.max())) + 1
        raise FEImportError(f"{where}: entry in row/column {bad} but the dof map has {n} rows (a dof map of another "
                            "model, or a truncated file)")
    A = sp.coo_matrix((v, (i, j)), shape=(n, n)).tocsr()
    A.sum_duplicates()
    low, up = np.any(i > j), np.any(i < j)
    if low and up:
        check_symmetric(A, where)
        return A
    T = sp.triu(A, 1) if up else sp.tril(A, -1)
    return (A + T.T).tocsr()


def check_symmetric(A: sp.spmatrix, where: str) -> None:
    scale = abs(A).max() if A.nnz else 0.0
    if scale == 0.0:
        raise FEImportError(f"{where}: the matrix is zero")
    asym = abs(A - A.T).max()
    if asym > SYMMETRY_TOL * scale:
        raise FEImportError(f"{where}: not symmetric (largest |A - A^T| = {asym:.3g}, {asym / scale:.2g} of the "
                            f"largest entry; accepted: {SYMMETRY_TOL:g}): mass and stiffness of an undamped "
                            "structure are symmetric (a matrix with follower-load or gyroscopic terms cannot be "
                            "imported as a stiffness)")


def check_finite(A: sp.spmatrix, where: str) -> None:
    if not np.all(np.isfinite(A.data)):
        raise FEImportError(f"{where}: contains NaN or infinite entries")


def check_dof_map(nodes: np.ndarray, comps: np.ndarray, where: str) -> None:
    bad = ~np.isin(comps, COMPONENTS)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise FEImportError(f"{where}: row {k + 1} has component {comps[k]}; accepted: 1-3 (translations x, y, z) "
                            "and 4-6 (rotations)")
    key = nodes.astype(np.int64) * 8 + comps
    u, cnt = np.unique(key, return_counts=True)
    if (cnt > 1).any():
        d = int(u[np.argmax(cnt > 1)])
        raise FEImportError(f"{where}: dof {d // 8}.{d % 8} appears twice in the dof map")


def convert(M: sp.spmatrix, comps: np.ndarray, u: UnitSystem, kind: str) -> sp.csr_matrix:
    """``kind`` 'K' or 'M' in the file's units to SI (see units.py): F L D K D, m L^2 D M D."""
    d = np.where(comps <= 3, 1.0 / u.length, 1.0)
    D = sp.diags(d)
    scale = u.force * u.length if kind == "K" else u.mass * u.length**2
    return (scale * (D @ M @ D)).tocsr()


def make_model(M, stiffness, dof_nodes, dof_comps, node_ids, coords, units: UnitSystem, source: str,
               mass_nodes=None, mass_comps=None, spin_softening_in_K: bool | None = None) -> FEModel:
    """Check what a reader collected (file units) and return the SI model. ``stiffness``: [(speed, K)]."""
    dof_nodes = np.asarray(dof_nodes, dtype=np.int64)
    dof_comps = np.asarray(dof_comps, dtype=np.int64)
    check_dof_map(dof_nodes, dof_comps, f"{source}: dof map")
    n = dof_nodes.size
    if mass_nodes is None:
        mass_nodes, mass_comps = dof_nodes, dof_comps
    else:
        mass_nodes = np.asarray(mass_nodes, dtype=np.int64)
        mass_comps = np.asarray(mass_comps, dtype=np.int64)
        check_dof_map(mass_nodes, mass_comps, f"{source}: mass dof map")
        have = set(zip(mass_nodes.tolist(), mass_comps.tolist()))
        miss = [(a, b) for a, b in zip(dof_nodes.tolist(), dof_comps.tolist()) if (a, b) not in have]
        if miss:
            raise FEImportError(f"{source}: the mass matrix has no row for dof {miss[0][0]}.{miss[0][1]} of the "
                                "stiffness (the mass dofs must include every free dof: a mass matrix of another "
                                "model?)")
    if M.shape != (mass_nodes.size,) * 2:
        raise FEImportError(f"{source}: the mass matrix is {M.shape[0]} x {M.shape[1]} but its dof map has "
                            f"{mass_nodes.size} rows")
    check_finite(M, f"{source}: mass")
    check_symmetric(M, f"{source}: mass")
    if not stiffness:
        raise FEImportError(f"{source}: no stiffness matrix")
    speeds = [float(w) for w, _ in stiffness]
    if any(not np.isfinite(w) or w < 0 for w in speeds):
        raise FEImportError(f"{source}: spin speeds {speeds} must be finite and >= 0")
    if len(set(speeds)) != len(speeds):
        raise FEImportError(f"{source}: a spin speed is given twice: {speeds}")
    if min(speeds) != 0.0:
        raise FEImportError(f"{source}: no stiffness at rest (speeds {speeds} rad/time unit); accepted: one of the "
                            "stiffness matrices at speed 0 (the FE code's plain modal step)")
    order = np.argsort(speeds)
    Ks = []
    for k in order:
        w, K = stiffness[k]
        where = f"{source}: stiffness at {w:g} rad/time unit"
        if K.shape != (n, n):
            raise FEImportError(f"{where} is {K.shape[0]} x {K.shape[1]} but the dof map has {n} rows")
        check_finite(K, where)
        check_symmetric(K, where)
        Ks.append((float(w) / units.time, convert(K, dof_comps, units, "K")))
    node_ids = np.asarray(node_ids, dtype=np.int64)
    coords = np.asarray(coords, dtype=float)
    if coords.ndim != 2 or coords.shape[1] != 3 or coords.shape[0] != node_ids.size:
        raise FEImportError(f"{source}: coordinates must be (nodes, 3), got {coords.shape}")
    if not np.all(np.isfinite(coords)):
        raise FEImportError(f"{source}: node coordinates contain NaN or infinite values")
    if np.unique(node_ids).size != node_ids.size:
        raise FEImportError(f"{source}: a node id appears twice among the coordinates")
    missing = np.setdiff1d(np.unique(mass_nodes), node_ids)
    if missing.size:
        raise FEImportError(f"{source}: node {int(missing[0])} of the dof map has no coordinates ({missing.size} such "
                            "nodes): the coordinates belong to another model (elements with internal nodes, as "
                            "CalculiX's C3D8I, are not accepted: use C3D8R, C3D20(R) or C3D10)")
    return FEModel(M=convert(M, mass_comps, units, "M"), stiffness=tuple(Ks), dof_nodes=dof_nodes,
                   dof_components=dof_comps, node_ids=node_ids, coordinates=coords * units.length,
                   mass_nodes=mass_nodes, mass_components=mass_comps, source=source, units=units.name,
                   spin_softening_in_K=spin_softening_in_K)
