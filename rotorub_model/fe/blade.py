"""The imported blade, reduced: :class:`ReducedBlade`, built by :func:`reduce_blade` from an :class:`FEModel`.

A ReducedBlade is the whole contract between an FE export and the model (blade frame of
:mod:`rotorub_model.fe.rotating`, SI units). Its m generalised coordinates q_b are the reduced blade's
modes at rest, each scaled to a largest tip-node displacement of 1 m (as the built-in blades' functions are
scaled to a unit tip deflection), so q_b reads as tip deflection. Its fields:

* ``K0, K1, K2`` (m, m): the blade's stiffness at rest and its speed terms, K(Omega) = K0 + Omega^2 K1 +
  Omega^4 K2, *as the blade clamped on a fixed disk has it, spin softening included* (``K1`` = stress
  stiffening - Phi^T M P Phi); ``damping_ratio``: modal damping of every kept mode at rest;
* on the extended coordinates [t (3), theta (3), q_b (m)] (t, theta: the root's rigid translation and rotation
  in the blade frame, about the frame's origin), the (6 + m) square kernels ``basis_mass`` (J^T M J),
  ``basis_coriolis`` (J^T (M Z + Z M) J), ``basis_softening`` (-J^T sym(M P) J), ``basis_euler`` (J^T M Z J)
  and the vector ``basis_euler_load`` (-J^T M Z x), J = [rigid modes, basis] on the mass dofs;
* ``second_moments`` C = int rho x x^T (3, 3), ``centrifugal_coupling`` W (3, m) with W_a = int rho
  ((P x) x e_a) . u, and ``euler_coupling`` Y (3, m) with Y_a = int rho ((Z x) x e_a) . u: the second-order
  couplings of a disk tilt with the blade (structure/blades.py's S2 and E1 terms, for any mass distribution);
* the tip: ``tip_nodes`` (n_t,), ``tip_positions`` (n_t, 3) rest positions, ``tip_recovery`` (n_t, 3, m):
  displacement of tip node i = tip_recovery[i] @ q_b, ``tip_residual`` (3 n_t, 3 n_t) [m/N]: the static
  flexibility at the tip dofs the basis does not hold (massless; the contact may act through it),
  ``tip_centrifugal`` (n_t, 3) [m s^2]: the tip nodes' static displacement under the centrifugal load per
  Omega^2 (linear: radial growth and untwist, a closure of the clearance);
* ``nodes`` (N, 3): every node in the blade frame (for figures), ``speeds`` of the FE data, and the check
  ``reference``: the full FE model's and the reduced blade's frequencies at every speed.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.linalg import eigh

from ..errors import FEImportError
from .femodel import FEModel
from .reduction import (
    TWO_PI,
    complement,
    condensed,
    factorize,
    lowest_modes,
    orthonormal_basis,
    residual_flexibility,
)
from .rotating import (
    P3,
    Z3,
    BladeFrame,
    blade_frame,
    frame_operators,
    identify_speed_terms,
    rigid_modes,
    spin_softening_fraction,
)
from .rotating import (
    field as nodal_field,
)
from .units import unit_system

FORMAT = "rotorub-superelement-1"
BASES = ("condensed", "modal", "two-speed")
ARRAY_FIELDS = ("K0", "K1", "K2", "basis_mass", "basis_coriolis", "basis_softening", "basis_euler",
                "basis_euler_load", "second_moments", "centrifugal_coupling", "euler_coupling", "tip_nodes",
                "tip_positions", "tip_recovery", "tip_residual", "tip_centrifugal", "nodes", "speeds")
REQUIRED = ("K0", "basis_mass", "basis_coriolis", "basis_softening", "basis_euler", "basis_euler_load",
            "second_moments", "centrifugal_coupling", "euler_coupling", "tip_nodes", "tip_positions", "tip_recovery")


@dataclass
class ReducedBlade:
    """The reduced imported blade (see the module docstring for every field; blade frame, SI)."""

    K0: np.ndarray
    K1: np.ndarray
    K2: np.ndarray
    damping_ratio: float
    basis_mass: np.ndarray
    basis_coriolis: np.ndarray
    basis_softening: np.ndarray
    basis_euler: np.ndarray
    basis_euler_load: np.ndarray
    second_moments: np.ndarray
    centrifugal_coupling: np.ndarray
    euler_coupling: np.ndarray
    tip_nodes: np.ndarray
    tip_positions: np.ndarray
    tip_recovery: np.ndarray
    tip_residual: np.ndarray
    tip_centrifugal: np.ndarray
    nodes: np.ndarray
    speeds: np.ndarray
    reference: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)

    @property
    def m(self) -> int:
        """Reduced dofs of the blade."""
        return int(self.K0.shape[0])

    @property
    def M(self) -> np.ndarray:
        return self.basis_mass[6:, 6:]

    @property
    def mass(self) -> float:
        """The blade's mass [kg] as the mass matrix carries it."""
        return float(np.trace(self.basis_mass[:3, :3]) / 3.0)

    def K_at(self, omega: float) -> np.ndarray:
        """The clamped blade's stiffness at spin speed omega [rad/s] (spin softening included)."""
        w2 = omega * omega
        return self.K0 + w2 * self.K1 + w2 * w2 * self.K2

    def frequencies(self, omega: float = 0.0) -> np.ndarray:
        """The clamped blade's frequencies [Hz] at omega (no Coriolis: as an FE code's modal step)."""
        lam = eigh(self.K_at(omega), self.M, eigvals_only=True)
        return np.sqrt(np.clip(lam, 0.0, None)) / TWO_PI

    @property
    def D(self) -> np.ndarray:
        """Modal damping of the kept modes at rest: D = M z diag(2 zeta omega) z^T M (z: M-normalised modes)."""
        lam, z = eigh(self.K0, self.M)
        Mz = self.M @ z
        return Mz @ np.diag(2.0 * self.damping_ratio * np.sqrt(np.clip(lam, 0.0, None))) @ Mz.T

    @property
    def stress_stiffening(self) -> np.ndarray:
        """S2's blade block: K1 with the spin softening taken out (the model adds it as N2)."""
        return self.K1 - self.basis_softening[6:, 6:]

    def save(self, path: str | Path) -> Path:
        """The project's superelement file (.npz, schema in docs/THEORY.md section 9)."""
        path = Path(path)
        arrays = {k: np.asarray(getattr(self, k)) for k in ARRAY_FIELDS}
        meta = {"format": FORMAT, "units": "SI", "damping_ratio": self.damping_ratio, "info": self.info,
                "reference": {k: np.asarray(v).tolist() for k, v in self.reference.items()}}
        tmp = path.with_name(path.name + ".part.npz")
        np.savez_compressed(tmp, meta=json.dumps(meta), **arrays)
        tmp.replace(path)
        return path


def load_superelement(path: str | Path) -> ReducedBlade:
    """A superelement file written by :meth:`ReducedBlade.save` (or by another code, to the same schema)."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"superelement: {path}: no such file")
    try:
        d = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise FEImportError(f"superelement: {path}: not an .npz file ({exc})") from None
    with d:
        if "meta" not in d:
            raise FEImportError(f"superelement: {path}: no 'meta' entry (format {FORMAT})")
        meta = json.loads(str(d["meta"]))
        if meta.get("format") != FORMAT or meta.get("units") != "SI":
            raise FEImportError(f"superelement: {path}: format {meta.get('format')!r} in {meta.get('units')!r}; "
                                f"accepted: {FORMAT!r} in 'SI'")
        missing = [k for k in REQUIRED if k not in d]
        if missing:
            raise FEImportError(f"superelement: {path}: missing {', '.join(missing)} (schema: docs/THEORY.md 9)")
        a = {k: np.array(d[k]) for k in ARRAY_FIELDS if k in d}
    m = a["K0"].shape[0]
    nt = a["tip_nodes"].size
    a.setdefault("K1", np.zeros((m, m)))
    a.setdefault("K2", np.zeros((m, m)))
    a.setdefault("tip_residual", np.zeros((3 * nt, 3 * nt)))
    a.setdefault("tip_centrifugal", np.zeros((nt, 3)))
    a.setdefault("nodes", a["tip_positions"])
    a.setdefault("speeds", np.zeros(1))
    shapes = {"K0": (m, m), "K1": (m, m), "K2": (m, m), "basis_mass": (m + 6, m + 6),
              "basis_coriolis": (m + 6, m + 6), "basis_softening": (m + 6, m + 6), "basis_euler": (m + 6, m + 6),
              "basis_euler_load": (m + 6,), "second_moments": (3, 3), "centrifugal_coupling": (3, m),
              "euler_coupling": (3, m), "tip_positions": (nt, 3), "tip_recovery": (nt, 3, m),
              "tip_residual": (3 * nt, 3 * nt), "tip_centrifugal": (nt, 3)}
    for k, s in shapes.items():
        if a[k].shape != s:
            raise FEImportError(f"superelement: {path}: {k} has shape {a[k].shape}; accepted {s} (m = {m} dofs, "
                                f"{nt} tip nodes)")
        if not np.all(np.isfinite(a[k])):
            raise FEImportError(f"superelement: {path}: {k} has NaN or infinite entries")
    for k in ("K0", "basis_mass"):
        A = a[k]
        if np.abs(A - A.T).max() > 1e-8 * np.abs(A).max():
            raise FEImportError(f"superelement: {path}: {k} is not symmetric")
        # K0 and the blade's own mass positive definite; the rigid block may be singular (a line of point masses
        # has no inertia about its own axis)
        lam = np.linalg.eigvalsh(0.5 * (A + A.T))
        B = A if k == "K0" else A[6:, 6:]
        if np.linalg.eigvalsh(0.5 * (B + B.T)).min() <= 0 or lam.min() < -1e-10 * lam.max():
            raise FEImportError(f"superelement: {path}: {k} is not positive definite"
                                + (" (the blade has rigid-body modes: is the root clamped?)" if k == "K0" else ""))
    if np.unique(a["tip_nodes"]).size != nt or nt == 0:
        raise FEImportError(f"superelement: {path}: tip_nodes must be distinct and at least one")
    return ReducedBlade(damping_ratio=float(meta.get("damping_ratio", 0.005)),
                        reference={k: np.asarray(v) for k, v in meta.get("reference", {}).items()},
                        info=meta.get("info", {}), **a)


def _check_tip(fe: FEModel, tip_nodes) -> tuple[np.ndarray, np.ndarray]:
    """Tip node ids (in the given order) and their (n_t, 3) free x, y, z rows."""
    tips = np.asarray(tip_nodes).reshape(-1)
    if tips.size == 0:
        raise FEImportError("tip_nodes: none given; accepted: the ids of the nodes along the blade tip")
    try:
        tips = tips.astype(np.int64)
    except (TypeError, ValueError):
        raise FEImportError(f"tip_nodes: {tip_nodes!r}; accepted: integer node ids") from None
    u, cnt = np.unique(tips, return_counts=True)
    if (cnt > 1).any():
        raise FEImportError(f"tip_nodes: node {int(u[cnt > 1][0])} is given twice")
    key = {(int(a), int(b)): i for i, (a, b) in enumerate(zip(fe.dof_nodes, fe.dof_components))}
    known = set(fe.node_ids.tolist())
    rows = -np.ones((tips.size, 3), dtype=np.int64)  # -1: a constrained translation (no elastic displacement)
    for i, t in enumerate(tips.tolist()):
        if t not in known:
            raise FEImportError(f"tip_nodes: node {t} is not in the model ({fe.source})")
        for c in range(3):
            rows[i, c] = key.get((t, c + 1), -1)
        if (rows[i] < 0).all():
            raise FEImportError(f"tip_nodes: node {t} has no free translation (a clamped node cannot be a contact "
                                "node)")
    return tips, rows


def tip_values(V: np.ndarray, tip_rows: np.ndarray) -> np.ndarray:
    """(n_t, 3, m) tip displacements of the columns of V (file axes); zero along constrained translations."""
    out = V[np.clip(tip_rows, 0, None)]
    out[tip_rows < 0] = 0.0
    return out


def tip_flexibility(f0, K0, V: np.ndarray, tip_rows: np.ndarray) -> np.ndarray:
    """The tip's residual flexibility (3 n_t square, file axes), zero along constrained translations."""
    flat = tip_rows.reshape(-1)
    ok = np.flatnonzero(flat >= 0)
    G = np.zeros((flat.size, flat.size))
    G[np.ix_(ok, ok)] = residual_flexibility(f0, K0, V, flat[ok])
    return G


def _check_clamped(fe: FEModel, frame: BladeFrame, R_free: np.ndarray) -> None:
    """The root holds every rigid motion, and the coordinates are the matrices' (K annihilates the rigid
    rotations wherever it annihilates the translations: away from the root)."""
    K = fe.K0
    kmax = abs(K).max()
    names = ("translation along e_x", "translation along e_y", "translation along e_z", "rotation about e_x",
             "rotation about e_y", "rotation about e_z")
    res = np.column_stack([K @ R_free[:, k] for k in range(6)])
    for k in range(6):
        scale = kmax * np.abs(R_free[:, k]).max()
        if np.abs(res[:, k]).max() < 1e-9 * scale:
            raise FEImportError(f"{fe.source}: the blade is free in {names[k]} (a rigid-body mode): the root is not "
                                "clamped; accepted: the root's dofs constrained (left out of the stiffness)")
    interior = np.all(np.abs(res[:, :3]) < 1e-9 * kmax, axis=1)
    if interior.sum() < 0.1 * interior.size:
        return  # too few rows away from the root to tell (a very coarse model)
    scale = kmax * np.abs(R_free[:, 3:]).max()
    off = np.abs(res[interior, 3:]).max() / scale
    if off > 1e-6:
        raise FEImportError(f"{fe.source}: the node coordinates are not those of the matrices' model (a rigid rotation "
                            f"of the coordinates strains the blade away from its root: residual {off:.2g} of the "
                            "stiffness; accepted < 1e-6): coordinates from another model, another unit, or "
                            "renumbered nodes")


def _frame_of(fe: FEModel, axis_origin, axis_direction, radial_direction) -> BladeFrame:
    L = unit_system(fe.units).length
    node_index = {int(k): i for i, k in enumerate(fe.node_ids)}
    # the nodal masses locate the centre of mass: a node's mass in each translation it has, averaged
    masses = np.zeros(fe.node_ids.size)
    counts = np.zeros(fe.node_ids.size)
    where = np.array([node_index[int(k)] for k in fe.mass_nodes])
    for c in (1, 2, 3):
        e = np.where(fe.mass_components == c, 1.0, 0.0)
        np.add.at(masses, where, np.asarray(fe.M @ e) * e)
        np.add.at(counts, where, e)
    masses = masses / np.maximum(counts, 1.0)
    return blade_frame(fe.coordinates, masses, np.asarray(axis_origin, dtype=float) * L, axis_direction,
                       radial_direction)


def _rows_xyz(fe: FEModel, nodes: np.ndarray) -> np.ndarray:
    node_index = {int(k): i for i, k in enumerate(fe.node_ids)}
    return fe.coordinates[[node_index[int(k)] for k in nodes]]


def reduce_blade(fe: FEModel, tip_nodes, *, cutoff_hz: float = 1500.0, basis: str = "condensed",
                 order: int | None = None, damping_ratio: float = 0.005, axis_origin=(0.0, 0.0, 0.0),
                 axis_direction=(0.0, 0.0, 1.0),
                 radial_direction=None, reference_speeds: bool = True, name: str = "",
                 diagnostics: dict | None = None) -> ReducedBlade:
    """Reduce ``fe`` (root clamped) to a :class:`ReducedBlade`.

    ``cutoff_hz``: keep the fixed-interface modes below it (at least one); ``basis``: 'condensed' (the modes
    at rest carry the mass; what the modes at the highest speed of the FE data add to them is condensed
    statically into K(Omega), massless: the default, see :mod:`rotorub_model.fe.reduction`), 'modal'
    (the modes at rest alone) or 'two-speed' (modes at rest and at the top speed, all with their mass:
    the built-in blades' choice, exact at both speeds, but the added directions can be stiff); ``order``:
    2 for K0 + W^2 K1 + W^4 K2 (needs 3 speeds), 1 for K0 + W^2 K1 (2 speeds), 0 for the rest stiffness alone
    (the stress stiffening is then neglected); default: the highest the speeds allow. ``axis_origin``: a point of the
    spin axis at the fan disk's station, in the file's length unit; ``axis_direction``: the spin axis (file
    axes, spin positive about it); ``radial_direction``: default through the blade's centre of mass.
    ``reference_speeds``: also solve the full model at every speed (the check of the reduction).
    ``diagnostics``: a dict to receive the full model's modes, factorizations, basis and frame (the report's)."""
    t_start = time.perf_counter()
    if basis not in BASES:
        raise FEImportError(f"basis: {basis!r}; accepted: {', '.join(repr(b) for b in BASES)}")
    if not (np.isfinite(cutoff_hz) and cutoff_hz > 0):
        raise FEImportError(f"cutoff_hz: {cutoff_hz!r}; accepted: a frequency > 0 Hz")
    if not (0.0 <= damping_ratio <= 0.5):
        raise FEImportError(f"damping_ratio: {damping_ratio!r}; accepted: [0, 0.5]")
    speeds = fe.speeds
    order = check_order(order, speeds)
    tips, tip_rows = _check_tip(fe, tip_nodes)
    M = fe.M_free
    frame = _frame_of(fe, axis_origin, axis_direction, radial_direction)
    R_free = rigid_modes(frame, fe.dof_nodes, fe.dof_components, _rows_xyz(fe, fe.dof_nodes))
    _check_clamped(fe, frame, R_free)
    soft = measured_spin_softening(fe, frame)

    t0 = time.perf_counter()
    f0 = factorize(fe.K0, f"{fe.source}: stiffness at rest")
    w0, P0 = lowest_modes(fe.K0, M, f0, cutoff_hz)
    t_rest = time.perf_counter() - t0
    statics = None
    if basis != "two-speed":
        # the tip's statics need K0's factorization and the final basis, known now: then it can go before
        # K(Omega_top)'s is made (the two together are most of the peak memory)
        V = tip_normalised_modes(fe, P0, tip_rows)
        statics = tip_statics(fe, frame, V, tip_rows, f0)
        if diagnostics is None or not diagnostics.get("keep_factor", True):
            f0 = None
    top = None
    if speeds.size > 1 and (basis != "modal" or reference_speeds):
        ft = factorize(fe.stiffness[-1][1], f"{fe.source}: stiffness at {speeds[-1]:.4g} rad/s")
        top = lowest_modes(fe.stiffness[-1][1], M, ft, cutoff_hz, at_least=min(w0.size, fe.n_dofs - 2))
        del ft  # one factorization alive at a time (the peak memory)
    if basis == "two-speed":
        V = orthonormal_basis([P0, top[1]], M) if top is not None else P0
        V = tip_normalised_modes(fe, V, tip_rows)
    Kr = Cm = None
    if basis == "condensed" and top is not None:
        Cm = complement(top[1], V, M)
        Kr = [condensed(V, Cm, K) for _, K in fe.stiffness]
    if diagnostics is not None:
        diagnostics.update(rest=(w0, P0), top=top, factor0=f0, V=V, complement=Cm, frame=frame, tip_rows=tip_rows)
    blade = assemble_superelement(fe, frame, V, tips, tip_rows, order, soft, damping_ratio, f0, Kr=Kr,
                                  statics=statics)
    reference: dict = {"full_rest_hz": w0 / TWO_PI}
    if reference_speeds and speeds.size > 1:
        for k, (w, K) in enumerate(fe.stiffness[1:], start=1):
            if k == speeds.size - 1 and top is not None:
                wk = top[0]
            else:
                fk = factorize(K, f"{fe.source}: stiffness at {w:.4g} rad/s")
                wk, _ = lowest_modes(K, M, fk, cutoff_hz, at_least=min(w0.size, fe.n_dofs - 2))
            reference[f"full_{k}_hz"] = wk / TWO_PI
    for k, w in enumerate(speeds):
        reference[f"reduced_{k}_hz"] = blade.frequencies(float(w))
    blade.reference = reference
    blade.info.update({"name": name, "cutoff_hz": float(cutoff_hz), "basis": basis, "seconds_rest_modes": t_rest,
                       "seconds_total": time.perf_counter() - t_start})
    return blade


def check_order(order: int | None, speeds: np.ndarray) -> int:
    """The identification order, checked against the speeds available."""
    max_order = min(2, speeds.size - 1)
    if order is None:
        return max_order
    if order not in (0, 1, 2):
        raise FEImportError(f"order: {order!r}; accepted: 0, 1 or 2")
    if order > max_order:
        raise FEImportError(f"speeds: {speeds.size} stiffness matrices ({', '.join(f'{w:.4g}' for w in speeds)} rad/s) "
                            f"cannot identify K(Omega) to order {order} (Omega^{2 * order}); accepted: {order + 1} or "
                            f"more speeds, one at rest")
    return order


def measured_spin_softening(fe: FEModel, frame: BladeFrame) -> bool | None:
    """Whether the FE code's K(Omega) holds the spin softening, measured on the matrices (None: one speed)."""
    soft = fe.spin_softening_in_K
    if fe.speeds.size < 2:
        return soft
    _, Pn = frame_operators(frame, fe.dof_nodes, fe.dof_components)
    w, Kw = fe.stiffness[-1]
    frac = spin_softening_fraction(fe.K0, Kw, w, fe.M_free, Pn, frame, fe.dof_nodes, fe.dof_components)
    found = True if abs(frac - 1.0) < 0.05 else False if abs(frac) < 0.05 else None
    if found is None:
        raise FEImportError(f"{fe.source}: K(Omega) - K0 holds {frac:.2f} of the spin softening -Omega^2 M P "
                            "(0 or 1 expected): the prestress was computed about another axis than the declared "
                            "spin axis, or at another speed than declared")
    if soft is not None and soft != found:
        raise FEImportError(f"{fe.source}: declared spin_softening_in_K = {soft} but the matrices show "
                            f"{'it' if found else 'none'} (fraction {frac:.2f})")
    return found


def tip_normalised_modes(fe: FEModel, V: np.ndarray, tip_rows: np.ndarray) -> np.ndarray:
    """The reduced blade's modes at rest in span(V), each scaled to a largest tip-node displacement of 1 (its
    largest tip component positive)."""
    M = fe.M_free
    _, z = eigh(V.T @ (fe.K0 @ V), V.T @ (M @ V))
    V = V @ z
    tv = tip_values(V, tip_rows)
    tipdisp = np.linalg.norm(tv, axis=1)
    imax = np.argmax(tipdisp, axis=0)
    scale = tipdisp[imax, np.arange(V.shape[1])]
    if np.any(scale < 1e-9 * np.abs(V).max(axis=0)):
        raise FEImportError("tip_nodes: a kept mode does not move the tip nodes (are they on the blade?)")
    comp = tv[imax, :, np.arange(V.shape[1])]  # (m, 3)
    sign = np.sign(comp[np.arange(V.shape[1]), np.argmax(np.abs(comp), axis=1)])
    return V * (sign / scale)


def tip_statics(fe: FEModel, frame: BladeFrame, V: np.ndarray, tip_rows: np.ndarray, f0) -> tuple:
    """(the tip's residual flexibility (3 n_t square, file axes), the static displacement of the free dofs
    under the centrifugal load per Omega^2: int rho P x on the free rows, the others being reactions)."""
    mnodes, mcomps = fe.mass_nodes, fe.mass_components
    node_index = {int(k): i for i, k in enumerate(fe.node_ids)}
    _, Pn = frame_operators(frame, mnodes, mcomps)
    x_field = nodal_field(fe.coordinates - frame.origin, mnodes, mcomps, node_index)
    u_cf = f0.solve(np.asarray(fe.M @ (Pn @ x_field))[fe.free_in_mass()])
    return tip_flexibility(f0, fe.K0, V, tip_rows), u_cf


def assemble_superelement(fe: FEModel, frame: BladeFrame, V: np.ndarray, tips: np.ndarray, tip_rows: np.ndarray,
                          order: int, soft: bool | None, damping_ratio: float, f0=None,
                          Kr: list[np.ndarray] | None = None, statics: tuple | None = None) -> ReducedBlade:
    """The :class:`ReducedBlade` of the basis V (free dofs, any scaling): reduced speed terms, the rigid-body
    kernels and the tip quantities (``f0``: a factorization of K0, for the tip's residual flexibility and
    centrifugal displacement; without it they are left zero)."""
    speeds = fe.speeds
    m = V.shape[1]
    if Kr is None:  # the stiffness at each speed on V (given: condensed)
        Kr = [V.T @ (K @ V) for _, K in fe.stiffness]
    terms = identify_speed_terms(speeds, Kr, order) if order else [Kr[0]]
    K0r = terms[0]
    K1r = terms[1] if order >= 1 else np.zeros((m, m))
    K2r = terms[2] if order >= 2 else np.zeros((m, m))
    K0r, K1r, K2r = (0.5 * (A + A.T) for A in (K0r, K1r, K2r))
    # the kernels on [rigid (6), q_b] over the mass dofs (rows only in the mass map move rigidly with the disk)
    M_all, mnodes, mcomps = fe.M, fe.mass_nodes, fe.mass_components
    node_index = {int(k): i for i, k in enumerate(fe.node_ids)}
    R_all = rigid_modes(frame, mnodes, mcomps, _rows_xyz(fe, mnodes))
    free_idx = fe.free_in_mass()
    V_all = np.zeros((mnodes.size, m))
    V_all[free_idx] = V
    J = np.hstack([R_all, V_all])
    Zn, Pn = frame_operators(frame, mnodes, mcomps)
    MJ = M_all @ J
    ZJ = Zn @ J
    PJ = Pn @ J
    basis_mass = J.T @ MJ
    basis_euler = J.T @ (M_all @ ZJ)
    basis_coriolis = basis_euler - ZJ.T @ MJ  # J^T (M Z + Z M) J, Z^T = -Z
    basis_softening = -0.5 * (J.T @ (M_all @ PJ) + PJ.T @ MJ)
    xb = frame.to_blade(fe.coordinates)  # blade-frame position of every coordinate row
    x_field = nodal_field(fe.coordinates - frame.origin, mnodes, mcomps, node_index)
    basis_euler_load = -J.T @ (M_all @ (Zn @ x_field))
    Q = frame.axes  # rows: the blade axes in file components
    # second moments C_ab = int rho x_a x_b, from the fields x_a e_c (averaged over c)
    Fx = [[nodal_field(np.outer(xb[:, a], Q[c]), mnodes, mcomps, node_index) for c in range(3)] for a in range(3)]
    C = np.array([[sum(Fx[a][c] @ (M_all @ Fx[b][c]) for c in range(3)) / 3.0 for b in range(3)] for a in range(3)])
    C = 0.5 * (C + C.T)
    W = np.zeros((3, m))
    Y = np.zeros((3, m))
    MV = M_all @ V_all
    for a in range(3):
        wa = np.cross(xb @ P3.T, np.eye(3)[a]) @ Q  # (P x) x e_a, blade frame -> file components
        ya = np.cross(xb @ Z3.T, np.eye(3)[a]) @ Q
        W[a] = nodal_field(wa, mnodes, mcomps, node_index) @ MV
        Y[a] = nodal_field(ya, mnodes, mcomps, node_index) @ MV
    if not soft:
        # K1 holds the spin softening -V^T M P V (CalculiX's convention); where the FE code's K(Omega) has none,
        # or there is no K(Omega) at all (order 0: the stress stiffening is then neglected), it is added here
        K1r = K1r + basis_softening[6:, 6:]
    nt = tips.size
    tip_positions = frame.to_blade(fe.coordinates_of(tips))
    tip_recovery = np.einsum("ab,ibm->iam", Q, tip_values(V, tip_rows))
    tip_residual = np.zeros((3 * nt, 3 * nt))
    tip_centrifugal = np.zeros((nt, 3))
    if statics is None and f0 is not None:
        statics = tip_statics(fe, frame, V, tip_rows, f0)
    if statics is not None:
        Gf, u_cf = statics
        Qb = np.kron(np.eye(nt), Q)
        tip_residual = Qb @ Gf @ Qb.T
        tip_centrifugal = np.einsum("ab,ib->ia", Q, tip_values(u_cf[:, None], tip_rows)[:, :, 0])
    return ReducedBlade(
        K0=K0r, K1=K1r, K2=K2r, damping_ratio=float(damping_ratio), basis_mass=0.5 * (basis_mass + basis_mass.T),
        basis_coriolis=0.5 * (basis_coriolis - basis_coriolis.T), basis_softening=basis_softening,
        basis_euler=basis_euler, basis_euler_load=basis_euler_load, second_moments=C, centrifugal_coupling=W,
        euler_coupling=Y, tip_nodes=tips, tip_positions=tip_positions, tip_recovery=tip_recovery,
        tip_residual=tip_residual, tip_centrifugal=tip_centrifugal, nodes=xb, speeds=speeds,
        info={"source": fe.source, "units": fe.units, "dofs_full": fe.n_dofs, "mass_rows": int(mnodes.size),
              "rigid_rows_in_mass": int(mnodes.size - fe.n_dofs), "order": int(order),
              "spin_softening_in_fe_K": None if soft is None else bool(soft),
              "frame_origin": frame.origin.tolist(), "frame_axes": frame.axes.tolist()})
