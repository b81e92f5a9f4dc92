"""The casing from an FE modal model, in place of the built-in ring (structure/casing.py).

An axisymmetric casing's modes come in pairs of n nodal diameters. On the contact circle (the casing's inner
surface in the blade-tip plane) a mode of the pair displaces the surface radially by u(a) = A cos n(a - a0),
tangentially by w(a) = tau_n A sin n(a - a0) and axially by v(a) = zeta_n A cos n(a - a0). Scaled to a unit
radial amplitude, the pair has modal mass m_n = phi^T M phi / A^2 and stiffness k_n = omega_n^2 m_n; that is
all the model needs: each pair becomes the ring's (cos, sin) dof pair ``casing.n{n}.x/y`` with harmonic n
(frames.axisymmetric_to_rotating), exactly as the ring's modes are coupled today, and the contact point map
takes tau_n and zeta_n where the ring has -1/n and 0 (inextensional thin ring).

:func:`casing_from_modes` reads the modes the FE code computed (frequencies, shapes sampled at nodes of the
contact circle, mass-normalised as FE codes write them); :func:`casing_from_matrices` computes them from the
casing's mass and stiffness (shift-invert Lanczos about a small negative shift: an unsupported casing has
rigid-body modes). :func:`fe_casing_matrices` and :func:`fe_casing_point_map` are the ring's
``casing_matrices`` and ``casing_point_map`` with these modes.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..errors import FEImportError
from ..structure.frames import Matrices
from ..structure.params import Parameters


@dataclass(frozen=True)
class CasingMode:
    """One nodal-diameter pair of the FE casing, per unit radial amplitude on the contact circle."""

    n: int
    frequency_hz: float
    modal_mass: float  # [kg]
    modal_stiffness: float  # [N/m]
    damping_ratio: float
    tau: float  # tangential / radial amplitude (thin ring: -1/n)
    zeta: float  # axial / radial amplitude (in phase)


@dataclass(frozen=True)
class FECasing:
    radius: float  # [m] of the contact circle
    modes: tuple[CasingMode, ...]
    info: dict = field(default_factory=dict)

    def mode(self, n: int) -> CasingMode:
        for m in self.modes:
            if m.n == n:
                return m
        raise FEImportError(f"casing: no FE mode with {n} nodal diameters; found {[m.n for m in self.modes]}")

    def ratios(self, ns) -> tuple[np.ndarray, np.ndarray]:
        """(tau, zeta) of the modes with ``ns`` nodal diameters: their tangential and axial amplitudes per unit
        radial one on the contact circle."""
        return (np.array([self.mode(n).tau for n in ns], dtype=float),
                np.array([self.mode(n).zeta for n in ns], dtype=float))

    def save(self, path: str | Path) -> Path:
        """The casing's modal model as the project's file (JSON, SI; docs/THEORY.md 9.6): what a parameter file's
        ``[fe_casing] model`` names."""
        path = Path(path)
        doc = {"format": CASING_FORMAT, "units": "SI", "radius": self.radius, "info": self.info,
               "modes": [{k: getattr(m, k) for k in MODE_FIELDS} for m in self.modes]}
        tmp = path.with_name(path.name + ".part")
        tmp.write_text(json.dumps(doc, indent=1) + "\n")
        tmp.replace(path)
        return path


CASING_FORMAT = "rotorub-casing-1"
MODE_FIELDS = ("n", "frequency_hz", "modal_mass", "modal_stiffness", "damping_ratio", "tau", "zeta")


def load_fe_casing(path: str | Path) -> FECasing:
    """An FE casing's modal model written by :meth:`FECasing.save` (or by hand, to the same schema). One line
    (FEImportError) naming the file and what is accepted when it is not one."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"casing model: {path}: no such file")
    try:
        doc = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FEImportError(f"casing model: {path}: not a JSON file ({exc}); accepted: the {CASING_FORMAT} file "
                            "FECasing.save writes") from None
    if not isinstance(doc, dict) or doc.get("format") != CASING_FORMAT or doc.get("units") != "SI":
        got = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise FEImportError(f"casing model: {path}: format {got!r}; accepted: {CASING_FORMAT!r} in 'SI'")
    modes = []
    for i, md in enumerate(doc.get("modes") or []):
        try:
            vals = {k: (int(md[k]) if k == "n" else float(md[k])) for k in MODE_FIELDS}
        except (KeyError, TypeError, ValueError) as exc:
            raise FEImportError(f"casing model: {path}: mode {i + 1}: {exc!s} missing or not a number; accepted "
                                f"fields: {', '.join(MODE_FIELDS)}") from None
        if not (vals["n"] >= 2 and vals["modal_mass"] > 0 and vals["modal_stiffness"] > 0
                and all(np.isfinite(v) for v in vals.values())):
            raise FEImportError(f"casing model: {path}: mode {i + 1}: n >= 2, a positive modal mass and stiffness "
                                f"expected, got {vals}")
        modes.append(CasingMode(**vals))
    if not modes:
        raise FEImportError(f"casing model: {path}: no modes")
    r = doc.get("radius")
    if not (isinstance(r, int | float) and r > 0):
        raise FEImportError(f"casing model: {path}: radius {r!r}; accepted: the contact circle's radius > 0 m")
    return FECasing(radius=float(r), modes=tuple(sorted(modes, key=lambda m: m.n)), info=doc.get("info", {}))

def harmonic_content(angles: np.ndarray, radial: np.ndarray, n_max: int) -> tuple[int, float, float]:
    """(n, a_c, a_s): the dominant harmonic of a radial displacement sampled at ``angles`` and its cos/sin
    amplitudes (least squares on the samples, which need not be evenly spaced)."""
    best = (0, 0.0, 0.0)
    power = -1.0
    for n in range(0, n_max + 1):
        B = np.column_stack([np.cos(n * angles), np.sin(n * angles)])
        (ac, as_), *_ = np.linalg.lstsq(B, radial, rcond=None)
        pw = ac * ac + as_ * as_
        if pw > power:
            best, power = (n, float(ac), float(as_)), pw
    return best


def casing_from_modes(frequencies_hz, shapes: np.ndarray, points: np.ndarray, mass_norms=None,
                      damping_ratio: float | np.ndarray = 0.02, keep: tuple[int, ...] | None = None,
                      purity: float = 0.95) -> FECasing:
    """The FE casing from its modes: ``shapes`` (n_modes, n_points, 3) displacements [m] at ``points``
    (n_points, 3) of the contact circle (rotating-frame axes: the spin axis is z, z = 0 the tip plane),
    ``mass_norms`` phi^T M phi of each mode (default 1: mass-normalised, as FE codes write them). Of each
    nodal diameter in ``keep`` (default: every n >= 2 found) the lowest mode is kept; a mode whose radial
    displacement is less than ``purity`` one harmonic is refused (a casing that is not axisymmetric)."""
    f = np.asarray(frequencies_hz, dtype=float)
    shapes = np.asarray(shapes, dtype=float)
    pts = np.asarray(points, dtype=float)
    if shapes.ndim != 3 or shapes.shape[1:] != (pts.shape[0], 3) or shapes.shape[0] != f.size:
        raise FEImportError(f"casing: shapes {shapes.shape} do not match {f.size} frequencies and "
                            f"{pts.shape[0]} points")
    r = np.hypot(pts[:, 0], pts[:, 1])
    if np.ptp(r) > 1e-6 * r.mean():
        raise FEImportError(f"casing: the sample points are not on one circle about the spin axis (radii "
                            f"{r.min():.6g} to {r.max():.6g} m)")
    a = np.arctan2(pts[:, 1], pts[:, 0])
    e_r = np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)])
    e_t = np.column_stack([-np.sin(a), np.cos(a), np.zeros_like(a)])
    norms = np.ones(f.size) if mass_norms is None else np.asarray(mass_norms, dtype=float)
    zeta_in = np.broadcast_to(np.asarray(damping_ratio, dtype=float), f.shape)
    n_max = max(2, pts.shape[0] // 2 - 1)
    found: dict[int, CasingMode] = {}
    for k in np.argsort(f):
        u = np.einsum("pa,pa->p", shapes[k], e_r)
        w = np.einsum("pa,pa->p", shapes[k], e_t)
        v = shapes[k][:, 2]
        n, ac, as_ = harmonic_content(a, u, n_max)
        A2 = ac * ac + as_ * as_
        if n < 2 or (keep is not None and n not in keep) or n in found:
            continue
        fit = np.column_stack([np.cos(n * a), np.sin(n * a)]) @ np.array([ac, as_])
        if np.sum(fit**2) < purity * np.sum(u**2):
            raise FEImportError(f"casing: mode {k + 1} ({f[k]:.4g} Hz) is not one nodal diameter on the contact "
                                f"circle ({100 * np.sum(fit**2) / np.sum(u**2):.0f} % in n = {n}; accepted >= "
                                f"{100 * purity:.0f} %): the casing is not axisymmetric there")
        B = np.column_stack([np.cos(n * a), np.sin(n * a)])
        (bc, bs), *_ = np.linalg.lstsq(B, w, rcond=None)
        (cc, cs), *_ = np.linalg.lstsq(B, v, rcond=None)
        m = norms[k] / A2
        found[n] = CasingMode(n=n, frequency_hz=float(f[k]), modal_mass=float(m),
                              modal_stiffness=float((2 * np.pi * f[k]) ** 2 * m), damping_ratio=float(zeta_in[k]),
                              tau=float((bs * ac - bc * as_) / A2), zeta=float((cc * ac + cs * as_) / A2))
    if keep is not None:
        missing = [n for n in keep if n not in found]
        if missing:
            raise FEImportError(f"casing: no mode with {missing[0]} nodal diameters among the {f.size} given")
    if not found:
        raise FEImportError("casing: no mode with 2 or more nodal diameters among those given")
    return FECasing(radius=float(r.mean()), modes=tuple(found[n] for n in sorted(found)))


def casing_from_matrices(K: sp.spmatrix, M: sp.spmatrix, dof_nodes: np.ndarray, dof_components: np.ndarray,
                         node_ids: np.ndarray, coordinates: np.ndarray, circle_nodes: np.ndarray, n_modes: int = 30,
                         damping_ratio: float = 0.02, keep: tuple[int, ...] | None = None) -> FECasing:
    """The FE casing from its matrices (SI, coordinates in rotating-frame axes: spin axis z, z = 0 the tip
    plane): its ``n_modes`` lowest modes, sampled at ``circle_nodes`` (the contact circle's nodes)."""
    n = K.shape[0]
    Ks, Ms = sp.csc_matrix(K), sp.csc_matrix(M)
    scale = abs(Ks).max() / max(abs(Ms).max(), 1e-300)
    sigma = -1e-6 * scale  # below the rigid-body modes of an unsupported casing
    try:
        lam, V = sla.eigsh(Ks, k=min(n_modes, n - 2), M=Ms, sigma=sigma, which="LM")
    except (RuntimeError, sla.ArpackError) as exc:
        raise FEImportError(f"casing: the modes cannot be computed ({exc})") from None
    order = np.argsort(lam)
    lam, V = lam[order], V[:, order]
    w = np.sqrt(np.clip(lam, 0.0, None))
    key = {(int(a), int(c)): i for i, (a, c) in enumerate(zip(dof_nodes, dof_components))}
    idx = {int(k): i for i, k in enumerate(node_ids)}
    rows = np.full((len(circle_nodes), 3), -1)
    for i, node in enumerate(np.asarray(circle_nodes).tolist()):
        if node not in idx:
            raise FEImportError(f"casing: contact-circle node {node} has no coordinates")
        for c in range(3):
            rows[i, c] = key.get((node, c + 1), -1)
    if (rows[:, :2] < 0).any():
        raise FEImportError("casing: a contact-circle node has no free radial-plane translation")
    shapes = np.where(rows[None, :, :] >= 0, V.T[:, np.clip(rows, 0, None)], 0.0)
    pts = coordinates[[idx[int(k)] for k in circle_nodes]]
    norms = np.einsum("ik,ik->k", V, Ms @ V)
    return casing_from_modes(w / (2 * np.pi), shapes, pts, norms, damping_ratio, keep)


def fe_casing_matrices(p: Parameters, casing: FECasing) -> Matrices:
    """The casing block with the FE modes (p.casing.modes nodal diameters) in place of the ring's: rigid
    translation and tilt as structure/casing.py, dofs casing.t.*, casing.r.*, casing.n{n}.*."""
    from ..structure.casing import casing_matrices

    def modal(n: int) -> tuple[float, float, float]:
        md = casing.mode(n)
        return md.modal_mass, md.modal_stiffness, md.damping_ratio

    return casing_matrices(p, modal)


def fe_casing_point_map(p: Parameters, casing: FECasing, point: np.ndarray) -> np.ndarray:
    """structure/casing.py's ``casing_point_map`` with the FE modes: 3 x n_casing, displacement of the casing
    surface point at rest position ``point`` (rotating frame, z from the blade-tip plane)."""
    from ..structure.casing import casing_point_map

    return casing_point_map(p, point, *casing.ratios(p.casing.modes))
