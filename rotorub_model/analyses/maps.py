"""Maps of balanced static solutions and their stability over (Omega, g0) (paper section 5).

At each speed the static solution is continued from the largest clearance (no
contact: the linear response) down to the smallest, each solve warm-started from
the previous one. Where no equilibrium is found (Newton cycling between contact
sets, which for a piecewise-linear residual means the static stiffness changes
sign between them: no static solution nearby), the cell is marked (n_contact = -1,
grey in the figures) and left out of every fraction. Per point: blades in contact, total chord in contact (3D),
the largest real part and the sum of positive real parts of the eigenvalues of
eq. (11), and whether Newton converged.

"stable strip" (summary): the contact region's boundary cells (contact cells with a
non-contact neighbour on the grid) are mostly (>= 80 %) stable while unstable
cells exist inside: the paper's 3D picture of a stable band around the unstable area.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..contact import make_contact
from ..results import pyplot, save_figure, save_result
from ..structure.model import Model, build_model
from ..structure.params import from_dict, to_dict
from .stability import stability_indicators
from .static import solve_static
from .sweeps import run_tasks


@lru_cache(maxsize=8)
def _cached_model(params_json: str) -> Model:
    import json

    return build_model(from_dict(json.loads(params_json)))


def map_row(params_json: str, formulation: str, variant: str, speed: float, g0s: list[float]) -> dict[str, np.ndarray]:
    """One speed row of a static/stability map (top-level: runs in any worker)."""
    model = _cached_model(params_json)
    omega = speed * model.params.normalisation.omega_ref
    order = np.argsort(g0s)[::-1]
    n = len(g0s)
    out = {k: np.zeros(n) for k in ("n_contact", "chord_total", "max_real", "sum_pos", "converged", "residual")}
    base = make_contact(model, formulation, variant)
    q = None
    for i in order:
        c = base.with_clearance(float(g0s[i]))
        st = solve_static(model, c, omega, q0=q)
        q = st.q
        out["converged"][i] = float(st.converged)
        out["residual"][i] = st.residual
        if not st.converged:
            # no equilibrium found (near folds, or none exists): marked, never counted as contact
            out["n_contact"][i] = -1
            out["max_real"][i] = out["sum_pos"][i] = np.nan
            q = None
            continue
        out["n_contact"][i] = st.n_contact
        out["chord_total"][i] = float(np.sum(st.fractions))
        out["max_real"][i], out["sum_pos"][i] = stability_indicators(model, c, omega, st.q)
    return out


@dataclass
class StabilityMap:
    formulation: str
    speeds: np.ndarray  # normalised
    g0s: np.ndarray  # m
    n_contact: np.ndarray  # (n_speeds, n_g0)
    chord_total: np.ndarray
    max_real: np.ndarray
    sum_pos: np.ndarray
    converged: np.ndarray

    @property
    def contact(self) -> np.ndarray:
        return self.n_contact > 0

    @property
    def unstable(self) -> np.ndarray:
        from .stability import RE_TOL

        return np.nan_to_num(self.max_real, nan=-np.inf) > RE_TOL

    @property
    def no_solution(self) -> np.ndarray:
        return self.n_contact < 0

    def cell_areas(self) -> np.ndarray:
        """Area of each cell in the (speed, g0) plane: fractions are of the contact AREA,
        whatever the grid spacing (the quick grid is denser at small g0)."""

        def widths(x: np.ndarray) -> np.ndarray:
            if x.size == 1:
                return np.ones(1)
            e = np.concatenate([[x[0]], 0.5 * (x[1:] + x[:-1]), [x[-1]]])
            return np.diff(e)

        return np.outer(widths(self.speeds), widths(self.g0s))

    def unstable_fraction(self) -> float:
        c = self.contact
        a = self.cell_areas()
        return float(a[self.unstable & c].sum() / max(a[c].sum(), 1e-300))

    def boundary(self) -> np.ndarray:
        c = self.contact
        free = np.pad(self.n_contact == 0, 1, constant_values=False)
        nb_free = free[:-2, 1:-1] | free[2:, 1:-1] | free[1:-1, :-2] | free[1:-1, 2:]
        return c & nb_free

    def stable_strip(self) -> bool:
        b = self.boundary()
        if b.sum() == 0 or not (self.unstable & self.contact).any():
            return False
        return bool((~self.unstable[b]).mean() >= 0.8)

    def summary(self) -> dict:
        c = self.contact
        b = self.boundary()
        return {
            "formulation": self.formulation,
            "unstable_fraction": self.unstable_fraction(),
            "contact_points": int(c.sum()),
            "grid_points": int(c.size),
            "max_blades_in_contact": int(self.n_contact.max()),
            "stable_strip": self.stable_strip(),
            "boundary_stable_fraction": float((~self.unstable[b]).mean()) if b.any() else None,
            "no_equilibrium_points": int(self.no_solution.sum()),
            "max_sum_positive_real": float(np.nanmax(self.sum_pos)) if np.isfinite(self.sum_pos).any() else 0.0,
        }

    def plot(self, path: str | Path) -> Path:
        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
        X, Y = self.speeds, self.g0s * 1e3
        nmax = max(int(self.n_contact.max()), 1)
        im0 = axes[0].pcolormesh(X, Y, np.where(self.contact, self.n_contact, np.nan).T, cmap="viridis",
                                 vmin=0.5, vmax=nmax + 0.5, shading="nearest")
        fig.colorbar(im0, ax=axes[0], label="blades in contact", ticks=range(1, nmax + 1))
        axes[1].pcolormesh(X, Y, np.where(self.contact & ~self.unstable, 1.0, np.nan).T, cmap="Greens", vmin=0, vmax=4,
                           shading="nearest")
        val = np.where(self.contact & self.unstable, self.sum_pos, np.nan).T
        im1 = axes[1].pcolormesh(X, Y, val, cmap="inferno_r", shading="nearest")
        fig.colorbar(im1, ax=axes[1], label="sum of positive real parts [1/s]")
        for ax in axes:
            grey = np.where(self.no_solution, 1.0, np.nan).T
            ax.pcolormesh(X, Y, grey, cmap="Greys", vmin=0, vmax=2, shading="nearest")
            ax.contour(X, Y, self.contact.T.astype(float), levels=[0.5], colors="k", linewidths=0.8)
            ax.set_xlabel("normalised spin speed Ω / Ω_ref")
            ax.grid(alpha=0.2)
        axes[0].set_ylabel("initial clearance g0 [mm]")
        axes[0].set_title(f"{self.formulation}: contact configuration")
        axes[1].set_title(f"{self.formulation}: stability (green = stable, grey = no equilibrium)")
        return save_figure(fig, path)

    @classmethod
    def load(cls, folder: str | Path, formulation: str) -> StabilityMap:
        """A map written by :meth:`save` (``stability_<formulation>.npz`` in ``folder``)."""
        d = np.load(Path(folder) / f"stability_{formulation}.npz")
        return cls(formulation, d["speeds"], d["g0s"], d["n_contact"].astype(int), d["chord_total"], d["max_real"],
                   d["sum_pos"], d["converged"])

    def save(self, out: str | Path) -> dict:
        stem = f"stability_{self.formulation}"
        s = save_result(self, out, stem)
        np.savez(Path(out) / f"{stem}.npz", speeds=self.speeds, g0s=self.g0s, n_contact=self.n_contact,
                 chord_total=self.chord_total, max_real=self.max_real, sum_pos=self.sum_pos, converged=self.converged)
        return s


def run_stability_map(
    model: Model,
    formulation: str,
    speeds: np.ndarray,
    g0s: np.ndarray,
    variant: str = "full",
    executor=None,
    out: str | Path | None = None,
    progress: bool = True,
) -> StabilityMap:
    """Static + stability map over normalised ``speeds`` x clearances ``g0s`` [m]."""
    import json

    make_contact(model, formulation, variant)  # validates the names before any work is sent out
    pj = json.dumps(to_dict(model.params), sort_keys=True)
    g0l = [float(g) for g in g0s]
    payloads = [
        {"params_json": pj, "formulation": formulation, "variant": variant, "speed": float(s), "g0s": g0l}
        for s in speeds
    ]
    rows = run_tasks(map_row, payloads, executor=executor, out=out, progress=progress,
                     desc=f"{formulation} static+stability map")
    stack = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    return StabilityMap(formulation, np.asarray(speeds, float), np.asarray(g0s, float), stack["n_contact"].astype(int),
                        stack["chord_total"], stack["max_real"], stack["sum_pos"], stack["converged"])
