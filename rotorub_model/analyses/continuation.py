"""``run_continuation``: static branches, their special points, the periodic orbits the
instability grows into, and the stability boundary as curves over the grid maps.

For each formulation, at the study speed (3.3 omega_ref, the paper's section-6 speed):

1. the balanced solutions continued in g0 from the top of the map's range to contact at g0 = 0
   (``branch.continue_static``), with contact events, folds, Hopf points and contact-induced
   stability switches located;
2. the periodic orbits: from the first destabilising Hopf point (amplitude growing from zero), or,
   where the stability is lost at a contact event (2D), from the state a transient settles on
   past it, continued in g0 both ways, with their Floquet multipliers (``periodic``);
3. the stability boundary over the map's (Omega, g0) range as curves (``boundary``), checked
   against the grid maps: every grid cell whose verdict contradicts the side of the curve it lies
   on should be within one cell of the curve.

The result saves ``continuation.png`` (bifurcation diagrams), ``boundaries.png`` (curves over the
maps) and ``summary.json``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..results import pyplot, save_figure, write_json
from ..structure.model import Model
from .boundary import Curve, trace_boundaries
from .branch import Branch, continue_static
from .equilibria import Equilibria
from .maps import StabilityMap
from .periodic import OrbitBranch, continue_orbits, continue_orbits_from_hopf, orbit_from_state
from .transient import run_transient

FORMULATIONS = ("2D", "3D")


@dataclass
class ContinuationResult:
    speed: float  # normalised speed of the g0 branches
    branches: dict[str, Branch]
    orbits: dict[str, list[OrbitBranch]]
    curves: dict[str, list[Curve]]
    agreement: dict[str, dict]
    timings: dict[str, float]
    maps: dict[str, StabilityMap] = field(default_factory=dict)

    def summary(self) -> dict:
        out: dict = {"speed": self.speed, "timings_s": self.timings}
        for f, b in self.branches.items():
            out[f] = {
                "branch": {"points": len(b.points), "complete": b.complete, "message": b.message},
                "specials": [s.summary() for s in b.specials if s.kind != "contact"],
                "contact_events": len(b.of_kind("contact")),
                "orbit_branches": [
                    {"start": "hopf" if ob.hopf_g0 is not None else "transient", "message": ob.message,
                     "hopf_g0_m": ob.hopf_g0, "hopf_frequency_rad_s": ob.hopf_frequency,
                     "orbits": [o.summary() for o in ob.orbits], **ob.notes}
                    for ob in self.orbits.get(f, [])],
                "boundary": {"curves": len(self.curves.get(f, [])),
                             "points": sum(len(c) for c in self.curves.get(f, [])),
                             "kinds": sorted({k for c in self.curves.get(f, []) for k in c.kinds}),
                             **self.agreement.get(f, {})},
            }
        return out

    def plot(self, path: str | Path) -> Path:
        plt = pyplot()
        fig, axes = plt.subplots(1, len(self.branches), figsize=(6 * len(self.branches), 4.5), squeeze=False)
        for ax, (f, b) in zip(axes[0], self.branches.items()):
            g = np.array([p.g0 for p in b.points]) * 1e3
            F = np.array([p.max_force for p in b.points])
            st = b.stable()
            for mask, style, lab in ((st, "-", "static, stable"), (~st, "--", "static, unstable")):
                y = np.where(mask, F, np.nan)
                ax.plot(g, y, style, color="C0", lw=1.5, label=lab)
            for ob in self.orbits.get(f, []):
                go = np.array([o.g0 for o in ob.orbits]) * 1e3
                Fo = np.array([o.max_force for o in ob.orbits])
                so = np.array([o.stable for o in ob.orbits])
                ax.plot(go[so], Fo[so], "o", color="C3", ms=4, label="periodic, stable")
                ax.plot(go[~so], Fo[~so], "o", mfc="none", color="C3", ms=4, label="periodic, unstable")
            marks = {"hopf": ("^", "C2", "Hopf"), "fold": ("s", "k", "fold"), "switch": ("D", "C1", "switch")}
            for kind, (m, c, lab) in marks.items():
                sp = b.of_kind(kind)
                if sp:
                    ax.plot([s.point.g0 * 1e3 for s in sp], [s.point.max_force for s in sp], m, color=c, ms=8,
                            label=lab)
            touching = [p.g0 for p in b.points if p.n_contact > 0]
            if touching:  # the contact part of the branch, with the first clearance-only stretch
                ax.set_xlim(0.0, 1.3 * max(touching) * 1e3)
            ax.set_xlabel("clearance g0 [mm]")
            ax.set_ylabel("largest blade normal force [N] (orbits: over the period)")
            ax.set_title(f"{f}, Ω = {self.speed:g} Ω_ref")
            _legend(ax)
            ax.grid(alpha=0.3)
        return save_figure(fig, path)

    def plot_boundaries(self, path: str | Path) -> Path:
        plt = pyplot()
        fig, axes = plt.subplots(1, len(self.curves), figsize=(6 * len(self.curves), 4.5), squeeze=False)
        for ax, (f, cs) in zip(axes[0], self.curves.items()):
            mp = self.maps.get(f)
            if mp is not None:
                S, G = np.meshgrid(mp.speeds, mp.g0s * 1e3, indexing="ij")
                ax.scatter(S[mp.unstable], G[mp.unstable], s=6, c="C3", label="grid: unstable")
                ax.scatter(S[mp.contact & ~mp.unstable], G[mp.contact & ~mp.unstable], s=6, c="C2",
                           label="grid: stable, contact")
                ax.scatter(S[mp.no_solution], G[mp.no_solution], s=8, c="k", marker="x", label="grid: no equilibrium")
            for i, c in enumerate(cs):
                k = np.array(c.kinds)
                s, g = np.array(c.speeds), np.array(c.g0s) * 1e3
                ax.plot(s, g, "-", color="k", lw=1.2, label="boundary (continuation)" if i == 0 else None)
                for kind, col in (("hopf", "C0"), ("switch", "C1"), ("fold", "C4")):
                    sel = k == kind
                    if sel.any():
                        ax.plot(s[sel], g[sel], ".", color=col, ms=2, label=kind)
            ax.set_xlabel("Ω / Ω_ref")
            ax.set_ylabel("clearance g0 [mm]")
            ag = self.agreement.get(f, {})
            ax.set_title(f"{f}: stability boundary; grid cells off the curve's verdict: "
                         f"{ag.get('contradicting_cells', '?')} ({ag.get('contradicting_beyond_one_cell', '?')} beyond "
                         "one cell)", fontsize=8)
            _legend(ax)
            ax.grid(alpha=0.3)
        return save_figure(fig, path)

    def save(self, out: str | Path) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        self.plot(out / "continuation.png")
        if self.curves:
            self.plot_boundaries(out / "boundaries.png")
        s = self.summary()
        write_json(out / "summary.json", s)
        return s


def _legend(ax) -> None:
    """One legend entry per label (the branches and curves repeat theirs)."""
    h, lab = ax.get_legend_handles_labels()
    uniq = dict(zip(lab, h))
    ax.legend(uniq.values(), uniq.keys(), fontsize=7)


def agreement(curves: list[Curve], mp: StabilityMap, cell: tuple[float, float]) -> dict:
    """Grid cells whose verdict contradicts the side of the boundary curves they lie on.

    The curves cut the grid into regions (grid neighbours are connected unless a curve passes
    between them; cells without an equilibrium are left out): inside a region the curves say the
    verdict is one. A region's verdict is its majority; a cell that disagrees contradicts the curves,
    and should lie within one cell of one (a boundary the tracer missed leaves the cells on its far
    side contradicting, away from every curve)."""
    ns, ng = len(mp.speeds), len(mp.g0s)
    xy = np.stack(np.meshgrid(mp.speeds / cell[0], mp.g0s / cell[1], indexing="ij"), axis=-1)
    segs = [np.array([[s / cell[0], g / cell[1]] for s, g in zip(c.speeds, c.g0s)]) for c in curves]
    segs = [np.stack([P[:-1], P[1:]], axis=1) for P in segs if len(P) > 1]
    S = np.concatenate(segs) if segs else np.zeros((0, 2, 2))
    valid = ~mp.no_solution
    parent = np.arange(ns * ng)

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for (di, dj) in ((1, 0), (0, 1)):
        for i in range(ns - di):
            for j in range(ng - dj):
                if not (valid[i, j] and valid[i + di, j + dj]):
                    continue
                if len(S) and _cuts(xy[i, j], xy[i + di, j + dj], S):
                    continue
                a, b = find(i * ng + j), find((i + di) * ng + j + dj)
                parent[a] = b
    roots = np.array([find(k) for k in range(ns * ng)]).reshape(ns, ng)
    bad = np.zeros((ns, ng), dtype=bool)
    for r in np.unique(roots[valid]):
        cells = (roots == r) & valid
        majority = mp.unstable[cells].mean() > 0.5
        bad |= cells & (mp.unstable != majority)
    P = np.concatenate([np.array([[s / cell[0], g / cell[1]] for s, g in zip(c.speeds, c.g0s)]) for c in curves]) \
        if curves else np.zeros((0, 2))
    dist = np.full((ns, ng), np.inf)
    if len(P):
        for i in range(ns):
            dist[i] = np.min(np.linalg.norm(xy[i][:, None, :] - P[None, :, :], axis=-1), axis=1)
    beyond = bad & (dist > 1.0 + 1e-9)
    n_valid = max(int(valid.sum()), 1)
    return {"grid_cells": int(valid.sum()), "regions": int(len(np.unique(roots[valid]))),
            "contradicting_cells": int(bad.sum()), "contradicting_fraction": float(bad.sum() / n_valid),
            "contradicting_beyond_one_cell": int(beyond.sum()),
            "contradicting_beyond_one_cell_fraction": float(beyond.sum() / n_valid)}


def _cuts(a: np.ndarray, b: np.ndarray, S: np.ndarray) -> bool:
    """Does the segment a-b cross any of the segments S (k, 2, 2)?"""
    c, d = S[:, 0], S[:, 1]

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    o1, o2 = orient(a, b, c), orient(a, b, d)
    o3, o4 = orient(c, d, a), orient(c, d, b)
    return bool(np.any((o1 * o2 <= 0) & (o3 * o4 <= 0)))


def _orbits_2d(eq: Equilibria, branch: Branch, omega: float, max_orbits: int) -> list[OrbitBranch]:
    """Where the 2D solution loses stability at a contact event: the orbit a transient settles on
    past it, continued both ways."""
    unstable = [p for p in branch.points if p.max_real is not None and p.max_real > 0.1]
    if not unstable:
        return []
    p = unstable[0]
    g0 = p.g0
    q = p.q
    q0, v0 = eq.unstable_start(q, omega, g0, p.mu, 1e-5)
    tr = run_transient(eq.model, eq.contact(g0), omega, t_end=40.0, t_ramp=0.0, me=eq.me, q0=q0, v0=v0,
                       record_dt=5e-4)
    if tr.diverged or len(tr.q) < 100:
        return [OrbitBranch(eq.formulation, omega, [], f"the transient at g0 = {g0:.4g} m diverged: no orbit")]
    d = tr.q[-4000:] @ eq._T2.T
    x = d[:, 0] - d[:, 0].mean()
    up = np.flatnonzero((x[1:] > 0) & (x[:-1] <= 0))
    if len(up) < 3:
        return [OrbitBranch(eq.formulation, omega, [], "the transient settled: no oscillation")]
    period = float(np.mean(np.diff(up)) * (tr.t[1] - tr.t[0]))
    qd = (tr.q[-1] - tr.q[-2]) / (tr.t[1] - tr.t[0])
    o = orbit_from_state(eq, omega, g0, tr.q[-1], qd, period)
    if o is None:
        return [OrbitBranch(eq.formulation, omega, [], "shooting from the settled transient did not converge")]
    switch = branch.of_kind("switch")
    top = switch[0].point.g0 if switch else branch.points[0].g0
    up_branch = continue_orbits(eq, o, top, max_orbits=max_orbits // 2)
    down_branch = continue_orbits(eq, o, 0.0, max_orbits=max_orbits // 2)
    up_branch.notes = {"seed_g0_m": g0, "seed_transient_s": 40.0}
    down_branch.notes = {"seed_g0_m": g0, "seed_transient_s": 40.0}
    return [up_branch, down_branch]


def run_continuation(model: Model, maps: dict[str, StabilityMap] | None = None, speeds: np.ndarray | None = None,
                     g0s: np.ndarray | None = None, speed: float = 3.3, quick: bool = True,
                     formulations: tuple[str, ...] = FORMULATIONS, boundaries: bool = True,
                     progress: bool = False) -> ContinuationResult:
    """Branches at ``speed`` (normalised) in g0 over the map range, orbits, and boundary curves
    over the maps' (or ``speeds`` x ``g0s``) range, compared with the maps when given."""
    wref = model.params.normalisation.omega_ref
    omega = speed * wref
    if maps:
        any_map = next(iter(maps.values()))
        speeds, g0s = any_map.speeds, any_map.g0s
    if speeds is None or g0s is None:
        raise ValueError("speeds and g0s (or maps) are needed: the range of the boundary curves")
    max_orbits = 24 if quick else 60
    branches, orbits, curves, agree, timings = {}, {}, {}, {}, {}
    for f in formulations:
        eq = Equilibria(model, f)
        t0 = time.perf_counter()
        b = continue_static(eq, "g0", omega, float(np.max(g0s)), 0.0)
        branches[f] = b
        timings[f"branch_{f}"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        hopf = [s for s in b.of_kind("hopf") if s.detail.get("direction") == "destabilising"]
        if hopf:
            h = hopf[0].point
            orbits[f] = [continue_orbits_from_hopf(eq, omega, h.g0, h.mu, 0.0, max_orbits=max_orbits)]
        else:
            orbits[f] = _orbits_2d(eq, b, omega, max_orbits)
        timings[f"orbits_{f}"] = time.perf_counter() - t0
        if progress:
            print(f"continuation {f}: branch {len(b.points)} points, {len(b.specials)} special points")
        if boundaries:
            t0 = time.perf_counter()
            cv, info = trace_boundaries(eq, np.asarray(speeds), np.asarray(g0s))
            curves[f] = cv
            timings[f"boundary_{f}"] = time.perf_counter() - t0
            agree[f] = {"evaluations": info["evaluations"], "resolution_cells": info["resolution_cells"],
                        "points_by_corrector": info["points_by_corrector"]}
            if maps and f in maps:
                agree[f].update(agreement(cv, maps[f], tuple(info["cell"])))
    return ContinuationResult(speed, branches, orbits, curves, agree, timings, maps or {})


def boundary_curves_only(model: Model, formulation: str, speeds: np.ndarray, g0s: np.ndarray,
                         resolution: float = 0.1) -> tuple[list[Curve], dict]:
    """The boundary curves of one formulation (top-level: runs in a worker process)."""
    return trace_boundaries(Equilibria(model, formulation), np.asarray(speeds), np.asarray(g0s), resolution)


__all__ = ["ContinuationResult", "agreement", "boundary_curves_only", "run_continuation"]
