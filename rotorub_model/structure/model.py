"""Assembly of the bladed rotor and the casing in the rotating frame.

Dof order: shaft (2 x n_shaft, interleaved x/y), blades (N x n_blade), casing
(translation, tilt, ring modes). Each component builds its own matrices; this
module only places them. Rotor and casing are coupled only through contact.

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> m = build_model()
>>> m.n_dofs
38
>>> m.dofs[0], m.dofs[-1]
('shaft.a0.x', 'casing.n3.y')
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .. import kernel
from .blades import bladed_disk_matrices, check_mistuning
from .casing import casing_matrices
from .frames import MATRIX_KEYS, Matrices
from .params import Parameters, from_dict, reference_parameters, to_dict
from .shaft import shaft_matrices, station_maps


@dataclass
class ImportedTip:
    """What the contact and the outputs need of an imported blade (its tip and its mass), as :func:`save_model`
    keeps it: numpy only, so that a saved model (the pythonfmu FMU's) builds its contact without scipy. A
    :class:`~rotorub_model.fe.blade.ReducedBlade` has the same fields."""

    tip_nodes: np.ndarray  # (n_t,) ids
    tip_positions: np.ndarray  # (n_t, 3) rest positions, blade frame [m]
    tip_recovery: np.ndarray  # (n_t, 3, m) tip displacement per unit reduced coordinate
    nodes: np.ndarray  # (N, 3) the mesh's nodes (figures, the blade's angular extent)
    mass: float  # [kg]
    basis_mass: np.ndarray  # (6 + m, 6 + m): the rigid block holds the first moments (the static moment)

    @property
    def m(self) -> int:
        return int(self.tip_recovery.shape[2])


IMPORTED_FIELDS = ("tip_nodes", "tip_positions", "tip_recovery", "nodes", "basis_mass")


@dataclass
class Model:
    """Rotating-frame linear model: M q'' + (D + G(W)) q' + K(W) q = F(W^2).

    K(W) = K + Ks(W^2) + N(W) + C(W), with G = W G1, C = W C1, N = W^2 N2, Ks = W^2 S2.
    """

    params: Parameters
    dofs: list[str]
    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    G1: np.ndarray
    C1: np.ndarray
    N2: np.ndarray
    S2: np.ndarray
    E1: np.ndarray  # angular-acceleration (Euler) term: dOmega/dt E1 q
    f_unit: np.ndarray  # imbalance force for m e = 1 kg m at Omega = 1 rad/s
    f_tangential: np.ndarray  # imbalance force for m e = 1 kg m at dOmega/dt = 1 rad/s^2
    f_euler: np.ndarray  # inertia load of the blades at dOmega/dt = 1 rad/s^2
    slices: dict[str, slice]
    mistuning: tuple[float, ...] | None = None  # per-blade stiffness deviations (build_model); None: tuned
    S4: np.ndarray | None = None  # Omega^4 term of an imported blade's prestressed stiffness (None: the built-in's)
    # the imported blade when [fe_blade] names one: fe.blade.ReducedBlade (build_model), ImportedTip (load_model)
    fe_blade: object | None = None
    # an FE casing's (``[fe_casing]``) tangential and axial ratios of each of casing.modes; None: the thin ring's
    casing_ratios: tuple[np.ndarray, np.ndarray] | None = None

    def casing_point_map(self, point: np.ndarray) -> np.ndarray:
        """3 x n_casing: the casing surface point's displacement (structure/casing.py; an FE casing's modes)."""
        from .casing import casing_point_map

        return casing_point_map(self.params, point, *(self.casing_ratios or (None, None)))

    @property
    def blade_dofs(self) -> int:
        """Generalised coordinates per blade (the built-in blade's functions, or an imported blade's modes)."""
        sl = self.slices["blades"]
        return (sl.stop - sl.start) // self.params.blades.count

    @property
    def n_dofs(self) -> int:
        return len(self.dofs)

    def G(self, omega: float) -> np.ndarray:
        return omega * self.G1

    def K_omega(self, omega: float) -> np.ndarray:
        """K(Omega) = K + Ks(Omega^2) + N(Omega) + C(Omega): the kernel's (rr_k_omega), the same bits the FMUs and
        the time loop's matrices use."""
        return kernel.k_omega(self.K, self.S2, self.N2, self.C1, float(omega), self.S4)

    def force(self, omega: float, me: float | None = None, omega_dot: float = 0.0) -> np.ndarray:
        """Imbalance force F(Omega^2) (constant in the rotating frame); with an angular
        acceleration the imbalance also pulls tangentially (m e dOmega/dt) and the
        blades carry their inertia load (they lag when the spin speeds up)."""
        me = self.params.imbalance.me if me is None else me
        f = me * omega * omega * self.f_unit
        if omega_dot:
            f = f + omega_dot * (me * self.f_tangential + self.f_euler)
        return f

    def index(self, name: str) -> int:
        return self.dofs.index(name)

    @cached_property
    def cyclic(self):
        """The contact-open model's cyclic-symmetry blocks (structure/cyclic.py): what the eigen-analyses
        of the free rotor solve instead of the whole problem."""
        from .cyclic import cyclic_blocks

        return cyclic_blocks(self)

    @cached_property
    def block_layout(self) -> tuple[int, int, int, int] | None:
        """(hub dofs, blades, dofs per blade, casing dofs) when the matrices are arrows: the blades couple to the
        shaft only, the casing to nothing (it meets the rotor through contact); what the time loop's block step
        needs (a step then costs what grows linearly with the blades). None when any block breaks the pattern."""
        sh, bl, cs = self.slices["shaft"], self.slices["blades"], self.slices["casing"]
        nb = self.params.blades.count
        nblade = bl.stop - bl.start
        if nb < 1 or nblade % nb:
            return None
        m = nblade // nb
        mats = [self.M, self.D, self.K, self.G1, self.C1, self.N2, self.S2, self.E1]
        if self.S4 is not None:
            mats.append(self.S4)
        rotor = slice(sh.start, bl.stop)
        for A in mats:
            if np.any(A[rotor, cs]) or np.any(A[cs, rotor]):
                return None
            B = A[bl, bl]
            for j in range(nb):
                rows = slice(j * m, (j + 1) * m)
                off = np.abs(B[rows]).copy()
                off[:, rows] = 0.0
                if np.any(off):
                    return None
        return sh.stop - sh.start, nb, m, cs.stop - cs.start

    @cached_property
    def M_inv(self) -> np.ndarray:
        """M^-1 (every first-order system and eigen-analysis needs it; the model's matrices do not change)."""
        return np.linalg.inv(self.M)

    @cached_property
    def disk_maps(self) -> tuple[np.ndarray, np.ndarray]:
        """(T, R), 3 x n: fan-disk translation and rotation vector from q."""
        p = self.params
        Ts, Rs = station_maps(p, p.fan_disk.z)
        T = np.zeros((3, self.n_dofs))
        R = np.zeros((3, self.n_dofs))
        T[:, self.slices["shaft"]] = Ts
        R[:, self.slices["shaft"]] = Rs
        return T, R

    def omega_norm(self, omega: float | np.ndarray) -> float | np.ndarray:
        return np.asarray(omega) / self.params.normalisation.omega_ref

    def omega_si(self, omega_norm: float | np.ndarray) -> float | np.ndarray:
        return np.asarray(omega_norm) * self.params.normalisation.omega_ref


def _place(n: int, parts: list[tuple[Matrices, np.ndarray]]) -> dict[str, np.ndarray]:
    out = {k: np.zeros((n, n)) for k in MATRIX_KEYS}
    for mats, idx in parts:
        ix = np.ix_(idx, idx)
        for k in out:
            out[k][ix] += getattr(mats, k)
    return out


CASING_RADIUS_TOL = 0.1  # an FE casing's contact circle within this fraction of the tip radius (its surface or
# mid-surface, a mesh)


def fe_casing(p: Parameters):
    """(the casing block, (tau, zeta) of each of casing.modes) of [fe_casing]'s modal model, its modes damped by
    [casing].damping_ratio (as the ring's: the file's ratio is what it was written with)."""
    from ..errors import ParameterError
    from ..fe.casing_modes import CasingMode, FECasing, fe_casing_matrices, load_fe_casing

    where = f"fe_casing.model ({Path(p.fe_casing.model).name})"
    if not Path(p.fe_casing.model).is_file():
        raise ParameterError(f"fe_casing.model: {p.fe_casing.model}: no such file; accepted: an FE casing's modal "
                             "model that FECasing.save wrote (a path relative to the parameter file)")
    cas = load_fe_casing(p.fe_casing.model)
    have = [m.n for m in cas.modes]
    missing = [n for n in p.casing.modes if n not in have]
    if missing:
        raise ParameterError(f"casing.modes: {list(p.casing.modes)} but {where} has modes of {have} nodal "
                             f"diameters; accepted: nodal diameters among {have}")
    R = p.blades.tip_radius
    if not abs(cas.radius - R) <= CASING_RADIUS_TOL * R:
        raise ParameterError(f"{where}: its contact circle has radius {cas.radius:.4g} m, the blade tips are at "
                             f"{R:.4g} m; accepted: within {CASING_RADIUS_TOL:.0%} (a model of this casing, sampled "
                             "where the tips meet it)")
    damped = FECasing(cas.radius, tuple(CasingMode(**{**m.__dict__, "damping_ratio": p.casing.damping_ratio})
                                        for m in cas.modes), cas.info)
    return fe_casing_matrices(p, damped), damped.ratios(p.casing.modes)


TIP_RADIUS_TOL = 0.01  # an imported tip's radius may differ from [blades]' by this fraction (its own cut, a mesh)


def check_fits(p: Parameters, blade) -> None:
    """One line (ParameterError) when the imported blade does not fit the parameter file's [blades]: its tip (the
    tip nodes' median radius) not at the tip radius hub_radius + length (within TIP_RADIUS_TOL: the casing's
    line, the 2D tip and the liner sit there), or blades.count such blades overlapping their neighbours (the
    blade's angular extent about the spin axis, over its nodes, wider than the pitch 360 deg / count)."""
    from ..errors import ParameterError

    where = f"fe_blade.superelement ({Path(p.fe_blade.superelement).name})"
    r = float(np.median(np.hypot(blade.tip_positions[:, 0], blade.tip_positions[:, 1])))
    R = p.blades.tip_radius
    if not abs(r - R) <= TIP_RADIUS_TOL * R:
        raise ParameterError(f"{where}: its tip lies at radius {r:.4g} m but [blades] puts the tips at hub_radius + "
                             f"length = {R:.4g} m; accepted: within {TIP_RADIUS_TOL:.0%} (set blades.hub_radius and "
                             "blades.length to the blade's)")
    pts = blade.nodes if blade.nodes.shape[0] > blade.tip_positions.shape[0] else blade.tip_positions
    a = np.arctan2(pts[:, 1], pts[:, 0])
    span = float(a.max() - a.min())
    pitch = 2.0 * np.pi / p.blades.count
    if span >= pitch:
        raise ParameterError(f"blades.count: {p.blades.count} blades of {where} overlap (each spans "
                             f"{np.degrees(span):.3g} deg about the spin axis, the pitch is {np.degrees(pitch):.3g} "
                             f"deg); accepted: at most {int(np.floor(2.0 * np.pi / span - 1e-9))}")


def build_model(params: Parameters | None = None, mistuning: Sequence[float] | np.ndarray | None = None) -> Model:
    """Assemble the model of ``params`` (default: the embedded reference).

    ``mistuning``: one stiffness deviation delta_j per blade (blade j's stiffness and stiffness-proportional
    damping times 1 + delta_j, :func:`~rotorub_model.structure.blades.bladed_disk_matrices`); None: tuned."""
    p = params or reference_parameters()
    sh = shaft_matrices(p)
    blade = None
    if p.fe_blade.superelement:  # an imported blade (docs/THEORY.md 9) in place of the built-in beams
        from ..fe.blade import load_superelement
        from ..fe.bladed_disk import fe_bladed_disk_matrices

        if not Path(p.fe_blade.superelement).is_file():
            from ..errors import ParameterError

            raise ParameterError(f"fe_blade.superelement: {p.fe_blade.superelement}: no such file; accepted: the "
                                 "blade.npz rotorub import-blade wrote (a path relative to the parameter file)")
        blade = load_superelement(p.fe_blade.superelement)
        check_fits(p, blade)
        # the blade's damping is the parameter file's (blades.damping_ratio, modal on every kept mode at rest), as
        # for the built-in blades: the ratio the import stored is the one it was given, kept for its report
        blade = dataclasses.replace(blade, damping_ratio=p.blades.damping_ratio)
        bd = fe_bladed_disk_matrices(p, blade)
        delta = check_mistuning(p, mistuning)
        if delta is not None:  # blade j's stiffness and damping times 1 + delta_j, as the built-in blades'
            ns0 = 2 * p.shaft.n_ritz
            for j, dj in enumerate(delta):
                sl = slice(ns0 + j * blade.m, ns0 + (j + 1) * blade.m)
                bd.K[sl, sl] *= 1.0 + dj
                bd.D[sl, sl] *= 1.0 + dj
    else:
        bd = bladed_disk_matrices(p, mistuning=mistuning)
    cs, ratios = casing_matrices(p), None
    if p.fe_casing.model:  # an FE casing's modes in place of the ring's (docs/THEORY.md 9.6)
        cs, ratios = fe_casing(p)
    ns = len(sh.dofs)
    nbt = len(bd.dofs) - ns
    nc = len(cs.dofs)
    n = ns + nbt + nc
    slices = {
        "shaft": slice(0, ns),
        "blades": slice(ns, ns + nbt),
        "rotor": slice(0, ns + nbt),
        "casing": slice(ns + nbt, n),
    }
    dofs = sh.dofs + bd.dofs[ns:] + cs.dofs
    mats = _place(
        n,
        [
            (sh, np.arange(ns)),
            (bd, np.arange(ns + nbt)),
            (cs, np.arange(ns + nbt, n)),
        ],
    )
    model = Model(params=p, dofs=dofs, f_unit=np.zeros(n), f_tangential=np.zeros(n), f_euler=np.zeros(n),
                  slices=slices, mistuning=check_mistuning(p, mistuning), **mats)
    model.f_euler[slices["rotor"]] = bd.f_euler
    model.casing_ratios = ratios
    if blade is not None:
        model.fe_blade = blade
        model.S4 = np.zeros((n, n))
        model.S4[: ns + nbt, : ns + nbt] = bd.S4
        if not np.any(model.S4):
            model.S4 = None  # a prestress linear in Omega^2: K(Omega) as the built-in's
    T, _ = model.disk_maps
    ang = np.radians(p.imbalance.angle_deg)
    Ts, _ = station_maps(p, next(d for d in p.disks if d.name == p.imbalance.disk).z)
    f = np.zeros(n)
    f[slices["shaft"]] = Ts.T @ np.array([np.cos(ang), np.sin(ang), 0.0])
    model.f_unit = f
    ft = np.zeros(n)
    ft[slices["shaft"]] = Ts.T @ np.array([-np.sin(ang), np.cos(ang), 0.0])
    model.f_tangential = ft
    return model


_ARRAYS = ("M", "D", "K", "G1", "C1", "N2", "S2", "E1", "f_unit", "f_tangential", "f_euler")


def save_model(model: Model, path: str | Path) -> Path:
    """Write the assembled model (matrices, dofs, parameters, disk maps) to an .npz file.

    What a consumer that must not depend on scipy needs: :func:`load_model` restores the
    same arrays bit for bit without assembling anything (the FMU carries one).
    """
    import json

    T, R = model.disk_maps
    path = Path(path)
    extra = {} if model.mistuning is None else {"mistuning": np.array(model.mistuning)}
    if model.S4 is not None:
        extra["S4"] = model.S4
    if model.casing_ratios is not None:
        extra["casing_tau"], extra["casing_zeta"] = model.casing_ratios
    if model.fe_blade is not None:  # an imported blade: what its contact needs (the superelement's path may not
        b = model.fe_blade  # exist where the saved model goes: an FMU's host)
        extra.update({f"fe_{k}": np.asarray(getattr(b, k)) for k in IMPORTED_FIELDS}, fe_mass=np.array(b.mass))
    np.savez(path, params=json.dumps(to_dict(model.params)), dofs=np.array(model.dofs),
             slices=json.dumps({k: [s.start, s.stop] for k, s in model.slices.items()}),
             disk_T=T, disk_R=R, **{k: getattr(model, k) for k in _ARRAYS}, **extra)
    return path


def load_model(path: str | Path, params: Parameters | None = None) -> Model:
    """The model saved by :func:`save_model`. ``params`` may replace the parameters when only
    sections that do not enter the matrices differ (``contact``: clearance, k_r, mu, cone, chord)."""
    import json

    with np.load(Path(path), allow_pickle=False) as d:
        saved = from_dict(json.loads(str(d["params"])))
        if params is not None and params.replace(contact=to_dict(saved)["contact"]) != saved:
            raise ValueError("load_model: the parameters differ from the saved model's outside [contact]")
        m = Model(params=params or saved, dofs=[str(x) for x in d["dofs"]],
                  slices={k: slice(a, b) for k, (a, b) in json.loads(str(d["slices"])).items()},
                  mistuning=tuple(float(v) for v in d["mistuning"]) if "mistuning" in d.files else None,
                  **{k: np.array(d[k]) for k in _ARRAYS})
        m.__dict__["disk_maps"] = (np.array(d["disk_T"]), np.array(d["disk_R"]))
        if "S4" in d.files:
            m.S4 = np.array(d["S4"])
        if "casing_tau" in d.files:
            m.casing_ratios = (np.array(d["casing_tau"]), np.array(d["casing_zeta"]))
        if "fe_tip_recovery" in d.files:
            m.fe_blade = ImportedTip(mass=float(d["fe_mass"]), **{k: np.array(d[f"fe_{k}"]) for k in IMPORTED_FIELDS})
    return m
