"""``run_continuation``: static branches, their special points, the periodic orbits the
instability grows into, and the stability boundary as curves over the grid maps.

For each formulation, at the study speed (:func:`study_speed`: the paper's section-6 speed 3.3
omega_ref where it lies on the configuration's grid, else the configuration's first critical speed):

1. the balanced solutions continued in g0 from the top of the map's range to contact at g0 = 0
   (``branch.continue_static``), with contact events, folds, Hopf points and contact-induced
   stability switches located (a change of stability that cannot be located as either is reported
   as "unlocated", never as a Hopf point);
2. the periodic orbits: from the first loss of stability where it is a Hopf point (amplitude
   growing from zero), or, where it is lost at a contact event (2D), from the state a transient
   settles on past it, continued in g0 both ways, with their Floquet multipliers (``periodic``);
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

from ...plotting import pyplot, save_figure
from ...progress import say, stage
from ...structure.model import Model
from ...threads import blas_threads
from ...writing import write_json
from ..maps import StabilityMap
from ..transient import run_transient
from .boundary import Curve, nearest_on_polyline, trace_boundaries
from .branch import Branch, continue_static
from .equilibria import Equilibria
from .periodic import OrbitBranch, continue_orbits, continue_orbits_from_hopf, orbit_from_state

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
    speed_source: str = "given"

    def summary(self) -> dict:
        out: dict = {"speed": self.speed, "speed_source": self.speed_source, "timings_s": self.timings}
        for f, b in self.branches.items():
            hopf = b.of_kind("hopf")
            out[f] = {
                "branch": {"points": len(b.points), "complete": b.complete, "message": b.message},
                "specials": [s.summary() for s in b.specials if s.kind != "contact"],
                # "unlocated": a change of stability whose refinement did not reach a Hopf point's
                # |Re mu| <= 1e-8 /s nor a contact event (reported as such, never as a Hopf point)
                "special_counts": {k: len(b.of_kind(k)) for k in ("hopf", "switch", "fold", "unlocated")},
                "hopf_max_abs_real_part": max((abs(s.point.mu.real) for s in hopf), default=None),
                "contact_events": len(b.of_kind("contact")),
                "orbit_branches": [
                    {"start": ob.notes.get("start", "hopf" if ob.hopf_g0 is not None else "transient"),
                     "message": ob.message, "hopf_g0_m": ob.hopf_g0, "hopf_frequency_rad_s": ob.hopf_frequency,
                     "orbits": [o.summary() for o in ob.orbits], **ob.notes}
                    for ob in self.orbits.get(f, [])],
                "orbit_note": self.orbit_note(f),
                "boundary": {"curves": len(self.curves.get(f, [])),
                             "points": sum(len(c) for c in self.curves.get(f, [])),
                             "kinds": sorted({k for c in self.curves.get(f, []) for k in c.kinds}),
                             **self.agreement.get(f, {})},
            }
        return out

    def orbit_note(self, f: str) -> str:
        """What the figure says about the orbit family of one formulation: where it started, how far it was
        followed, and where it stops short of the special point it belongs to (a truncated family said so)."""
        obs = [ob for ob in self.orbits.get(f, []) if ob.orbits]
        if not obs:
            msgs = "; ".join(ob.message for ob in self.orbits.get(f, []) if ob.message)
            return f"no periodic orbit{': ' + msgs if msgs else ''}"
        g = np.array([o.g0 for ob in obs for o in ob.orbits]) * 1e3
        ob0 = obs[0]
        if ob0.hopf_g0 is not None:
            start = f"born at the Hopf point, g0 = {ob0.hopf_g0 * 1e3:.4g} mm"
        else:
            seed = ob0.notes.get("seed_g0_m")
            start = (f"from a {ob0.notes.get('seed_transient_s', 0):.0f} s transient at g0 = {seed * 1e3:.4g} mm"
                     if seed is not None else "from a transient")
        note = f"orbits {start}, followed over g0 = {g.min():.4g}-{g.max():.4g} mm"
        stopped = [ob.message for ob in obs if ob.message.startswith("stopped after")]
        if stopped:
            note += f"; truncated: {stopped[0]} per direction (the quick study's cap)"
        b = self.branches.get(f)
        sw = [sp.point.g0 * 1e3 for sp in (b.specials if b else []) if sp.kind in ("switch", "hopf", "fold")]
        far = [x for x in sw if x > g.max() * 1.02 or x < g.min() * 0.98]
        if far:
            note += f"; not followed to the {'switch' if b.of_kind('switch') else 'special point'} at {far[0]:.4g} mm"
        return note

    def figure(self, kind: str = "branches"):
        """``"branches"``: the bifurcation diagrams in g0 (the fan-disk centre's distance from the axis, for the
        static solutions and, its largest and smallest over the period, for the orbits: the same quantity, so that
        an orbit born at a Hopf point starts on its static branch), each with a note of how far its orbit family
        was followed; ``"boundaries"``: the stability boundary curves over the grid maps."""
        if kind == "boundaries":
            return self._figure_boundaries()
        if kind != "branches":
            from ...errors import ParameterError

            raise ParameterError(f"kind: '{kind}' unknown; accepted: branches, boundaries")
        plt = pyplot()
        fig, axes = plt.subplots(1, max(len(self.branches), 1), figsize=(6 * max(len(self.branches), 1), 5.0),
                                 squeeze=False, layout="constrained")
        for ax, (f, b) in zip(axes[0], self.branches.items()):
            ax.set_title(f"{f}, Ω = {self.speed:g} Ω_ref")
            ax.set_xlabel("clearance g0 [mm]")
            ax.set_ylabel("fan-disk centre from the axis [mm]\n(orbits: largest and smallest over the period)")
            ax.grid(alpha=0.3)
            if not b.points:
                ax.text(0.5, 0.5, b.message or "no balanced solution", ha="center", va="center", transform=ax.transAxes)
                continue
            g, r, st = _joined(b)
            for mask, style, lab in ((st, "-", "static, stable"), (~st, "--", "static, unstable")):
                ax.plot(g, np.where(mask, r, np.nan), style, color="C0", lw=1.5, label=lab)
            for ob in self.orbits.get(f, []):
                if not ob.orbits:
                    continue
                go = np.array([o.g0 for o in ob.orbits]) * 1e3
                so = np.array([o.stable for o in ob.orbits], dtype=bool)
                for attr in ("disk_max_radius", "disk_min_radius"):
                    ro = np.array([getattr(o, attr) for o in ob.orbits]) * 1e3
                    ax.plot(go[so], ro[so], "o", color="C3", ms=4, label="periodic, stable")
                    ax.plot(go[~so], ro[~so], "o", mfc="none", color="C3", ms=4, label="periodic, unstable")
            marks = {"hopf": ("^", "C2", "Hopf"), "fold": ("s", "k", "fold"), "switch": ("D", "C1", "switch"),
                     "unlocated": ("X", "C4", "stability change, unlocated")}
            for kind_, (m, c, lab) in marks.items():
                sp = b.of_kind(kind_)
                if sp:
                    ax.plot([s.point.g0 * 1e3 for s in sp], [s.point.disk_amplitude * 1e3 for s in sp], m, color=c,
                            ms=8, label=lab)
            touching = [p.g0 for p in b.points if p.n_contact > 0]
            if touching and max(touching) > 0:  # the contact part of the branch, with the first clearance-only stretch
                ax.set_xlim(0.0, 1.3 * max(touching) * 1e3)
            ax.text(0.01, 0.01, _wrap(self.orbit_note(f), 70), transform=ax.transAxes, fontsize=7, va="bottom",
                    ha="left", bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "0.7"})
            _legend(ax)
        return fig

    def _figure_boundaries(self):
        """The boundary curves, each segment in the colour of its kind (a contact-induced switch, a Hopf curve, a
        fold), over the grid maps' verdicts; the legend names only what is drawn."""
        from matplotlib.lines import Line2D

        plt = pyplot()
        fig, axes = plt.subplots(1, max(len(self.curves), 1), figsize=(6 * max(len(self.curves), 1), 4.8),
                                 squeeze=False, layout="constrained")
        colours = {"switch": "C1", "hopf": "C0", "fold": "C4"}
        names = {"switch": "boundary: contact-induced switch", "hopf": "boundary: Hopf", "fold": "boundary: fold"}
        for ax, (f, cs) in zip(axes[0], self.curves.items()):
            handles = []
            mp = self.maps.get(f)
            if mp is not None:
                S, G = np.meshgrid(mp.speeds, mp.g0s * 1e3, indexing="ij")
                for mask, kw, lab in ((mp.unstable, {"c": "C3", "s": 6}, "grid: unstable"),
                                      (mp.contact & ~mp.unstable, {"c": "C2", "s": 6}, "grid: stable, contact"),
                                      (mp.no_solution, {"c": "k", "s": 8, "marker": "x"}, "grid: no equilibrium")):
                    if mask.any():
                        handles.append(ax.scatter(S[mask], G[mask], label=lab, **kw))
            drawn = set()
            for c in cs:
                k = np.array(c.kinds)
                s, g = np.array(c.speeds), np.array(c.g0s) * 1e3
                for i in range(len(s) - 1):  # each segment in the colour of the point it starts from
                    kind = k[i] if k[i] in colours else "switch"
                    ax.plot(s[i:i + 2], g[i:i + 2], "-", color=colours[kind], lw=1.8, solid_capstyle="round")
                    drawn.add(kind)
            handles += [Line2D([], [], color=colours[k], lw=1.8, label=names[k]) for k in colours if k in drawn]
            ax.set_xlabel("normalised spin speed Ω / Ω_ref [-]")
            ax.set_ylabel("clearance g0 [mm]")
            ag = self.agreement.get(f, {})
            ax.set_title(f"{f}: stability boundary; grid cells off the curve's verdict: "
                         f"{ag.get('contradicting_cells', '?')} ({ag.get('contradicting_beyond_one_cell', '?')} beyond "
                         "one cell)", fontsize=8)
            ax.legend(handles=handles, fontsize=7)
            ax.grid(alpha=0.3)
        return fig

    def save(self, out: str | Path) -> dict:
        """continuation.png (the branches), boundaries.png (the curves over the maps) and summary.json."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        save_figure(self.figure("branches"), out / "continuation.png")
        if self.curves:
            save_figure(self.figure("boundaries"), out / "boundaries.png")
        s = self.summary()
        write_json(out / "summary.json", s)
        return s


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def _joined(b: Branch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The branch's (g0 [mm], disk distance [mm], stable) with the special point between two points of
    different verdicts put in twice, once of each, so that the stable and the unstable line meet there
    (else the step across the change is drawn by neither)."""
    specials = [s.point for s in b.specials if s.kind in ("switch", "hopf", "fold", "unlocated")]
    st = b.stable()
    G: list[float] = []
    R: list[float] = []
    S: list[bool] = []
    for i, p in enumerate(b.points):
        if i and st[i] != st[i - 1]:
            lo, hi = sorted((b.points[i - 1].g0, p.g0))
            at = next((x for x in specials if lo <= x.g0 <= hi), p)
            G += [at.g0, at.g0]
            R += [at.disk_amplitude, at.disk_amplitude]
            S += [bool(st[i - 1]), bool(st[i])]
        G.append(p.g0)
        R.append(p.disk_amplitude)
        S.append(bool(st[i]))
    return np.array(G) * 1e3, np.array(R) * 1e3, np.array(S, dtype=bool)


def _legend(ax) -> None:
    """One legend entry per label (the branches and curves repeat theirs)."""
    h, lab = ax.get_legend_handles_labels()
    uniq = dict(zip(lab, h))
    ax.legend(uniq.values(), uniq.keys(), fontsize=7)


def _junctions(polys: list[np.ndarray]) -> list[np.ndarray]:
    """Where boundaries of different kinds meet (a switch turning into a Hopf curve at a corner) the correctors
    stop short of the corner, and a curve can end less than a cell from the one it meets. Such an end is joined to
    the nearest point of the other curve (a segment shorter than a cell, at the resolution the agreement is
    judged): a gap there would connect the regions on both sides, and one gap floods a whole map (30 blades, 2D:
    one region, every stable cell 'contradicting'). Returns the joining segments (scaled coordinates)."""
    out = []
    for i, P in enumerate(polys):
        if len(P) < 2 or np.linalg.norm(P[0] - P[-1]) < 1e-9:
            continue
        for e in (P[0], P[-1]):
            best, where = 1.0, None
            for j, Q in enumerate(polys):
                if j == i or len(Q) == 0:
                    continue
                x, d = nearest_on_polyline(e, Q)
                if 1e-12 < d < best:
                    best, where = d, x
            if where is not None:
                out.append(np.array([e, where]))
    return out


def agreement(curves: list[Curve], mp: StabilityMap, cell: tuple[float, float]) -> dict:
    """Grid cells whose verdict contradicts the side of the boundary curves they lie on.

    The curves cut the grid into regions (grid neighbours are connected unless a curve passes
    between them, a curve's end joined to another curve less than a cell away: :func:`_junctions`; cells
    without an equilibrium are left out): inside a region the curves say the
    verdict is one. A region's verdict is its majority; a cell that disagrees contradicts the curves,
    and should lie within one cell of one (a boundary the tracer missed leaves the cells on its far
    side contradicting, away from every curve)."""
    ns, ng = len(mp.speeds), len(mp.g0s)
    xy = np.stack(np.meshgrid(mp.speeds / cell[0], mp.g0s / cell[1], indexing="ij"), axis=-1)
    polys = [np.array([[s / cell[0], g / cell[1]] for s, g in zip(c.speeds, c.g0s)]) for c in curves]
    segs = [np.stack([P[:-1], P[1:]], axis=1) for P in polys if len(P) > 1]
    junctions = _junctions(polys)
    segs += [np.array([j]) for j in junctions]
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
    off = off_branch(mp)
    n_valid = max(int(valid.sum()), 1)
    out = {"grid_cells": int(valid.sum()), "regions": int(len(np.unique(roots[valid]))),
           "junctions_closed": len(junctions),
           "contradicting_cells": int(bad.sum()), "contradicting_fraction": float(bad.sum() / n_valid),
           "contradicting_beyond_one_cell": int(beyond.sum()),
           "contradicting_beyond_one_cell_fraction": float(beyond.sum() / n_valid),
           "contradicting_off_branch": int((bad & off).sum()),
           "contradicting_beyond_one_cell_off_branch": int((beyond & off).sum()),
           "off_branch_cells": int((off & valid).sum())}
    if beyond.any():
        on = int((beyond & ~off).sum())
        rest = f"; {on} are on it, across a boundary the tracer did not follow" if on else ""
        out["reason"] = (
            f"{int((beyond & off).sum())} of the {int(beyond.sum())} cells beyond one cell of every curve are not "
            "continued from the branch the map follows down in g0 (at or below a cell of their speed solved from a "
            "contact-set start or left without a solution: another equilibrium, which the curves, continued from "
            f"their neighbours on the followed branch, do not bound){rest}. The grid map is the reference there "
            "(docs/THEORY.md, section 5.1).")
    return out


def off_branch(mp: StabilityMap) -> np.ndarray:
    """Cells whose equilibrium the map did not continue from the branch it follows down in g0 at their
    speed: at or below (in g0) a cell of the same speed solved from a contact-set start or left without a
    solution, from which the sweep went on warm-started from another equilibrium, or from scratch."""
    order = np.argsort(mp.g0s)[::-1]  # the map's sweep: largest clearance first
    rescued = mp.no_solution.copy()
    if mp.from_contact_set is not None:
        rescued |= mp.from_contact_set > 0
    off = np.zeros_like(rescued)
    off[:, order] = np.logical_or.accumulate(rescued[:, order], axis=1)
    return off


def _cuts(a: np.ndarray, b: np.ndarray, S: np.ndarray) -> bool:
    """Does the segment a-b cross any of the segments S (k, 2, 2)?"""
    c, d = S[:, 0], S[:, 1]

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    o1, o2 = orient(a, b, c), orient(a, b, d)
    o3, o4 = orient(c, d, a), orient(c, d, b)
    return bool(np.any((o1 * o2 <= 0) & (o3 * o4 <= 0)))


def _orbits(eq: Equilibria, branch: Branch, omega: float, max_orbits: int) -> list[OrbitBranch]:
    """The periodic orbits past the first loss of stability along the branch: from a destabilising Hopf
    point when that comes first, else from where a transient settles past the first unstable stretch."""
    lost = [s for s in branch.specials if s.kind in ("hopf", "switch", "unlocated")
            and s.detail.get("direction", "destabilising") == "destabilising"]
    if lost and lost[0].kind == "hopf":
        h = lost[0].point
        ob = continue_orbits_from_hopf(eq, omega, h.g0, h.mu, 0.0, max_orbits=max_orbits)
        ob.notes = {"start": "hopf"}
        return [ob]
    return _orbits_from_transient(eq, branch, omega, max_orbits)


def _orbits_from_transient(eq: Equilibria, branch: Branch, omega: float, max_orbits: int) -> list[OrbitBranch]:
    """Where the solution loses stability at a contact event (2D: a switch, no Hopf point), the orbit a
    transient settles on past it, continued both ways."""
    unstable = [p for p in branch.points if p.max_real is not None and p.max_real > 0.1]
    if not unstable:
        return []
    p = unstable[0]
    g0 = p.g0
    q0, v0 = eq.unstable_start(p.q, omega, g0, p.mu, 1e-5)
    # 40 s chunks until the disk's peak-to-peak over the last 2 s is within 3 % of that 10 s before, 200 s at
    # most: friction 0.3 (2D, Re = +0.24 /s) settles only after ~70 s, and shooting from its state at 40 s
    # converged on the static solution
    elapsed, record_dt = 0.0, 5e-4
    while True:
        tr = run_transient(eq.model, eq.contact(g0), omega, t_end=40.0, t_ramp=0.0, me=eq.me, q0=q0, v0=v0,
                           record_dt=record_dt)
        elapsed += 40.0
        if tr.diverged or len(tr.q) < 100:
            notes = {"start": "transient", "seed_g0_m": g0, "seed_transient_s": elapsed}
            return [OrbitBranch(eq.formulation, omega, [], f"the transient at g0 = {g0:.4g} m diverged: no orbit",
                                notes=notes)]
        d = tr.q @ eq._T2.T
        w = int(2.0 / record_dt)
        last, before = np.ptp(d[-w:], axis=0).max(), np.ptp(d[-6 * w:-5 * w], axis=0).max()
        if abs(last - before) <= 0.03 * last or elapsed >= 200.0:
            break
        q0, v0 = tr.q[-1], (tr.q[-1] - tr.q[-2]) / (tr.t[1] - tr.t[0])
    notes = {"start": "transient", "seed_g0_m": g0, "seed_transient_s": elapsed}
    d = tr.q[-4000:] @ eq._T2.T
    x = d[:, 0] - d[:, 0].mean()
    up = np.flatnonzero((x[1:] > 0) & (x[:-1] <= 0))
    if len(up) < 3:
        return [OrbitBranch(eq.formulation, omega, [], "the transient settled: no oscillation", notes=notes)]
    period = float(np.mean(np.diff(up)) * (tr.t[1] - tr.t[0]))
    qd = (tr.q[-1] - tr.q[-2]) / (tr.t[1] - tr.t[0])
    o = orbit_from_state(eq, omega, g0, tr.q[-1], qd, period)
    if o is None:
        return [OrbitBranch(eq.formulation, omega, [], "shooting from the transient's last state found no orbit (not "
                            "converged, or converged on the static solution: the transient had not settled)",
                            notes=notes)]
    switch = [s for s in branch.of_kind("switch") if s.point.g0 >= g0]
    top = switch[-1].point.g0 if switch else branch.points[0].g0
    up_branch = continue_orbits(eq, o, top, max_orbits=max_orbits // 2)
    down_branch = continue_orbits(eq, o, 0.0, max_orbits=max_orbits // 2)
    up_branch.notes = dict(notes)
    down_branch.notes = dict(notes)
    return [up_branch, down_branch]


PAPER_SPEED = 3.3  # the paper's section-6 speed (normalised)


def study_speed(model: Model, speeds: np.ndarray) -> tuple[float, str]:
    """The speed of the g0 branches on this configuration, and why: the paper's when it lies on the
    configuration's own speed range (as the transient study picks its point), else the configuration's
    first critical speed (where the paper's speed sits relative to the reference's: the rub is strongest
    there), else the middle of the range."""
    lo, hi = float(np.min(speeds)), float(np.max(speeds))
    if lo <= PAPER_SPEED <= hi:
        return PAPER_SPEED, "the paper's speed, on this configuration's grid"
    from ..linear import run_response

    crit = run_response(model, lo, hi, 400).critical_speeds
    if len(crit):
        return float(crit[0]), "this configuration's first critical speed (the paper's is off its grid)"
    return 0.5 * (lo + hi), "the middle of the grid's speeds (no critical speed on it)"


def run_continuation(model: Model, maps: dict[str, StabilityMap] | None = None, speeds: np.ndarray | None = None,
                     g0s: np.ndarray | None = None, speed: float | None = None, quick: bool = True,
                     formulations: tuple[str, ...] = FORMULATIONS, boundaries: bool = True,
                     progress: bool = False, speed_source: str = "given") -> ContinuationResult:
    """Branches at ``speed`` (normalised; default :func:`study_speed`) in g0 over the map range, orbits,
    and boundary curves over the maps' (or ``speeds`` x ``g0s``) range, compared with the maps when
    given. ``speed_source``: why a given ``speed`` (what the result's summary says of it)."""
    # many small static solutions and eigenproblems (2 n unknowns): one BLAS thread below BLAS_THREADS_FROM
    # (rotorub_model/threads.py: 18 blades at load 5.5, 2 min 57 s against 44 s)
    with blas_threads(2 * model.n_dofs):
        return _run_continuation(model, maps, speeds, g0s, speed, quick, formulations, boundaries, progress,
                                 speed_source)


def _run_continuation(model: Model, maps: dict[str, StabilityMap] | None = None, speeds: np.ndarray | None = None,
                      g0s: np.ndarray | None = None, speed: float | None = None, quick: bool = True,
                      formulations: tuple[str, ...] = FORMULATIONS, boundaries: bool = True,
                      progress: bool = False, speed_source: str = "given") -> ContinuationResult:
    if maps:
        any_map = next(iter(maps.values()))
        speeds, g0s = any_map.speeds, any_map.g0s
    if speeds is None or g0s is None:
        raise ValueError("speeds and g0s (or maps) are needed: the range of the boundary curves")
    source = speed_source
    if speed is None:
        speed, source = study_speed(model, np.asarray(speeds))
    wref = model.params.normalisation.omega_ref
    omega = speed * wref
    max_orbits = 24 if quick else 60
    branches, orbits, curves, agree, timings = {}, {}, {}, {}, {}
    for f in formulations:
        eq = Equilibria(model, f)
        t0 = time.perf_counter()
        with stage(f"continuation {f}: static branch in g0 at Ω = {speed:.4g} Ω_ref", progress, done=False):
            b = continue_static(eq, "g0", omega, float(np.max(g0s)), 0.0)
        branches[f] = b
        timings[f"branch_{f}"] = time.perf_counter() - t0
        if progress:
            n_contact = len(b.of_kind("contact"))  # as the summary counts them: contact events apart
            n_special = len(b.specials) - n_contact
            say(f"continuation {f}: branch {len(b.points)} points, {n_special} special point"
                f"{'' if n_special == 1 else 's'} and {n_contact} contact event{'' if n_contact == 1 else 's'} "
                f"({timings[f'branch_{f}']:.1f} s)")
        t0 = time.perf_counter()
        with stage(f"continuation {f}: periodic orbits past the loss of stability (at most {max_orbits})", progress):
            orbits[f] = _orbits(eq, b, omega, max_orbits) if b.points else []
        timings[f"orbits_{f}"] = time.perf_counter() - t0
        if boundaries:
            t0 = time.perf_counter()
            with stage(f"continuation {f}: stability boundary as curves over the maps' range", progress):
                # the map's verdicts (cells on the branch it follows) seed what the lattice misses
                mp = maps.get(f) if maps else None
                verdicts = None if mp is None else np.where(mp.no_solution | off_branch(mp), -1,
                                                            mp.unstable.astype(int))
                cv, info = trace_boundaries(eq, np.asarray(speeds), np.asarray(g0s), verdicts=verdicts)
            curves[f] = cv
            timings[f"boundary_{f}"] = time.perf_counter() - t0
            agree[f] = {"evaluations": info["evaluations"], "resolution_cells": info["resolution_cells"],
                        "points_by_corrector": info["points_by_corrector"],
                        **{k: v for k, v in info.items() if "map_edges" in k}}
            if maps and f in maps:
                agree[f].update(agreement(cv, maps[f], tuple(info["cell"])))
    return ContinuationResult(speed, branches, orbits, curves, agree, timings, maps or {}, source)


def boundary_curves_only(model: Model, formulation: str, speeds: np.ndarray, g0s: np.ndarray,
                         resolution: float = 0.1) -> tuple[list[Curve], dict]:
    """The boundary curves of one formulation (top-level: runs in a worker process)."""
    return trace_boundaries(Equilibria(model, formulation), np.asarray(speeds), np.asarray(g0s), resolution)


__all__ = ["PAPER_SPEED", "ContinuationResult", "agreement", "boundary_curves_only", "off_branch",
           "run_continuation", "study_speed"]
