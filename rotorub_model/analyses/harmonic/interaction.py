"""Interaction maps: the forced rub response of a distorted casing over a speed range, from the HB continuation
and from a sweep of transients side by side, with the blade and casing mode crossings k Omega = omega.

Panels: blade-tip amplitude; largest contact force; the casing's incursion (HB: the orbit's deepest
penetration) and, with the liner, the worn depth of the transients with its lobe count. HB branch: solid
where stable, dashed where unstable (Floquet multipliers, :mod:`.stability`), folds and changes of stability
marked. Transients: a filled dot where the run settled on a periodic orbit, a ring for a subharmonic, a cross
(at the top of the panel) where it did not settle on a periodic orbit (still settling, quasi-periodic or
chaotic), a red triangle where it diverged; such runs report no amplitude (the map marks them instead of
pretending).

Agreement: at each transient speed the HB orbit is solved at that very speed, with its multipliers, and the pair
gets a verdict with its reason (both periodic within 1 %; the transient not settled for the HB's multiplier; another
attractor; a periodic transient where the HB orbit is unstable; no stable orbit for either); a disagreement is
marked on the map (a red "≠") and listed in the summary's ``disagreements``.

Branch: followed in segments (:func:`follow_segments`): a blade resonance against the penalty contact hardens
without end, and a segment that climbs it past ``contact.max_penetration`` of tip amplitude is cut there, the
next starting past the furthest speed it reached.

Crossings: the rotating-frame frequencies of the model without contact (the blades' and the casing ring's, the
ring seen in the rotating frame as the model holds it) against k Omega for the forced harmonics k and their
doubles; a dotted line where they meet (k Omega = omega_mode(Omega)), numbered above the top panel in staggered
rows and listed under the figure (the blades of a bladed disk share frequencies: one line with a count).
"""

from __future__ import annotations

import math
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from ...contact import make_contact
from ...errors import ParameterError
from ...plotting import legend_outside, pyplot, save_figure
from ...structure.model import Model
from ...structure.params import to_dict
from ...threads import blas_threads
from ...writing import write_json
from ..linear import first_order
from ..sweeps import run_tasks
from .continuation import HBBranch, HBPoint, continue_hb
from .orbit import OrbitView, measures_at_phases, profile_lobes, tip_deflection
from .problem import HBProblem
from .surface import CasingForcing
from .transients import KINDS, SAMPLES_PER_REV, SETTLE_TOL, forced_transient


def mode_crossings(model: Model, speeds: np.ndarray, harmonics: tuple[int, ...], groups=("blades", "casing"),
                   n_grid: int = 121) -> list[dict]:
    """Speeds [rad/s] in [speeds.min(), speeds.max()] where k Omega equals a rotating-frame frequency of a mode
    whose kinetic energy lies mostly in one of ``groups`` (no contact)."""
    grid = np.linspace(float(np.min(speeds)), float(np.max(speeds)), n_grid)
    Md = np.diag(model.M)
    n = model.n_dofs
    fam = []
    for om in grid:
        lam, vec = np.linalg.eig(first_order(model, om))
        keep = lam.imag > 1e-6
        lam, vec = lam[keep], vec[:, keep]
        order = np.argsort(lam.imag)
        lam, vec = lam[order], vec[:, order]
        energy = Md[:, None] * np.abs(vec[n:]) ** 2
        share = {g: energy[model.slices[g]].sum(axis=0) / energy.sum(axis=0) for g in ("shaft", "blades", "casing")}
        label = [max(share, key=lambda g: share[g][i]) for i in range(lam.size)]
        fam.append((lam.imag, label))
    out = []
    nmode = min(len(f[0]) for f in fam)
    for k in harmonics:
        for j in range(nmode):
            d = np.array([k * om - f[0][j] for om, f in zip(grid, fam)])
            for i in np.flatnonzero(np.sign(d[1:]) != np.sign(d[:-1])):
                lab = fam[i][1][j]
                if lab not in groups:
                    continue
                a, b = d[i], d[i + 1]
                om = grid[i] + (grid[i + 1] - grid[i]) * a / (a - b)
                out.append({"k": int(k), "mode": j + 1, "group": lab, "omega_rad_s": float(om),
                            "frequency_rad_s": float(k * om)})
    return merge_crossings(out, float(np.ptp(grid)) * 2e-3)


def merge_crossings(crossings: list[dict], tol: float) -> list[dict]:
    """One entry per (harmonic, group) and speed within ``tol`` [rad/s]: the blades of a bladed disk share their
    modes' frequencies (8 of the 10 first blade modes cross 2 Omega at one speed), and eight labelled lines there
    say nothing more than one with a count."""
    out: list[dict] = []
    for c in sorted(crossings, key=lambda c: (c["k"], c["group"], c["omega_rad_s"])):
        last = out[-1] if out else None
        if last and last["k"] == c["k"] and last["group"] == c["group"] and \
                abs(c["omega_rad_s"] - last["omega_rad_s"]) <= tol:
            last["modes"].append(c["mode"])
            continue
        out.append({**c, "modes": [c["mode"]]})
    return sorted(out, key=lambda c: c["omega_rad_s"])


def crossing_label(c: dict) -> str:
    who = "blade" if c["group"] == "blades" else "casing"
    n = len(c.get("modes", [c["mode"]]))
    return f"{c['k']}Ω = {who} mode {c['mode']}" + (f" (x{n})" if n > 1 else "")


@dataclass
class InteractionMap:
    formulation: str
    g0: float
    forcing: CasingForcing
    harmonics: int
    omega_ref: float
    branch: HBBranch
    hb: dict[str, np.ndarray]  # per HB point: speed, tip, force, disk, incursion, lobes, stable; harmonics (pts, H+1)
    transients: dict[str, np.ndarray]  # per transient speed: speed, kind, tip, force, wear_depth, wear_lobes
    crossings: list[dict]
    timings: dict[str, float] = field(default_factory=dict)
    t_end: float = 60.0
    refine: int = 1

    # ------------------------------------------------------------------ numbers
    def agreement(self) -> list[dict]:
        """At each transient speed: the transient's kind and amplitudes, and where it settled periodic, the HB
        orbit solved at that very speed (Newton from the nearest stable point of the branch) and the relative
        differences of the blade-tip and fan-disk amplitudes (over max(value, 1e-3 g0): in 2D the blades barely
        move)."""
        return list(self.transients.get("agreement", []))

    def disagreements(self) -> list[dict]:
        return [r for r in self.agreement() if r.get("verdict") == "disagree"]

    def summary(self) -> dict:
        b = self.branch
        ag = self.agreement()
        rel = [abs(r["relative_difference"]) for r in ag if "relative_difference" in r]
        kinds = [KINDS[int(k)] for k in self.transients.get("kind", [])]
        dis = self.disagreements()
        ns = len(b.specials)
        verdict = (f"{self.formulation}, g0 = {self.g0 * 1e3:.3g} mm, casing {_forcing_text(self.forcing)}: HB "
                   f"branch of {len(b.points)} orbits ({b.message}), {int(np.sum(~self.hb['stable']))} unstable, "
                   f"{ns} special point{'' if ns == 1 else 's'}; "
                   # without transients there is nothing to agree or disagree with: "transients at 0 speeds: 0
                   # periodic ...; no disagreement" read as a check that passed
                   + ("no transients beside it (--transients K runs them at K speeds)" if not kinds else
                      f"transients ({self.t_end:g} s) at {len(kinds)} speeds: "
                      f"{sum(k == 'periodic' for k in kinds)} periodic, {sum(k == 'settling' for k in kinds)} not "
                      f"settled, {sum(k not in ('periodic', 'settling') for k in kinds)} not periodic; "
                      + (f"HB-transient amplitudes within {100 * max(rel):.2g} % where both are periodic; "
                         if rel else "no speed where both are periodic; ")
                      + (f"HB and transient DISAGREE at {len(dis)} speed(s): "
                         + "; ".join(f"{r['speed']:.3g}: {r['why']}" for r in dis) if dis else "no disagreement")))
        return {"formulation": self.formulation, "g0_m": self.g0, "forcing": self.forcing.summary(),
                "harmonics": self.harmonics, "omega_ref_rad_s": self.omega_ref, "branch_message": b.message,
                "points": len(b.points), "specials": [s.summary() for s in b.specials],
                "hb": {k: v.tolist() for k, v in self.hb.items() if k != "harmonics"},
                "transients": {k: (v.tolist() if k != "kind" else [KINDS[int(x)] for x in v])
                               for k, v in self.transients.items() if k != "agreement"},
                "transient_t_end_s": self.t_end, "transient_refine": self.refine,
                "crossings": self.crossings, "agreement": ag, "disagreements": dis, "timings_s": self.timings,
                "verdict": verdict}

    # ------------------------------------------------------------------ figures
    def figure(self):
        plt = pyplot()
        wear = "wear_depth" in self.transients
        fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
        s = self.hb["speed"]
        st = self.hb["stable"]
        for ax, key, scale, label in ((axes[0], "tip_amplitude", 1e3, "blade-tip amplitude [mm]"),
                                      (axes[1], "max_force", 1.0, "largest contact force [N]"),
                                      (axes[2], "incursion", 1e3, "incursion / wear depth [mm]")):
            seg = self.hb.get("segment", np.zeros(s.size, dtype=int))
            for k in np.unique(seg):  # a branch cut where it left the model's range is drawn in its pieces
                on = seg == k
                _draw_branch(ax, s[on], self.hb[key][on] * scale, st[on],
                             "HB" + (" incursion" if key == "incursion" else ""))
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
        for sp in self.branch.specials:
            i = int(np.argmin(np.abs(s - sp.point.omega / self.omega_ref)))
            mk = {"fold": "s", "branch": "D", "stability": "o"}[sp.kind]
            axes[0].plot(sp.point.omega / self.omega_ref, self.hb["tip_amplitude"][i] * 1e3, mk, mfc="none",
                         color="k", ms=6,
                         label=None if SPECIAL_LABELS[sp.kind] in _labelled(axes[0]) else SPECIAL_LABELS[sp.kind])
        tr = self.transients
        if tr.get("speed") is not None and len(tr["speed"]):
            kinds = np.array([KINDS[int(k)] for k in tr["kind"]])
            for ax, key, scale in ((axes[0], "tip_amplitude", 1e3), (axes[1], "max_force", 1.0)):
                per = kinds == "periodic"
                ax.plot(tr["speed"][per], tr[key][per] * scale, "o", color="C3", ms=5, label="transient, periodic")
                sub = np.char.startswith(kinds.astype(str), "period-")
                if sub.any():
                    ax.plot(tr["speed"][sub], tr[key][sub] * scale, "o", mfc="none", color="C3", ms=7,
                            label="transient, subharmonic")
                top = ax.get_ylim()[1]
                other = ~per & ~sub & (kinds != "divergent")
                if other.any():
                    ax.plot(tr["speed"][other], np.full(other.sum(), top), "x", color="C3", ms=7, clip_on=False,
                            label="transient not periodic (" + ", ".join(sorted(set(kinds[other]))) + ")")
                if (kinds == "divergent").any():
                    ax.plot(tr["speed"][kinds == "divergent"], np.full(int((kinds == "divergent").sum()), top), "^",
                            color="red", ms=7, clip_on=False, label="transient diverged")
            if wear:
                axes[2].plot(tr["speed"], tr["wear_depth"] * 1e3, "v", color="C2", label="transient wear depth")
                for x, y, lob in zip(tr["speed"], tr["wear_depth"] * 1e3, tr["wear_lobes"]):
                    if y > 0:
                        axes[2].annotate(f"{int(lob)} lobes" if lob else "even", (x, y), textcoords="offset points",
                                         xytext=(0, 5), fontsize=7, ha="center", color="C2")
        # where the HB and the transient disagree (the agreement's verdicts): a red mark at the panel's foot
        dis = self.disagreements()
        for r in dis:
            for ax in axes[:2]:
                ax.annotate("≠", (r["speed"], 0.02), xycoords=("data", "axes fraction"), color="red", fontsize=11,
                            ha="center", va="bottom", fontweight="bold")
        if dis:
            axes[0].plot([], [], ls="none", marker="$≠$", color="red", ms=9,
                         label="HB and transient disagree (why: the JSON's 'disagreements')")
        # mode crossings: dotted lines, numbered above the top panel in staggered rows, listed under the figure
        lo, hi = axes[0].get_xlim()
        rows_x: list[float] = []
        notes = []
        for i, c in enumerate(self.crossings, 1):
            x = c["omega_rad_s"] / self.omega_ref
            for ax in axes:
                ax.axvline(x, color="0.55" if c["group"] == "blades" else "C4", lw=0.7, ls=":")
            row = next((k for k, last in enumerate(rows_x) if x - last > 0.035 * (hi - lo)), len(rows_x))
            if row == len(rows_x):
                rows_x.append(x)
            rows_x[row] = x
            axes[0].annotate(str(i), (x, 1.01 + 0.055 * row), xycoords=("data", "axes fraction"), fontsize=7,
                             ha="center", va="bottom", color="0.3" if c["group"] == "blades" else "C4",
                             annotation_clip=False)
            notes.append(f"{i}: {crossing_label(c)} at {x:.3g}")
        axes[-1].set_xlabel("spin speed Ω / Ω_ref")
        f = self.forcing
        axes[0].set_title(f"Interaction map, {self.formulation}, g0 = {self.g0 * 1e3:.3g} mm, casing "
                          f"{_forcing_text(f)}, H = {self.harmonics}", pad=12 + 9 * len(rows_x))
        if notes:
            text = "Mode crossings k Ω = ω (rotating frame, no contact; grey: blades, purple: casing): " + \
                   "; ".join(notes)
            axes[-1].annotate(textwrap.fill(text, 125), (0.0, -0.3), xycoords="axes fraction", fontsize=7,
                              va="top", ha="left", annotation_clip=False)
        for ax in axes:
            legend_outside(ax)
        return fig

    def harmonics_figure(self):
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(9, 3.6))
        Hc = self.hb["harmonics"]  # (points, H+1)
        rel = Hc / np.maximum(Hc.max(axis=1, keepdims=True), 1e-30)
        s = self.hb["speed"]
        order = np.argsort(s)
        im = ax.pcolormesh(s[order], np.arange(Hc.shape[1]), np.log10(np.maximum(rel[order].T, 1e-8)),
                           shading="nearest", cmap="viridis", vmin=-6, vmax=0)
        fig.colorbar(im, ax=ax, label="log10 |harmonic k| / largest")
        ax.set_xlabel("spin speed Ω / Ω_ref")
        ax.set_ylabel("harmonic k of Ω")
        ax.set_title("Harmonic content of the HB orbits: tip of the most deflected blade, rotating frame\n(a branch "
                     "that folds is drawn where its points fall)", fontsize=10)
        return fig

    def save(self, out: str | Path, stem: str = "interaction_map") -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        save_figure(self.figure(), out / f"{stem}.png")
        save_figure(self.harmonics_figure(), out / f"{stem}_harmonics.png")
        s = self.summary()
        write_json(out / f"{stem}.json", s)
        return s


def _labelled(ax) -> set:
    return set(ax.get_legend_handles_labels()[1])


def _forcing_text(f: CasingForcing) -> str:
    parts = []
    if f.offset_amplitude:
        parts.append(f"offset {f.offset_amplitude * 1e3:.3g} mm")
    parts += [f"{n} lobes {a * 1e3:.3g} mm" for n, (a, _) in sorted(f.lobes.items())]
    return ", ".join(parts) or "round"


def _draw_branch(ax, s, y, stable, label):
    """Stable parts solid, unstable dashed, in the branch's own order (it may fold back); each label once."""
    have = set(ax.get_legend_handles_labels()[1])
    i0 = 0
    for i in range(1, len(s) + 1):
        if i == len(s) or stable[i] != stable[i0]:
            seg = slice(max(i0 - 1, 0), i)
            st = bool(stable[i0])
            lab = f"{label} stable" if st else f"{label} unstable"
            ax.plot(s[seg], y[seg], "-" if st else "--", color="C0" if st else "C1", lw=1.4,
                    label=None if lab in have else lab)
            have.add(lab)
            i0 = i


def _stable_values_at(s, y, stable, x) -> list[float]:
    """Values of the stable parts of a (possibly folding) branch at abscissa x (linear between points)."""
    out = []
    for i in range(len(s) - 1):
        a, b = s[i], s[i + 1]
        if stable[i] and stable[i + 1] and min(a, b) <= x <= max(a, b) and a != b:
            out.append(float(y[i] + (y[i + 1] - y[i]) * (x - a) / (b - a)))
    return out


def _agreement(problem: HBProblem, branch: HBBranch, tr: dict, omega_ref: float, g0: float,
               t_end: float) -> list[dict]:
    """Each transient speed against the HB orbit solved at that very speed (warm-started from the nearest point of
    the branch, stable or not, with its own Floquet multipliers), and a verdict: where the two disagree, why."""
    from .sweep import hb_point

    rows = []
    floor = 1e-3 * abs(g0)
    problem.set_clearance(g0)
    for i, s in enumerate(tr["speed"]):
        kind = KINDS[int(tr["kind"][i])]
        om = float(s * omega_ref)
        row = {"speed": float(s), "transient": kind, "transient_remaining": float(tr["remaining"][i])}
        if kind not in ("divergent",):
            row.update(transient_tip_m=float(tr["tip_amplitude"][i]), transient_disk_m=float(tr["disk_amplitude"][i]))
        near = min(branch.points, key=lambda p: abs(p.omega - om)) if branch.points else None
        p = hb_point(problem, om, None if near is None else near.Y, stability=True, measure_samples=1024)
        if not p.converged:
            row.update(hb="no solution", verdict="disagree", why="the HB found no orbit at this speed")
            rows.append(row)
            continue
        fl = p.floquet
        row.update(hb_tip_m=p.measures.tip_amplitude, hb_disk_m=p.measures.disk_amplitude, hb_stable=fl.stable,
                   hb_largest_multiplier=fl.largest, hb_kind=fl.kind())
        if kind == "periodic" and fl.stable:
            # like with like: the HB read on the transient's own recorded phases (64 a revolution)
            same = measures_at_phases(problem, p.Y, om, om, SAMPLES_PER_REV)
            row.update(hb_tip_same_phases_m=same.tip_amplitude, hb_disk_same_phases_m=same.disk_amplitude)
            row["tip_relative_difference"] = (row["transient_tip_m"] - same.tip_amplitude) / max(
                same.tip_amplitude, floor)
            row["disk_relative_difference"] = (row["transient_disk_m"] - same.disk_amplitude) / max(
                same.disk_amplitude, floor)
            row["relative_difference"] = max(abs(row["tip_relative_difference"]), abs(row["disk_relative_difference"]))
            if row["relative_difference"] <= 0.01:
                row.update(verdict="agree", why="both periodic, amplitudes within 1 %")
            else:
                row.update(verdict="disagree", why=f"both periodic, amplitudes {100 * row['relative_difference']:.2g} "
                           "% apart: the transient's step (T/64) errs on the fast blade mode (dt^2: halve it; "
                           "docs/THEORY.md section 8)")
        elif fl.stable and kind == "settling":
            revs = math.log(SETTLE_TOL) / math.log(max(fl.largest, 1e-12)) if fl.largest < 1 else math.inf
            row.update(verdict="disagree", why=f"the transient had not settled in {t_end:g} s (largest multiplier "
                       f"{fl.largest:.4f}: ~{revs:.0f} revolutions to 2e-3); the HB needs no settling")
        elif fl.stable:
            row.update(verdict="disagree", why=f"the HB orbit is stable but the transient went {kind}: another "
                       "attractor coexists at this speed (the transient's start decides)")
        elif kind == "periodic":
            row.update(verdict="disagree", why=f"the transient settled on a periodic orbit where this HB orbit is "
                       f"unstable ({fl.kind()}): another branch holds it")
        else:
            row.update(verdict="agree", why=f"no stable orbit: HB unstable ({fl.kind()}), the transient {kind}")
        rows.append(row)
    return rows


def hb_measures(problem: HBProblem, branch: HBBranch, omega_ref: float) -> dict[str, np.ndarray]:
    rows = {k: [] for k in ("speed", "tip_amplitude", "max_force", "disk_amplitude", "incursion", "incursion_lobes",
                            "stable", "largest_multiplier", "harmonics")}
    for p in branch.points:
        problem.set_clearance(p.g0)
        view = OrbitView(problem, p.Y, p.omega, p.w)
        m = view.measures()
        prof = view.incursion_profile()
        rows["speed"].append(p.omega / omega_ref)
        rows["tip_amplitude"].append(m.tip_amplitude)
        rows["max_force"].append(m.max_force)
        rows["disk_amplitude"].append(m.disk_amplitude)
        rows["incursion"].append(float(prof.max()))
        rows["incursion_lobes"].append(profile_lobes(prof)[0])
        rows["stable"].append(bool(p.stable) if p.stable is not None else True)
        rows["largest_multiplier"].append(p.floquet.largest if p.floquet is not None else math.nan)
        rows["harmonics"].append(m.tip_harmonics)
    out = {k: np.array(v) for k, v in rows.items()}
    out["stable"] = out["stable"].astype(bool)
    return out


def tip_cap(model: Model, problem: HBProblem, contact) -> callable:
    """The bound a followed branch must stay within: the blade-tip amplitude (the sum of its harmonics' moduli,
    an upper bound, from the orbit's coefficients: no sampling) at most ``contact.max_penetration`` (3 mm in the
    reference), the depth at which the transients stop as diverged. A resonance of the blades against a penalty
    contact hardens without end: the branch climbs its backbone to amplitudes the small-displacement model does
    not hold (measured: 5 mm at 2 Omega = blade mode 3, g0 = 0.1 mm), and a continuation there never returns."""
    cap = float(model.params.contact.max_penetration)

    def halt(p) -> str | None:
        problem.set_clearance(p.g0)
        tip = tip_deflection(model, problem.full(p.Y, p.omega, p.w))  # (2H+1, blades) coefficients
        amp = float(problem.basis.amplitudes(tip)[1:].sum(axis=0).max())
        return None if amp <= cap else (f"blade-tip amplitude above contact.max_penetration = {cap * 1e3:.3g} mm "
                                        "(beyond the model's range: the map restarts past this speed)")
    return halt


# the legend's words for the branch's special points ("HB stability" alone read as a state, not a point where it
# changes)
SPECIAL_LABELS = {"fold": "HB fold", "branch": "HB branch point", "stability": "HB change of stability"}



def follow_segments(problem: HBProblem, start: float, stop: float, g0: float, halt, max_points: int,
                    progress=None, restart_step: float | None = None) -> tuple[HBBranch, np.ndarray]:
    """Continuation in Omega from ``start`` to ``stop`` in segments: a segment ends at the range's end, at
    ``max_points``, or where ``halt`` says; the next starts at the first speed past the furthest one reached
    (steps of ``restart_step``, 0.5 % of the range by default) where Newton from the contact-free response finds
    an orbit within the bound. Returns the points of all segments as one branch and each point's segment."""
    from .sweep import hb_point

    step = restart_step or 0.005 * (stop - start)
    pts, specials, msgs, seg = [], [], [], []
    Y0, s0 = None, start
    while True:
        br = continue_hb(problem, "omega", s0, stop, g0, Y0=Y0, max_points=max_points, progress=progress, halt=halt,
                         unit="rad/s")
        k = len(msgs)
        pts += br.points
        specials += br.specials
        seg += [k] * len(br.points)
        msgs.append(f"from omega = {s0:.4g} rad/s: {br.message}")
        if br.complete or not br.points:
            break
        reached = max(p.omega for p in br.points)
        Y0 = None
        s = reached + step
        while s < stop:
            problem.set_clearance(g0)
            p = hb_point(problem, s, None, stability=False, measure_samples=0)
            if p.converged:
                if halt(HBPoint(s, g0, s, p.Y)) is None:
                    Y0, s0 = p.Y, s
                    break
            s += step
        if Y0 is None:
            msgs.append(f"no orbit within the bound found past {reached:.4g} rad/s")
            break
    complete = bool(pts) and abs(max(p.omega for p in pts) - stop) <= 1e-9 * stop
    return HBBranch("omega", pts, specials, complete, "; ".join(msgs)), np.array(seg, dtype=int)


def run_interaction_map(model: Model, formulation: str = "2D", speed_range: tuple[float, float] = (2.5, 4.5),
                        g0: float | None = None, forcing: CasingForcing | None = None, harmonics: int = 10,
                        n_transients: int = 9, t_end: float = 60.0, wear: bool = True, executor=None,
                        progress: bool = True, out: str | Path | None = None, refine: int = 1,
                        max_points: int = 400) -> InteractionMap:
    """HB continuation in the spin speed over ``speed_range`` (normalised) and transients at ``n_transients``
    speeds through the executor (:func:`..sweeps.run_tasks`: process pool, "serial", or a Dask executor).
    ``forcing`` defaults to an oval casing (2 lobes of 0.3 g0, widest at 0); ``refine`` divides the transients'
    step (T/64): in 3D the fast blade mode needs 2 for the amplitudes to be within 1 % (docs/THEORY.md 8).
    The branch is followed in segments (:func:`follow_segments`): one that climbs a resonance beyond the model's
    range is cut there and the map restarts past the furthest speed it reached."""
    lo, hi = (float(v) for v in speed_range)
    smax = model.params.normalisation.speed_max
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi <= smax):
        raise ParameterError(f"speed range: [{lo}, {hi}]; accepted 0 < A < B <= {smax:g} (normalised speeds; the "
                             "model's validity ends at normalisation.speed_max)")
    if n_transients < 0:
        raise ParameterError(f"n_transients: {n_transients} out of range; accepted [0, inf)")
    g0 = model.params.contact.g0 if g0 is None else float(g0)
    forcing = forcing if forcing is not None else CasingForcing.lobe(2, 0.3 * g0)
    forcing.check(g0)
    wr = model.params.normalisation.omega_ref
    contact = make_contact(model, formulation, g0=g0)
    problem = HBProblem(model, contact, harmonics, forcing=forcing)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(desc=f"HB continuation {formulation}", unit="orbit", total=None)
    t0 = time.perf_counter()
    # small dense algebra: BLAS threads only fight on a shared machine; a large balance (an imported blade's contact
    # spans most of its dofs: 3108 unknowns for the example in 3D) is one dense LU a Newton step, which they share
    # (measured 1.6x on 2 cores), and the transients run only after the branch
    with blas_threads(problem.N):  # the balance's unknowns: every core only for a large one
        def shown(p) -> None:  # where the branch is: a resonance can take hundreds of orbits of a small range
            bar.set_postfix_str(f"Ω/Ω_ref = {p.omega / wr:.4g} in [{lo:g}, {hi:g}]", refresh=False)
            bar.update(1)

        branch, seg = follow_segments(problem, lo * wr, hi * wr, g0, tip_cap(model, problem, contact),
                                      max_points, shown if bar is not None else None)
        t_hb = time.perf_counter() - t0
        hb = hb_measures(problem, branch, wr)
        hb["segment"] = seg
    if bar is not None:
        bar.close()
    t1 = time.perf_counter()
    tr: dict[str, np.ndarray] = {}
    if n_transients:
        speeds = np.linspace(lo, hi, n_transients)
        pd = to_dict(model.params)
        payloads = [{"params": pd, "formulation": formulation, "omega": float(s * wr), "g0": g0,
                     "offset": list(forcing.offset), "lobes": {str(k): list(v) for k, v in forcing.lobes.items()},
                     "t_end": float(t_end), "wears": False, "refine": int(refine)} for s in speeds]
        res = run_tasks(forced_transient, payloads, executor=executor, progress=progress, desc="transients")
        tr = {"speed": speeds, "kind": np.array([int(r["kind"]) for r in res]),
              "remaining": np.array([float(r["remaining"]) for r in res])}
        for key in ("tip_amplitude", "max_force", "disk_amplitude", "penetration"):
            tr[key] = np.array([float(r[key]) if key in r and KINDS[int(r["kind"])] != "divergent" else math.nan
                                for r in res])
        # a run that did not settle on a periodic orbit reports no amplitude: the map marks it
        if wear:
            for p in payloads:
                p["wears"] = True
            resw = run_tasks(forced_transient, payloads, executor=executor, progress=progress, desc="wear transients")
            tr["wear_depth"] = np.array([float(r.get("wear_depth", math.nan)) for r in resw])
            tr["wear_lobes"] = np.array([int(r.get("wear_lobes", 0)) for r in resw])
    t_tr = time.perf_counter() - t1
    if n_transients:
        with threadpool_limits(limits=1):
            tr["agreement"] = _agreement(problem, branch, tr, wr, g0, t_end)
    # the forced harmonics and their doubles (a rub's force is rich in both): k n Omega = omega_mode
    crossings = mode_crossings(model, np.array([lo, hi]) * wr,
                               tuple(sorted({k * n for n in forcing.lobe_counts for k in (1, 2)})))
    result = InteractionMap(formulation, g0, forcing, harmonics, wr, branch, hb, tr, crossings,
                            {"hb_continuation": t_hb, "transients": t_tr}, t_end, refine)
    if out is not None:
        result.save(out)
    return result
