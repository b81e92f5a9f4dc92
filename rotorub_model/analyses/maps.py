"""Maps of balanced static solutions and their stability over (Omega, g0) (paper section 5).

At each speed the static solution is continued from the largest clearance (no
contact: the linear response) down to the smallest, each solve warm-started from
the previous one. Past a fold of that branch (near the critical speed the contact
stiffening bends the resonance) Newton from the warm start, and the solver's own
restarts, can all fail although an equilibrium exists on another branch: measured
on the quick grid, every such cell of the reference (19 in 2D, 13 in 3D) and of a
ten times stiffer contact (62 and 66) has one. There the row tries contact-set
starts (:class:`ContactSetStarts`): with a chosen set of blades in full contact the
law is affine in q, so the balanced solution of that set is one linear solve; the
arcs of neighbouring blades (a whirl's contact patch) are solved in one batch, a 2D
set whose gaps agree with it is an exact equilibrium, and the others (3D: partial
chords are not affine) start Newton, most consistent first. What is still without
a solution is marked, never counted as contact, and left out of every fraction:

* ``NO_EQUILIBRIUM`` (n_contact = -2): proven absent. 2D only, where the law is
  piecewise affine: every one of the 2^N contact sets was solved and none is
  consistent with its own gaps (N <= ENUMERATE_MAX_BLADES);
* ``NOT_CONVERGED`` (n_contact = -1): the solver found none; one may exist (every
  failure of maps written before the contact-set starts is this).

Per point: blades in contact, total chord in contact (3D), the largest real part and
the sum of positive real parts of the eigenvalues of eq. (11), whether Newton
converged, and whether a contact-set start found the solution.

"stable strip" (summary): the contact region's boundary cells (contact cells with a
non-contact neighbour on the grid) are mostly (>= 80 %) stable while unstable
cells exist inside: the paper's 3D picture of a stable band around the unstable area.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..contact import ContactModel, make_contact
from ..plotting import pyplot
from ..structure.model import Model, build_model
from ..structure.params import from_dict, to_dict
from ..writing import save_result
from .stability import stability_indicators
from .static import StaticResult, solve_static
from .sweeps import run_tasks

NOT_CONVERGED = -1  # n_contact of a cell where the solver found no equilibrium (one may exist)
NO_EQUILIBRIUM = -2  # n_contact of a cell where no contact set admits one (2D enumeration: a proof)
ENUMERATE_MAX_BLADES = 12  # 2^12 linear solves of the model's size per proof: ~0.1 s at 38 dofs
NEWTON_STARTS = 16  # contact-set starts tried per cell in 3D (measured: the 8th at most was needed)
ROW_SOLVER = "contact-set starts 1"  # in the task payload: rows saved by an older row solver are not reused
GAP_TOL = 1e-13  # [m] a set's gaps agree with it within this (rounding of a 1e-3 m gap)
STABLE_STRIP_MIN = 0.8  # stable share (by area) of the contact region's boundary cells that makes a "stable strip"


class ContactSetStarts:
    """Balanced solutions of chosen contact sets at one speed: blades in the set in full contact
    (2D: the tip; 3D: both edges), the others free. Each set's law is affine in q and g0,
    F(q) = sum_j (J_j q + g0 h_j), with J_j, h_j from the kernel's law on blade j alone."""

    def __init__(self, model: Model, base: ContactModel, omega: float):
        self.model, self.base, self.omega = model, base, omega
        z = np.zeros(model.n_dofs)
        J, h = [], []
        for j in range(base.n_blades):
            one = base.blade_only(j)  # an imported tip: its segments, every station in contact
            # g0 = -1 closes the blade at q = 0, where its force is -h; the law's first slope (the penalty's: a
            # bilinear law's knee makes the set's law affine only up to it, so its sets are Newton starts only)
            c = ContactModel(base.formulation, base.variant, one.geometry, -1.0, base.k_r, base.mu, base.v_slip)
            J.append(c.jacobian(z, omega))
            h.append(-c.forces(z, omega))
        self.J, self.h = np.array(J), np.array(h)
        self.K = model.K_omega(omega)
        self.F = model.force(omega)

    def arcs(self) -> np.ndarray:
        """Membership (n_sets, N) of every arc of neighbouring blades, and of the empty set."""
        N = self.base.n_blades
        sets = [np.zeros(N)]
        for length in range(1, N + 1):
            for first in range(N if length < N else 1):
                s = np.zeros(N)
                s[(first + np.arange(length)) % N] = 1.0
                sets.append(s)
        return np.array(sets)

    def every_set(self) -> np.ndarray:
        N = self.base.n_blades
        bits = np.arange(1 << N)
        return ((bits[:, None] >> np.arange(N)) & 1).astype(float)

    def solve(self, member: np.ndarray, g0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
        """(q, consistent, violation, all_regular) of each set: consistent where the set's blades
        penetrate at every point and the others at none (within GAP_TOL); violation [m] the sum of
        the gaps that disagree; all_regular False where a set's system is singular (a continuum of
        solutions, or none: no verdict on that set)."""
        n = self.model.n_dofs
        qs, regular = np.zeros((len(member), n)), np.ones(len(member), dtype=bool)
        for lo in range(0, len(member), 1024):  # batches bound the memory (1024 x n x n)
            m = member[lo:lo + 1024]
            A = self.K[None] - np.einsum("sj,jab->sab", m, self.J)
            b = self.F[None] + g0 * (m @ self.h)
            try:
                qs[lo:lo + len(m)] = np.linalg.solve(A, b[..., None])[..., 0]
            except np.linalg.LinAlgError:
                for k in range(len(m)):
                    try:
                        qs[lo + k] = np.linalg.solve(A[k], b[k])
                    except np.linalg.LinAlgError:
                        regular[lo + k] = False
        c = self.base.with_clearance(g0)
        gaps = c.by_blade(c.gaps_batch(qs))  # (sets, N, points of a blade)
        inside = member > 0
        closed = (gaps < GAP_TOL).all(axis=2)
        free = (gaps > -GAP_TOL).all(axis=2)
        consistent = np.all(np.where(inside, closed, free), axis=1) & regular
        violation = np.where(inside, np.clip(gaps.max(axis=2), 0, None), np.clip(-gaps.min(axis=2), 0, None)).sum(1)
        violation[~regular] = np.inf
        return qs, consistent, violation, bool(regular.all())

    def find(self, g0: float, near: np.ndarray | None) -> tuple[StaticResult | None, bool]:
        """(equilibrium or None, proven_absent) at clearance g0; of several, the one nearest ``near``."""
        c = self.base.with_clearance(g0)
        qs, ok, violation, _ = self.solve(self.arcs(), g0)
        # the 2D point law is affine on each side of first contact: a consistent set is an exact equilibrium, and
        # none consistent of all 2^N proves there is none; not so past a bilinear law's knee
        piecewise_affine = self.base.formulation == "2D" and self.base.law == "penalty"
        if piecewise_affine and ok.any():
            return self._polish(c, self._nearest(qs[ok], near)), False
        for k in np.argsort(violation)[:NEWTON_STARTS]:
            st = solve_static(self.model, c, self.omega, q0=qs[k])
            if st.converged:
                return st, False
        if not piecewise_affine or self.base.n_blades > ENUMERATE_MAX_BLADES:
            return None, False
        qs, ok, _, regular = self.solve(self.every_set(), g0)
        if ok.any():
            return self._polish(c, self._nearest(qs[ok], near)), False
        return None, regular

    @staticmethod
    def _nearest(qs: np.ndarray, near: np.ndarray | None) -> np.ndarray:
        return qs[0] if near is None else qs[int(np.argmin(np.linalg.norm(qs - near, axis=1)))]

    def _polish(self, c: ContactModel, q: np.ndarray) -> StaticResult | None:
        # the set's solution is exact; Newton from it returns the solver's result and residual
        st = solve_static(self.model, c, self.omega, q0=q)
        return st if st.converged else None


@lru_cache(maxsize=8)
def _cached_model(params_json: str, mistuning: tuple[float, ...] | None = None) -> Model:
    import json

    return build_model(from_dict(json.loads(params_json)), mistuning=mistuning)


def map_row(params_json: str, formulation: str, variant: str, speed: float, g0s: list[float],
            solver: str = ROW_SOLVER, mistuning: list[float] | None = None) -> dict[str, np.ndarray]:
    """One speed row of a static/stability map (top-level: runs in any worker); ``mistuning``: the model's
    per-blade stiffness deviations (the parameters do not hold them)."""
    model = _cached_model(params_json, None if mistuning is None else tuple(mistuning))
    omega = speed * model.params.normalisation.omega_ref
    order = np.argsort(g0s)[::-1]
    n = len(g0s)
    keys = ("n_contact", "chord_total", "max_real", "sum_pos", "converged", "residual", "from_contact_set")
    out = {k: np.zeros(n) for k in keys}
    base = make_contact(model, formulation, variant)
    starts: ContactSetStarts | None = None  # built at the row's first failure only
    q = q_last = None
    for i in order:
        c = base.with_clearance(float(g0s[i]))
        st = solve_static(model, c, omega, q0=q)
        proven_absent = False
        if not st.converged:
            starts = starts or ContactSetStarts(model, base, omega)
            found, proven_absent = starts.find(float(g0s[i]), q_last)
            if found is not None:
                st = found
                out["from_contact_set"][i] = 1.0
        q = st.q if st.converged else None
        out["converged"][i] = float(st.converged)
        out["residual"][i] = st.residual
        if not st.converged:
            out["n_contact"][i] = NO_EQUILIBRIUM if proven_absent else NOT_CONVERGED
            out["max_real"][i] = out["sum_pos"][i] = np.nan
            continue
        q_last = st.q
        out["n_contact"][i] = st.n_contact
        out["chord_total"][i] = float(np.sum(st.fractions))
        out["max_real"][i], out["sum_pos"][i] = stability_indicators(model, c, omega, st.q)
    return out


@dataclass
class StabilityMap:
    formulation: str
    speeds: np.ndarray  # normalised
    g0s: np.ndarray  # m
    n_contact: np.ndarray  # (n_speeds, n_g0); NOT_CONVERGED, NO_EQUILIBRIUM where no solution
    chord_total: np.ndarray
    max_real: np.ndarray
    sum_pos: np.ndarray
    converged: np.ndarray
    from_contact_set: np.ndarray | None = None  # 1 where a contact-set start found the solution

    @property
    def contact(self) -> np.ndarray:
        return self.n_contact > 0

    @property
    def unstable(self) -> np.ndarray:
        from .stability import RE_TOL

        return np.nan_to_num(self.max_real, nan=-np.inf) > RE_TOL

    @property
    def no_solution(self) -> np.ndarray:
        """Cells without a balanced solution on the map, whatever the reason."""
        return self.n_contact < 0

    @property
    def not_converged(self) -> np.ndarray:
        return self.n_contact == NOT_CONVERGED

    @property
    def no_equilibrium(self) -> np.ndarray:
        """Cells where no equilibrium exists (proven)."""
        return self.n_contact == NO_EQUILIBRIUM

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

    def boundary_stable_fraction(self) -> float | None:
        """Stable share of the contact region's boundary cells, by area like every fraction of the map (the
        quick grid's clearances are spaced quadratically: a count would weigh the thin cells near g0 = 0
        as much as the wide ones at the top)."""
        b = self.boundary()
        if not b.any():
            return None
        a = self.cell_areas()
        return float(a[b & ~self.unstable].sum() / a[b].sum())

    def stable_strip(self) -> bool:
        f = self.boundary_stable_fraction()
        if f is None or not (self.unstable & self.contact).any():
            return False
        return bool(f >= STABLE_STRIP_MIN)

    def summary(self) -> dict:
        c = self.contact
        b = self.boundary()
        rescued = 0 if self.from_contact_set is None else int(np.sum(self.from_contact_set > 0))
        return {
            "formulation": self.formulation,
            "unstable_fraction": self.unstable_fraction(),
            "contact_points": int(c.sum()),
            "grid_points": int(c.size),
            "max_blades_in_contact": int(self.n_contact.max()),
            "stable_strip": self.stable_strip(),
            "boundary_stable_fraction": self.boundary_stable_fraction(),
            "boundary_cells": int(b.sum()),
            "boundary_stable_cells": int((~self.unstable[b]).sum()),
            "no_equilibrium_points": int(self.no_equilibrium.sum()),
            "not_converged_points": int(self.not_converged.sum()),
            "found_from_contact_set_points": rescued,
            "no_solution_note": "no_equilibrium_points: proven (2D: no contact set is consistent with its gaps); "
                                "not_converged_points: the solver found none, one may exist; "
                                "found_from_contact_set_points: solved from a contact-set start after the "
                                "warm start failed (past a fold of the branch continued in g0)",
            "max_sum_positive_real": float(np.nanmax(self.sum_pos)) if np.isfinite(self.sum_pos).any() else 0.0,
        }

    def figure(self):
        """Blades in contact (left) and the stability of the static solution (right), the flat colours' legend
        below, the clearance axis where the contact region is."""
        return maps_figure({self.formulation: self})

    @classmethod
    def load(cls, folder: str | Path, formulation: str) -> StabilityMap:
        """A map written by :meth:`save` (``stability_<formulation>.npz`` in ``folder``)."""
        d = np.load(Path(folder) / f"stability_{formulation}.npz")
        rescued = d["from_contact_set"] if "from_contact_set" in d.files else None
        return cls(formulation, d["speeds"], d["g0s"], d["n_contact"].astype(int), d["chord_total"], d["max_real"],
                   d["sum_pos"], d["converged"], rescued)

    def save(self, out: str | Path) -> dict:
        """stability_<formulation>.png, .json and .npz in ``out``; returns the summary."""
        stem = f"stability_{self.formulation}"
        s = save_result(self, out, stem)
        extra = {} if self.from_contact_set is None else {"from_contact_set": self.from_contact_set}
        np.savez(Path(out) / f"{stem}.npz", speeds=self.speeds, g0s=self.g0s, n_contact=self.n_contact,
                 chord_total=self.chord_total, max_real=self.max_real, sum_pos=self.sum_pos, converged=self.converged,
                 **extra)
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
        {"params_json": pj, "formulation": formulation, "variant": variant, "speed": float(s), "g0s": g0l,
         "solver": ROW_SOLVER}
        for s in speeds
    ]
    if model.mistuning is not None:  # the workers rebuild the model: a mistuned disk's deviations go with it
        for pl in payloads:
            pl["mistuning"] = list(model.mistuning)
    rows = run_tasks(map_row, payloads, executor=executor, out=out, progress=progress,
                     desc=f"{formulation} static+stability map")
    stack = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    return StabilityMap(formulation, np.asarray(speeds, float), np.asarray(g0s, float), stack["n_contact"].astype(int),
                        stack["chord_total"], stack["max_real"], stack["sum_pos"], stack["converged"],
                        stack.get("from_contact_set"))


# ----------------------------------------------------------------------------- figures
# Stable cells get one flat colour and the unstable ones a sequential scale that starts well away from
# it (blue against yellow-red, told apart in every common colour vision deficiency too); the scale is
# logarithmic because the sum of positive real parts spans 1e-6 to 10 /s on one map.
STABLE_COLOUR = "#2166ac"
NOT_CONVERGED_COLOUR = "#9a9a9a"
NO_EQUILIBRIUM_COLOUR = "#000000"


def unstable_cmap():
    from matplotlib.colors import ListedColormap

    return ListedColormap(pyplot().get_cmap("YlOrRd")(np.linspace(0.3, 1.0, 256)), name="unstable")


def _cells(ax, m: StabilityMap, mask: np.ndarray, colour: str, zorder: float) -> None:
    from matplotlib.colors import ListedColormap

    ax.pcolormesh(m.speeds, m.g0s * 1e3, np.where(mask, 1.0, np.nan).T, cmap=ListedColormap([colour]),
                  shading="nearest", zorder=zorder)


def _finish(ax, m: StabilityMap) -> None:
    ax.contour(m.speeds, m.g0s * 1e3, m.contact.T.astype(float), levels=[0.5], colors="k", linewidths=0.8,
               zorder=4)
    _cells(ax, m, m.not_converged, NOT_CONVERGED_COLOUR, 3)
    _cells(ax, m, m.no_equilibrium, NO_EQUILIBRIUM_COLOUR, 3)
    ax.set_xlabel("normalised spin speed Ω / Ω_ref [-]")
    ax.grid(alpha=0.2)


def contact_norm(maps: list[StabilityMap]):
    """One discrete scale of blade counts for every panel of a figure (colour means the count in all of them)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    nmax = max(max(int(m.n_contact.max()) for m in maps), 1)
    cmap = ListedColormap(pyplot().get_cmap("viridis")(np.linspace(0.0, 1.0, nmax)))
    return cmap, BoundaryNorm(np.arange(0.5, nmax + 1.0), nmax), nmax


def unstable_norm(maps: list[StabilityMap]):
    """One logarithmic scale of the sum of positive real parts for every panel (the same colour, the same rate)."""
    from matplotlib.colors import LogNorm

    vals = [m.sum_pos[m.contact & m.unstable] for m in maps]
    pos = np.concatenate([v[np.isfinite(v) & (v > 0)] for v in vals]) if vals else np.zeros(0)
    lo, hi = (float(pos.min()), float(pos.max())) if pos.size else (1e-6, 1.0)
    return LogNorm(vmin=lo, vmax=max(hi, lo * 10))


def draw_contact_panel(fig, ax, m: StabilityMap, cax=None, scale=None, colourbar: bool = True):
    """Blades in contact: one colour per count (a discrete scale, its colourbar ticked per count); ``scale``: the
    figure's shared (cmap, norm, nmax) of :func:`contact_norm`. Returns the mesh (for a shared colourbar)."""
    cmap, norm, nmax = scale or contact_norm([m])
    im = ax.pcolormesh(m.speeds, m.g0s * 1e3, np.where(m.contact, m.n_contact, np.nan).T, cmap=cmap, norm=norm,
                       shading="nearest")
    if colourbar:
        fig.colorbar(im, ax=ax, cax=cax, label="blades in contact [-]", ticks=range(1, nmax + 1))
    _finish(ax, m)
    return im


def draw_stability_panel(fig, ax, m: StabilityMap, cax=None, norm=None, colourbar: bool = True):
    """Stable contact cells flat blue; unstable ones coloured by the sum of positive real parts (log scale;
    ``norm``: the figure's shared :func:`unstable_norm`). Returns the mesh (for a shared colourbar)."""
    _cells(ax, m, m.contact & ~m.unstable, STABLE_COLOUR, 1)
    val = np.where(m.contact & m.unstable, m.sum_pos, np.nan)
    im = ax.pcolormesh(m.speeds, m.g0s * 1e3, val.T, cmap=unstable_cmap(), shading="nearest", zorder=2,
                       norm=norm or unstable_norm([m]))
    if colourbar:
        fig.colorbar(im, ax=ax, cax=cax, label="unstable: Σ Re(λ) > 0 [1/s]")
    _finish(ax, m)
    return im


def contact_top_mm(maps: list[StabilityMap]) -> float | None:
    """Where a map's clearance axis ends: a cell and a quarter above the highest clearance with anything but 'no
    contact' at any speed of any map (None: no such cell). The grid runs to 1.6 x the peak response, the contact
    region at most to the 3D closure: the rest would be blank axis."""
    tops = []
    for m in maps:
        j = np.flatnonzero((m.n_contact != 0).any(axis=0))
        if j.size:
            j = int(j.max())
            g = m.g0s * 1e3
            step = (g[j + 1] - g[j]) if j + 1 < len(g) else (g[j] - g[j - 1] if j else 1.0)
            tops.append(float(g[j] + 1.25 * step))
    return max(tops) if tops else None


def maps_figure(maps: dict[str, StabilityMap]):
    """Rows of maps (2D over 3D), blades in contact left and stability right, one colour scale per column shared by
    its rows (the same colour is the same count, the same rate), the flat colours' legend below, the clearance axis
    ending above the contact region (the grid's top named in the title when it is cut)."""
    plt = pyplot()
    ms = list(maps.values())
    n = len(ms)
    fig, axes = plt.subplots(n, 2, figsize=(11, 1.0 + 3.9 * n), sharex=True, sharey=True, squeeze=False,
                             layout="constrained")
    scale, norm = contact_norm(ms), unstable_norm(ms)
    for row, (f, m) in enumerate(maps.items()):
        ic = draw_contact_panel(fig, axes[row, 0], m, scale=scale, colourbar=False)
        iu = draw_stability_panel(fig, axes[row, 1], m, norm=norm, colourbar=False)
        axes[row, 0].set_ylabel(f"{f}: initial clearance g0 [mm]")
        for ax in axes[row]:
            ax.set_xlabel("normalised spin speed Ω / Ω_ref [-]" if row == n - 1 else "")
    fig.colorbar(ic, ax=list(axes[:, 0]), label="blades in contact [-]", ticks=range(1, scale[2] + 1))
    fig.colorbar(iu, ax=list(axes[:, 1]), label="unstable: Σ Re(λ) > 0 [1/s]" + (" (one scale, both rows)" if n > 1
                                                                                  else ""))
    axes[0, 0].set_title("blades in contact")
    axes[0, 1].set_title("stability of the static solution")
    top = contact_top_mm(ms)
    grid_top = max(float(m.g0s[-1]) * 1e3 for m in ms)
    if top is not None and top < grid_top:
        axes[0, 0].set_ylim(min(float(m.g0s[0]) for m in ms) * 1e3, top)
        fig.suptitle(f"clearance axis cut at {top:.3g} mm: no contact above, up to the grid's {grid_top:.3g} mm",
                     fontsize=8.5)
    h = category_handles(ms)
    fig.legend(handles=h, loc="outside lower center", ncol=min(len(h), 3), fontsize=8.5, frameon=False)
    return fig


def category_handles(maps: list[StabilityMap]) -> list:
    """Legend entries of the flat colours (the colour scales have their colourbars); a category that no
    map has is left out, so the legend says nothing the figures do not show."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    h = [Patch(facecolor=STABLE_COLOUR, label="stable contact (every Re(λ) ≤ 0)"),
         Line2D([], [], color="k", lw=0.8, label="edge of the contact region")]
    if any(m.not_converged.any() for m in maps):
        h.append(Patch(facecolor=NOT_CONVERGED_COLOUR, label="solver did not converge (an equilibrium may exist)"))
    if any(m.no_equilibrium.any() for m in maps):
        h.append(Patch(facecolor=NO_EQUILIBRIUM_COLOUR, label="no equilibrium (none of the 2^N contact sets)"))
    h.append(Patch(facecolor="white", edgecolor="0.6", label="no contact"))
    return h
