"""The geometry a contact formulation hands to the contact model, built by the kernel.

``build_geometry`` collects what the geometry is made of (the fan-disk maps T and R of the
shaft, the blades' Ritz values at the tip, the casing's dofs and ring modes, the cone and
the chord) and lets the kernel's ``rr_contact_geometry`` build the points, normals, the
point displacement maps J_b, J_c and the gap gradients: one construction for the library,
the pythonfmu FMU and the native FMU (which makes it at initialisation from the same
ingredients, baked at build time).
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np

from .. import kernel
from ..structure.blades import blade_functions
from ..structure.model import Model


@dataclass
class TipLayout:
    """An imported blade's tip (docs/THEORY.md 9): its chord stations joined by segments, each segment a 'blade'
    of the kernel (two points: its leading and trailing station) with the chord law of its own length. The rows
    G, A, B, S of the geometry are then compact: segment j's columns are the dofs ``cols[j]`` (the shaft's, its
    blade's, the casing's), so a contact evaluation costs what the segments touch, not segments x every dof."""

    n_blades: int  # the blades the outputs report
    n_dofs: int
    seg_len: np.ndarray  # (S,) each segment's chord length [m]
    seg_k: np.ndarray  # (S,) its share of k_r (and of the liner's yield force): its length over the tip's chord
    g_off: np.ndarray  # (S*2,) each point's rest gap beyond g0 [m] (a tip that is not cut to the casing's line)
    cols: np.ndarray  # (S, nloc) intc: the dofs of segment j's rows
    blade_of: np.ndarray  # (S,) intc: each segment's blade, ascending, its segments from the leading edge
    n_rows: int  # rows of the liner's worn depth: the tip's stations
    point_row: np.ndarray  # (S*2,) intc: each point's station
    point_share: np.ndarray  # (S*2,) the liner's share of each point (its station's tributary chord; 0: a twin)
    band: float = 0.0  # axial extent of the tip [m] (the band of the liner it sweeps)
    tip_area: float = 0.0  # the tip's footprint on the liner [m^2]: its chord times its thickness (0: unknown)


@dataclass
class ContactGeometry:
    """Per-point geometry: arrays of shape (N, P, ...) with P = 1 (2D) or 2 (LE, TE); for an imported blade's tip
    (``tips``), N is its segments' count and the rows are compact (TipLayout)."""

    points: np.ndarray  # (N, P, 3) rest positions, rotating frame, z from the blade-tip plane
    normals: np.ndarray  # (N, P, 3) outward casing normal
    tangents: np.ndarray  # (N, P, 3) e_t at the point
    Jb: np.ndarray  # (N, P, 3, n) blade-point displacement maps
    Jc: np.ndarray  # (N, P, 3, n) casing-point displacement maps
    chord: float  # l_c (0 for the point law)
    disk: np.ndarray  # (2, n) fan-disk centre translation (rotating x, y): an output of every state
    G: np.ndarray  # (N*P, n) gap gradients: gap = g0 + G q
    A: np.ndarray  # (N, n) d eta / dq (mean gap along the chord)
    B: np.ndarray  # (N, n) d zeta / dq (gap slope)
    S: np.ndarray  # (N*P, n) sliding rows e_t . (J_b - J_c): relative sliding along e_t = S q
    tips: TipLayout | None = None  # an imported blade's tip: segments, compact rows


def geometry_spec(model: Model, n_points: int, theta: float, chord: float, rotations: bool) -> dict:
    """The ingredients of rr_geometry_spec (plain numbers and arrays): what the native FMU bakes."""
    p = model.params
    T, R = model.disk_maps
    return {
        "n": model.n_dofs, "nb": p.blades.count, "np": n_points, "rotations": int(bool(rotations)),
        "r_tip": p.blades.tip_radius, "stagger": float(np.radians(p.blades.stagger_deg)), "theta": float(theta),
        "chord": float(chord), "z_cg": p.casing.z_cg, "blade_dof0": model.slices["blades"].start,
        "n_ritz": p.blades.dofs,  # the kernel's name: the blade functions per blade (polynomials or modes)
        "psi_tip": np.ascontiguousarray(blade_functions(p, p.blades.length)[0]),
        "casing_dof0": model.slices["casing"].start, "modes": np.asarray(p.casing.modes, dtype=np.intc),
        "T": np.ascontiguousarray(T, dtype=float), "Rot": np.ascontiguousarray(R, dtype=float),
    }


def build_geometry(model: Model, n_points: int, theta: float = 0.0, chord: float = 0.0,
                   rotations: bool = True) -> ContactGeometry:
    """The kernel's contact geometry: 2D point tips (``n_points=1``) or 3D LE/TE (``n_points=2``)."""
    s = geometry_spec(model, n_points, theta, chord, rotations)
    N, P, n = s["nb"], n_points, s["n"]
    lib = kernel.load()
    spec = kernel.RRGeometrySpec(
        n, N, P, s["rotations"], s["r_tip"], s["stagger"], s["theta"], s["chord"], s["z_cg"], s["blade_dof0"],
        s["n_ritz"], kernel.ptr(s["psi_tip"]), s["casing_dof0"], len(s["modes"]), kernel.iptr(s["modes"]),
        kernel.ptr(s["T"]), kernel.ptr(s["Rot"]))
    out = {k: np.zeros(shape) for k, shape in (
        ("points", (N, P, 3)), ("normals", (N, P, 3)), ("tangents", (N, P, 3)), ("Jb", (N, P, 3, n)),
        ("Jc", (N, P, 3, n)), ("G", (N * P, n)), ("A", (N, n)), ("B", (N, n)), ("S", (N * P, n)),
        ("disk", (2, n)))}
    geo = kernel.RRGeometry(*(kernel.ptr(out[k]) for k in ("points", "normals", "tangents", "Jb", "Jc", "G", "A",
                                                            "B", "S", "disk")))
    if lib.rr_contact_geometry(ctypes.byref(spec), ctypes.byref(geo)) != 0:
        raise ValueError(f"contact geometry: invalid specification (points {P}, chord {chord!r} m)")
    return ContactGeometry(chord=float(chord if P == 2 else 0.0), **out)


def with_fe_casing(model: Model, geo: ContactGeometry) -> ContactGeometry:
    """The built-in blades' geometry (the kernel's, which knows the thin ring's modes) facing an FE casing's modes
    (``model.casing_ratios``: each mode's tangential and axial ratios in place of the ring's -1/n and 0): the casing
    point maps Jc again from :meth:`Model.casing_point_map`, and the rows G, S, A, B from them, as the kernel forms
    them (docs/THEORY.md 4, 9.6)."""
    import dataclasses

    N, P = geo.points.shape[:2]
    modes = slice(model.slices["casing"].start + 4, model.slices["casing"].stop)  # after translation and tilt
    Jc = geo.Jc.copy()
    for j in range(N):
        for k in range(P):  # the modes' columns only: the rigid casing's are the kernel's (2D: no tilt)
            Jc[j, k][:, modes] = model.casing_point_map(geo.points[j, k])[:, 4:]
    rel = geo.Jb - Jc
    G = -np.einsum("jpi,jpin->jpn", geo.normals, rel)
    S = np.einsum("jpi,jpin->jpn", geo.tangents, rel).reshape(N * P, -1)
    if P == 1:
        A, B = G[:, 0].copy(), np.zeros_like(G[:, 0])
    else:
        A, B = 0.5 * (G[:, 0] + G[:, 1]), (G[:, 1] - G[:, 0]) / geo.chord
    return dataclasses.replace(geo, Jc=Jc, G=G.reshape(N * P, -1), S=S, A=A, B=B)
