"""The paper's section 5 and 6 studies, packaged: stability maps (2D and 3D) and the
2D-vs-3D transient at a point where the 2D static solution is unstable and the 3D
one stable.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..analyses.maps import StabilityMap, run_stability_map
from ..analyses.stability import stability_of
from ..analyses.static import solve_static
from ..analyses.transient import (  # noqa: F401 - the growth verdict's names, used here and by the FMU side
    DIVERGENCE_FIT_R2,
    DIVERGENCE_GROWTH,
    NO_GROWTH,
    TransientResult,
    envelope_grows,
    envelope_growth,
    run_transient,
)
from ..contact import make_contact
from ..contact.laws import knee_note
from ..errors import ParameterError
from ..plotting import pyplot, save_figure
from ..progress import say, stage
from ..structure.model import Model
from ..writing import write_json

PAPER_POINT = (3.3, 0.8e-3)  # the paper's transient point (normalised speed, g0 [m])
PAPER_PARTIAL = 0.88  # the paper's third blade touches over 88 % of its chord at that point
QUICK_GRID = (40, 36)  # the quick maps' speeds x clearances (the clearances spaced quadratically)
FULL_GRID = (100, 100)


def first_critical(model: Model) -> tuple[float, float]:
    """(first critical speed, the fan's peak amplitude there [m]) of this configuration's imbalance response
    over its range of validity (up to normalisation.speed_max, at most the paper's 10): where its rub studies
    centre. A configuration without imbalance, or without a critical speed in its range, gets a one-line
    :class:`ParameterError`: the studies map the rub the imbalance drives through the first critical."""
    from ..analyses.linear import run_response

    p = model.params
    if p.imbalance.me == 0.0:
        raise ParameterError("imbalance.me: 0 kg m; the stability, transient and continuation studies need an "
                             "imbalance (accepted range (0, inf) kg m): without one nothing touches for g0 >= 0")
    smax = p.normalisation.speed_max
    top = min(10.0, smax)
    r = run_response(model, 0.05, top, n_speeds=max(80, int(80 * top)))
    if not r.critical_speeds and smax > 10.0:  # beyond the paper's range, within the model's validity
        r = run_response(model, 10.0, smax, n_speeds=max(80, int(80 * (smax - 10.0))))
    if not r.critical_speeds:
        raise ParameterError(f"normalisation.speed_max: {smax:g}; this configuration has no critical speed in "
                             f"(0.05, {smax:g}], and its stability, transient and continuation studies centre on the "
                             "first one: raise speed_max if the model holds beyond it; otherwise give `transient` "
                             "a --speed and --g0 (static, modes: a --speed)")
    return float(r.critical_speeds[0]), float(r.peak_amplitudes[0])


def default_grid(model: Model, quick: bool) -> tuple[np.ndarray, np.ndarray]:
    """Speeds around the first critical (within the model's validity, speed_max) and clearances up to its 3D
    closure.

    The quick grid spaces the clearances quadratically (denser near g0 = 0, where the
    contact region is thin away from the peak) so that its boundary is resolved.
    """
    c1, peak = first_critical(model)
    lo, hi = max(c1 - 0.8, 0.05), min(c1 + 0.8, model.params.normalisation.speed_max)
    gmax = 1.6 * peak
    if quick:
        return np.linspace(lo, hi, QUICK_GRID[0]), gmax * np.linspace(0.0, 1.0, QUICK_GRID[1]) ** 2
    return np.linspace(lo, hi, FULL_GRID[0]), np.linspace(0.0, gmax, FULL_GRID[1])


def run_stability_study(model: Model, out: str | Path, quick: bool = False, speeds=None, g0s=None,
                        executor=None, progress: bool = True) -> dict:
    """Maps for 2D and 3D; writes stability_{2D,3D}.png/.json/.npz and summary.json."""
    out = Path(out)
    if speeds is None or g0s is None:
        speeds, g0s = default_grid(model, quick)
    maps = {f: run_stability_map(model, f, speeds, g0s, executor=executor, out=out / "work", progress=progress)
            for f in ("2D", "3D")}
    s2, s3 = maps["2D"].save(out), maps["3D"].save(out)
    _plot_pair(maps, out / "stability_maps.png")
    summary = {
        "unstable_fraction_2d": s2["unstable_fraction"],
        "unstable_fraction_3d": s3["unstable_fraction"],
        "stable_strip_3d": s3["stable_strip"],
        "stable_strip_2d": s2["stable_strip"],
        "max_blades_in_contact_2d": s2["max_blades_in_contact"],
        "max_blades_in_contact_3d": s3["max_blades_in_contact"],
        "no_equilibrium_points_2d": s2["no_equilibrium_points"],
        "no_equilibrium_points_3d": s3["no_equilibrium_points"],
        "not_converged_points_2d": s2["not_converged_points"],
        "not_converged_points_3d": s3["not_converged_points"],
        "found_from_contact_set_points_2d": s2["found_from_contact_set_points"],
        "found_from_contact_set_points_3d": s3["found_from_contact_set_points"],
        "grid": {"speeds": [float(speeds[0]), float(speeds[-1]), len(speeds)],
                 "g0_mm": [float(g0s[0] * 1e3), float(g0s[-1] * 1e3), len(g0s)]},
        "map_2d": s2,
        "map_3d": s3,
    }
    write_json(out / "summary.json", summary)
    return summary


def _plot_pair(maps: dict[str, StabilityMap], path: Path) -> Path:
    """2D over 3D: blades in contact (left) and stability (right), one colour scale per column, the flat colours'
    legend below (analyses.maps.maps_figure)."""
    from ..analyses.maps import maps_figure

    return save_figure(maps_figure(maps), path, dpi=110, layout=False)


def point_status(model: Model, speed: float, g0: float) -> dict:
    """Static solution and stability at one (normalised speed, g0) for 2D and 3D."""
    omega = speed * model.params.normalisation.omega_ref
    res = {}
    for f in ("2D", "3D"):
        c = make_contact(model, f, g0=g0)
        st = solve_static(model, c, omega)
        sb = stability_of(model, c, omega, st.q) if st.converged else None
        res[f] = {"static": st, "stability": sb}
    return res


@dataclass(frozen=True)
class TransientPoint:
    """Where a transient study runs, and why there."""

    speed: float
    g0: float
    source: str  # "paper point", "clearance search at <speed>", "stability maps"
    max_real_2d: float  # 1/s: the 2D static solution's leading eigenvalue (> 0: unstable)
    visible: bool  # the 2D growth shows in the run (the verdict's measure, with a margin of 2 on the rate)
    note: str = ""

    def summary(self) -> dict:
        return {"source": self.source, "max_real_2d_per_s": self.max_real_2d, "instability_visible": self.visible,
                "note": self.note}


def pick_transient_point(model: Model, stab_dir: str | Path | None = None, maps: dict | None = None,
                         progress: bool = False, t_end: float = 20.0) -> tuple[float, float]:
    """(speed, g0) of :func:`choose_transient_point`."""
    pt = choose_transient_point(model, stab_dir, maps, progress, t_end)
    return pt.speed, pt.g0


def choose_transient_point(model: Model, stab_dir: str | Path | None = None, maps: dict | None = None,
                           progress: bool = False, t_end: float = 20.0) -> TransientPoint:
    """:func:`_choose_transient_point` on one BLAS thread: its hundreds of static solutions and eigenvalue problems
    are small (38-160 dofs) and gain nothing from threads, while OpenBLAS's thread per core, spinning against other
    work on a loaded machine, made it 8x slower (an 18-blade configuration, load 5 on 2 cores: 44.6 s against 5.5 s
    on one thread). The rule is rotorub_model/threads.py's (2 n unknowns); a sweep's workers limit their own
    (analyses/sweeps.py)."""
    from ..threads import blas_threads

    with blas_threads(2 * model.n_dofs):
        return _choose_transient_point(model, stab_dir, maps, progress, t_end)


def _choose_transient_point(model: Model, stab_dir: str | Path | None, maps: dict | None, progress: bool,
                            t_end: float) -> TransientPoint:
    """A point where the 2D static solution is unstable and the 3D one stable, from this configuration, where a
    run of t_end shows the 2D instability (its growth e^(Re lambda t_end / 2) over the run's second half, the
    verdict's measure, reaches DIVERGENCE_GROWTH with a margin of 2 on the rate). Candidates, in order; the
    first with a visible instability is taken:

    1. The paper's point (3.3, 0.8 mm) when it qualifies and lies on this configuration's own map grid.
    2. A clearance search at the paper's speed when it is on the grid, else at this configuration's first
       critical speed (where the paper's point sits: the rub is strongest there): 160 clearances up to the
       3D closure (the qualifying windows are ~0.02 mm wide, finer than any map), preferring the most
       visible instability, then three blades touching in 2D and 3D, then the third 3D blade touching over
       a fraction of its chord nearest the paper's 88 %.
    3. This configuration's stability maps (``maps``, else those saved in ``stab_dir``, else the quick maps
       computed here): the qualifying cells, the most visible instability first, then by margin (all eight
       neighbours qualifying; at least two; the rest: a cell on the grid's edge counts its missing neighbours
       as not qualifying, its region may go on beyond the map), the speed nearest the first critical, three 2D
       blades, the middle of the speed's qualifying clearances; each checked at the point itself.
    Where no candidate's instability is visible, the most visible is taken and the point's ``note`` says how long
    a run would show it. A configuration where none qualifies gets a :class:`ParameterError` that says so.
    """
    speeds, g0s = default_grid(model, quick=True)
    # Re lambda the verdict sees in t_end: the envelope grows DIVERGENCE_GROWTH-fold over the second half
    # at that rate, if the ringing has gone by then (measured: the fitted rate is 0.6-1.0 x lambda)
    visible_rate = 2.0 * np.log(DIVERGENCE_GROWTH) / t_end
    candidates: list[tuple[int, int, TransientPoint]] = []

    def consider(order: int, speed: float, g0: float, source: str, max_real: float) -> TransientPoint | None:
        vis = _visibility(max_real, visible_rate)
        pt = TransientPoint(float(speed), float(g0), source, float(max_real), vis == 0)
        candidates.append((vis, order, pt))
        return pt if vis == 0 else None

    on_grid = speeds[0] <= PAPER_POINT[0] <= speeds[-1] and g0s[0] <= PAPER_POINT[1] <= g0s[-1]
    if on_grid:
        st = point_status(model, *PAPER_POINT)
        if _qualifies(st) and (pt := consider(0, *PAPER_POINT, "paper point", st["2D"]["stability"].max_real)):
            return pt
    from ..analyses.linear import linear_response, run_response

    crit = run_response(model, float(speeds[0]), float(speeds[-1]), 400).critical_speeds
    centre = float(crit[0]) if len(crit) else 0.5 * float(speeds[0] + speeds[-1])
    speed = PAPER_POINT[0] if on_grid else centre
    q = linear_response(model, speed * model.params.normalisation.omega_ref)
    closure = float(-make_contact(model, "3D", g0=0.0).gaps(q).min())
    found = []
    for g0 in np.linspace(0.0, max(closure, 0.0), 161)[1:-1]:
        st = point_status(model, speed, float(g0))
        if _qualifies(st):
            n2, n3 = st["2D"]["static"].n_contact, st["3D"]["static"].n_contact
            fr = st["3D"]["static"].fractions
            part = fr[(fr > 0) & (fr < 1)]
            dist = float(np.min(np.abs(part - PAPER_PARTIAL))) if part.size else np.inf
            mr = st["2D"]["stability"].max_real
            found.append(((_visibility(mr, visible_rate), abs(n2 - 3), abs(n3 - 3), dist), float(g0), mr))
    if found:
        _, g0, mr = min(found)
        if pt := consider(1, speed, g0, f"clearance search at {speed:.4g}", mr):
            return pt
    try:
        sp, g0, mr = _pick_from_maps(model, _stability_maps(model, stab_dir, maps, progress), centre, visible_rate)
        if pt := consider(2, sp, g0, "stability maps", mr):
            return pt
    except ParameterError:
        if not candidates:
            raise
    vis, _, pt = min(candidates, key=lambda c: (c[0], c[1]))
    needed = 2.0 * np.log(DIVERGENCE_GROWTH) / pt.max_real_2d * 2.0  # the margin of 2 on the rate
    return TransientPoint(pt.speed, pt.g0, pt.source, pt.max_real_2d, False,
                          f"no qualifying point of this configuration has a 2D instability fast enough for a "
                          f"{t_end:g} s run: the picker asks for Re λ >= {2 * visible_rate:.3g} 1/s (twice the "
                          f"rate at which the envelope grows {DIVERGENCE_GROWTH:g}-fold over the second half, a "
                          f"margin for the ringing and the contact changes on the way), here {pt.max_real_2d:.3g} "
                          f"1/s; the run may or may not show it: --t-end {np.ceil(needed):.0f} s or longer meets "
                          "the margin")


def _visibility(max_real: float, visible_rate: float) -> int:
    """0: the 2D growth shows in the run with a margin of 2 on the rate; 1: just; 2: hardly."""
    return 0 if max_real >= 2.0 * visible_rate else 1 if max_real >= visible_rate else 2


def _pick_from_maps(model: Model, maps: tuple[dict, dict], centre: float,
                    visible_rate: float) -> tuple[float, float, float]:
    from ..analyses.stability import RE_TOL

    m2, m3 = maps
    r2 = np.nan_to_num(m2["max_real"], nan=-1)
    r3 = np.nan_to_num(m3["max_real"], nan=1)
    ok = (m2["n_contact"] > 0) & (m3["n_contact"] > 0) & (r2 > RE_TOL) & (r3 <= RE_TOL)
    if not ok.any():
        raise ParameterError(f"transient point: no cell of this configuration's stability maps (speeds "
                             f"{m2['speeds'][0]:.3g}-{m2['speeds'][-1]:.3g}, g0 up to {m2['g0s'][-1] * 1e3:.3g} "
                             "mm) has an unstable 2D and a stable 3D static solution; give --speed and --g0")
    sp, g = m2["speeds"], m2["g0s"]
    pad = np.pad(ok, 1, constant_values=False)
    margin = sum(pad[1 + di:pad.shape[0] - 1 + di, 1 + dj:pad.shape[1] - 1 + dj].astype(int)
                 for di in (-1, 0, 1) for dj in (-1, 0, 1) if (di, dj) != (0, 0))
    tier = np.where(margin == 8, 0, np.where(margin >= 2, 1, 2))
    cells = [tuple(int(k) for k in ij) for ij in np.argwhere(ok)]
    mid = {i: float(np.median(np.flatnonzero(ok[i]))) for i, _ in cells}
    cells.sort(key=lambda ij: (_visibility(r2[ij], visible_rate), int(tier[ij]), round(abs(sp[ij[0]] - centre), 9),
                               abs(int(m2["n_contact"][ij]) - 3), abs(ij[1] - mid[ij[0]])))
    for i, j in cells[:40]:
        st = point_status(model, float(sp[i]), float(g[j]))
        if _qualifies(st):
            return float(sp[i]), float(g[j]), float(st["2D"]["stability"].max_real)
    raise ParameterError(f"transient point: {len(cells)} cells of this configuration's stability maps qualify "
                         f"(2D unstable, 3D stable) but none of the {min(len(cells), 40)} checked does at the "
                         "point itself (a region thinner than the grid); give --speed and --g0")


def _stability_maps(model: Model, stab_dir, maps, progress: bool) -> tuple[dict, dict]:
    """(2D, 3D) maps as dicts of arrays: given, saved in ``stab_dir``, or computed (quick grid)."""
    out = {}
    for f in ("2D", "3D"):
        if maps is not None and f in maps:
            m = maps[f]
            out[f] = {"speeds": m.speeds, "g0s": m.g0s, "n_contact": m.n_contact, "max_real": m.max_real}
            continue
        f_npz = Path(stab_dir) / f"stability_{f}.npz" if stab_dir else None
        if f_npz is not None and f_npz.exists():
            with np.load(f_npz) as z:
                out[f] = {k: z[k] for k in z.files}
    if len(out) < 2:
        speeds, g0s = default_grid(model, quick=True)
        for f in ("2D", "3D"):
            m = run_stability_map(model, f, speeds, g0s, progress=progress)
            out[f] = {"speeds": m.speeds, "g0s": m.g0s, "n_contact": m.n_contact, "max_real": m.max_real}
    return out["2D"], out["3D"]


def _qualifies(st: dict) -> bool:
    s2, s3 = st["2D"], st["3D"]
    return bool(s2["static"].converged and s3["static"].converged and s2["static"].n_contact > 0
                and s3["static"].n_contact > 0 and not s2["stability"].stable and s3["stability"].stable)


def _deepest(*runs: TransientResult) -> float:
    """The deepest penetration [m] over runs (the largest -gap recorded; 0 where nothing touched)."""
    return max((float(-np.min(r.outputs["gap"], initial=0.0)) for r in runs), default=0.0)


def _law_note(contact, runs: dict[str, TransientResult]) -> str:
    """The law's note over the study's runs (``knee_note``), naming the formulation when only one of them stayed
    short of the knee: a 2D run at 0.18 mm and a 3D run at 0.27 mm with a 0.2 mm knee are not both the bilinear
    law's results, and the note over both (the deeper) said nothing."""
    if contact is None:
        return ""
    notes = {f: knee_note(contact, _deepest(r)) for f, r in runs.items()}
    short = [f for f, n in notes.items() if n]
    if len(short) == len(notes):
        return knee_note(contact, _deepest(*runs.values()))
    return "; ".join(f"{f}: {notes[f]}" for f in short)


@dataclass
class TransientStudy:
    speed: float
    g0: float
    runs: dict[str, TransientResult]
    statics: dict
    point: TransientPoint | None = None  # how the point was chosen (None: given)
    contact: object | None = None  # the [contact] parameters (the law's note)

    def summary(self) -> dict:
        r2, r3 = self.runs["2D"], self.runs["3D"]
        i2, i3 = r2.at_time(1.0), r3.at_time(1.0)
        st3 = self.statics["3D"]["static"]
        fr3 = r3.outputs["fraction"][i3]
        touching = fr3[fr3 > 0]
        partial = touching[touching < 1.0 - 1e-9]
        # the state the 3D run settles on (last record): at exactly 1 s the ramp has just ended
        # and the blades still ring, so the chord fraction there is a snapshot of a transient
        fr_end = r3.outputs["fraction"][-1] if len(r3.t) else np.zeros(0)
        touching_end = fr_end[fr_end > 0]
        # the runs' own verdicts (analyses/transient.py): the same numbers as transient_2D.json, transient_3D.json
        g2, g3 = r2.envelope_growth, r3.envelope_growth
        return {
            "speed": self.speed,
            "g0_mm": self.g0 * 1e3,
            # diverged: either of the two below (one meaning in every file: the runs' own JSON say the same)
            "diverged_2d": r2.diverged,
            "diverged_3d": r3.diverged,
            "penetration_limit_hit": {"2D": r2.penetration_limit_hit, "3D": r3.penetration_limit_hit},
            "envelope_growing": {"2D": r2.envelope_growing, "3D": r3.envelope_growing},
            "envelope_growth": {"2D": g2, "3D": g3},
            "verdicts": {"2D": r2.verdict(), "3D": r3.verdict()},
            "verdict_note": "; ".join(n for n in (
                # only a run that neither hit the penetration limit nor lasted 4 s lacks a verdict: one stopped by
                # the limit at 6.3 s has no growth fit but is diverged, and the note told its reader otherwise
                "" if all(g["factor"] is not None or r.penetration_limit_hit for g, r in ((g2, r2), (g3, r3))) else
                "a run shorter than 4 s gets no growth verdict: diverged is null unless the penetration limit was hit "
                "(the envelope's growth is fitted over the second half of a run of at least 4 s)",
                _law_note(self.contact, {"2D": r2, "3D": r3})) if n),
            "point": self.point.summary() if self.point else {"source": "given"},
            "settled_3d": settled(r3, st3.q) if st3.converged else False,
            "blades_in_contact_2d_at_1s": r2.blades_in_contact(i2),
            "blades_in_contact_3d_at_1s": r3.blades_in_contact(i3),
            "partial_chord_fraction_3d": _partial(touching_end[touching_end < 1.0 - 1e-9], touching_end),
            "partial_chord_fraction_3d_at_1s": _partial(partial, touching),
            "chord_fractions_3d_at_1s": fr3,
            "chord_fractions_3d_settled": fr_end,
            "max_force_at_1s_N": {"2D": float(r2.outputs["F_N"][i2].max()), "3D": float(r3.outputs["F_N"][i3].max())},
            "static_2d": {"blades_in_contact": self.statics["2D"]["static"].n_contact,
                          "max_real_part": _max_real(self.statics["2D"])},
            "static_3d": {"blades_in_contact": st3.n_contact, "chord_fractions": st3.fractions,
                          "max_real_part": _max_real(self.statics["3D"])},
            "messages": {"2D": r2.message, "3D": r3.message},
        }

    def figure(self):
        """2D and 3D forces side by side (each on its own scale: a diverging 2D run would flatten the 3D one), each
        run's verdict in its title; a blade keeps its colour in both panels and the one legend sits right of them,
        outside the data."""
        from ..plotting import plot_blade_forces

        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
        for ax, f in zip(axes, ("2D", "3D")):
            r = self.runs[f]
            plot_blade_forces(ax, r.t, r.outputs["F_N"])
            ax.axvline(1.0, color="k", lw=0.6, ls=":", label="end of the imbalance ramp (1 s)")
            ax.set_title(f"{f}: {r.verdict()}", fontsize=8.5)
            ax.set_xlabel("time [s]")
            ax.set_ylabel("normal contact force F_N [N]")
            ax.grid(alpha=0.3)
        seen: dict[str, object] = {}
        for ax in axes:
            for h, lab in zip(*ax.get_legend_handles_labels()):
                seen.setdefault(lab, h)
        labels = sorted(seen, key=lambda s: (not s.startswith("blade"), int(s.split()[1]) if s.startswith("blade")
                                             else 0))
        fig.legend([seen[k] for k in labels], labels, loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=8,
                   frameon=False)
        fig.suptitle(f"Normal contact forces, Ω = {self.speed:.3g} Ω_ref, g0 = {self.g0 * 1e3:.3g} mm (imbalance "
                     "ramped in over 1 s)")
        fig.tight_layout()
        return fig

    def save(self, out: str | Path) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        for f, r in self.runs.items():
            r.save(out, stem=f"transient_{f}")
        save_figure(self.figure(), out / "contact_forces.png", layout=False)
        s = self.summary()
        write_json(out / "summary.json", s)
        return s


def _partial(partial: np.ndarray, touching: np.ndarray) -> float:
    """Smallest chord fraction among the partly touching blades (else among the touching ones)."""
    if partial.size:
        return float(partial.min())
    return float(touching.min()) if touching.size else 0.0


def _max_real(status: dict) -> float | None:
    return status["stability"].max_real if status["stability"] is not None else None


def diverging(growth: dict) -> bool:
    """The growth verdict (analyses.transient.envelope_grows) as a bool: False where it was not measured."""
    return bool(envelope_grows(growth))


def verdict(run: TransientResult, growth: dict) -> bool | None:
    """Diverged: through the penetration limit, or the envelope of ``growth`` grows; None where the growth could not
    be measured (a run shorter than 4 s) and the limit was not hit: no verdict, rather than a false one. (A run's own
    ``diverged`` is this with its own growth.)"""
    if run.penetration_limit_hit:
        return True
    return envelope_grows(growth)


def growth_after_ramp(run: TransientResult, q_static: np.ndarray, t_from: float | None = None) -> dict:
    """:func:`envelope_growth` of |q - q_static|, the distance to the balanced static solution."""
    if run.q.shape[0] < 4:
        return dict(NO_GROWTH)
    return envelope_growth(run.t, np.linalg.norm(run.q - q_static, axis=1), t_from)


def settled(run: TransientResult, q_static: np.ndarray, rel: float = 0.01) -> bool:
    """Every dof within rel x its largest static value of the static solution at the end."""
    if run.penetration_limit_hit or run.q.shape[0] == 0:
        return False
    err = np.abs(run.q[-1] - q_static)
    return bool(np.all(err <= rel * np.max(np.abs(q_static))))


def run_transient_study(model: Model, out: str | Path, speed: float | None = None, g0: float | None = None,
                        t_end: float = 20.0, stab_dir: str | Path | None = None, progress: bool = True) -> dict:
    """Paper section 6: 2D and 3D transients at one point; picks the point if not given."""
    if (speed is None) != (g0 is None):
        raise ParameterError("transient point: give both --speed and --g0, or neither (automatic choice)")
    point = None
    if speed is None:
        with stage("transient: picking the point (2D unstable, 3D stable) from this configuration", progress):
            point = choose_transient_point(model, stab_dir, progress=progress, t_end=t_end)
        speed, g0 = point.speed, point.g0
        if progress:
            say(f"transient: point Ω = {speed:.4g} Ω_ref, g0 = {g0 * 1e3:.4g} mm ({point.source})")
        if point.note:
            say(f"transient: {point.note}")
    omega = speed * model.params.normalisation.omega_ref
    statics = point_status(model, speed, g0)
    runs = {f: run_transient(model, make_contact(model, f, g0=g0), omega, t_end=t_end, progress=progress)
            for f in ("2D", "3D")}
    return TransientStudy(speed, g0, runs, statics, point, model.params.contact).save(out)


def run_wear_study(model: Model, out: str | Path, speed: float | None = None, g0: float | None = None,
                   t_end: float = 20.0, closure: float = 0.0, offset: tuple[float, float] = (0.0, 0.0),
                   stab_dir: str | Path | None = None, progress: bool = True, **liner) -> dict:
    """2D and 3D transients against the parameter file's abradable liner (``analyses.wear``), at the transient
    study's point unless given; writes out/{2D,3D}/ (wear map, profile, forces, JSON, NPZ) and summary.json."""
    from ..analyses.wear import run_wear

    if (speed is None) != (g0 is None):
        raise ParameterError("wear point: give both --speed and --g0, or neither (the transient study's point)")
    if speed is None:
        with stage("wear: picking the transient study's point", progress):
            speed, g0 = pick_transient_point(model, stab_dir, progress=progress, t_end=t_end)
    out = Path(out)
    summary = {"speed": speed, "g0_mm": g0 * 1e3}
    for f in ("2D", "3D"):
        summary[f] = run_wear(model, f, speed, g0, t_end=t_end, closure=closure, offset=offset, progress=progress,
                              **liner).save(out / f)
    write_json(out / "summary.json", summary)
    return summary


def run_continuation_study(model: Model, out: str | Path, speed: float | None = None,
                           maps_dir: str | Path | None = None, quick: bool = True, progress: bool = True,
                           speed_source: str = "given") -> dict:
    """Branches, special points, orbits and boundary curves (``analyses.continuation``) against the
    stability maps of ``maps_dir`` (or the quick maps, computed here)."""
    from ..analyses.continuation import run_continuation

    if maps_dir is not None:
        try:
            maps = {f: StabilityMap.load(maps_dir, f) for f in ("2D", "3D")}
        except FileNotFoundError as exc:
            raise ParameterError(f"maps: {exc.filename} not found; run `rotorub stability --out DIR` first") from None
    else:
        speeds, g0s = default_grid(model, quick=True)
        if progress:
            say("continuation: no --maps given: computing the quick stability maps first")
        maps = {f: run_stability_map(model, f, speeds, g0s, progress=progress) for f in ("2D", "3D")}
    r = run_continuation(model, maps=maps, speed=speed, quick=quick, progress=progress, speed_source=speed_source)
    s = r.save(out)
    for f in ("2D", "3D"):  # the orbits' count per branch, as the report tabulates them
        if f in s:
            s[f]["orbits"] = [len(b["orbits"]) for b in s[f]["orbit_branches"]]
    return s
