"""``run_wear``: a transient against an abradable liner, and what it leaves behind.

The run is :func:`~rotorub_model.analyses.transient.run_transient` with a
:class:`~rotorub_model.contact.liner.Liner` (the parameter file's ``[abradable]`` section, worn whatever its
``enabled`` says: this is the wear analysis). The result holds the wear map (the worn profile over the
circumference every ``wear_record_dt`` seconds), the final profile per row (2D: the tip; 3D: LE and TE) and
its summary: the largest and mean depth, the removed volume, the plastic work, the dominant lobe count and
the amplitudes of the profile's harmonics 1-8, and the effective clearance the engine keeps afterwards
(g0 - closure + the mean worn depth). It saves ``wear_map.png`` (depth over angle and time),
``wear_profile.png`` (the final profile unrolled and polar, its spectrum), ``forces.png``, ``wear.json``
and ``wear.npz``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..contact import make_contact
from ..contact.liner import Liner
from ..errors import ParameterError
from ..plotting import legend_outside, plot_blade_forces, pyplot, save_figure
from ..structure.model import Model
from ..writing import write_json
from .transient import TransientResult, run_transient

# The kernel's lobe rule (rotorub_kernel.h RR_LOBE_DOMINANCE, RR_LOBE_UNIFORM; tests/library/test_wear.py reads the
# header): a profile whose every harmonic is below LOBE_UNIFORM x its mean depth is worn evenly (no lobes); else the
# largest harmonic h is the lobe count when it is LOBE_DOMINANCE x every harmonic that is not a multiple of h.
LOBE_DOMINANCE = 2.0
LOBE_UNIFORM = 0.05
WEAR_SETTLED = 0.01  # the wear map's time axis: from the first record above, to the last change above, this x the depth


def lobe_verdict(summary: dict) -> tuple[int, str]:
    """(lobe count, the sentence that says why) of a liner summary (its ``harmonic_1..8`` and ``depth_mean`` [m]):
    the kernel's rule, stated with the numbers that decided it, for titles, the JSON and the console.

    >>> lobe_verdict({"depth_mean": 1e-4, **{f"harmonic_{h}": (2e-5 if h == 3 else 1e-6) for h in range(1, 9)}})
    (3, '3 lobes: harmonic 3 is 20 × every harmonic not its multiple (rule: ≥ 2 ×)')
    """
    amps = np.array([summary[f"harmonic_{h}"] for h in range(1, 9)], dtype=float)
    mean = float(summary["depth_mean"])
    k = int(np.argmax(amps)) + 1
    best = float(amps[k - 1])
    if best <= 1e-15:
        return 0, "no wear"
    if best < LOBE_UNIFORM * mean:
        return 0, (f"no lobes, worn evenly: every harmonic below {LOBE_UNIFORM:.0%} of the mean depth (the largest, "
                   f"harmonic {k}, {best / mean:.2%})")
    others = [(float(amps[h - 1]), h) for h in range(1, 9) if h % k != 0]
    other, j = max(others) if others else (0.0, 0)
    if best >= LOBE_DOMINANCE * other:
        lobe = f"{k} lobe{'s' if k != 1 else ''}"
        if other == 0:  # k = 1 (every harmonic is its multiple) or a pure k-lobed profile
            return k, f"{lobe}: harmonic {k} the largest, no other harmonic but its multiples"
        return k, f"{lobe}: harmonic {k} is {best / other:.3g} × every harmonic not its multiple (rule: ≥ " \
                  f"{LOBE_DOMINANCE:g} ×)"
    return 0, (f"no lobe dominates: harmonic {k} is only {best / other:.2g} × harmonic {j} (rule: ≥ {LOBE_DOMINANCE:g} "
               "×)")


@dataclass
class WearResult:
    formulation: str
    speed: float  # normalised
    g0: float  # [m]
    closure: float  # [m]
    offset: tuple[float, float]  # [m]
    liner: dict  # the liner's parameters
    transient: TransientResult

    @property
    def wear(self) -> dict:
        return self.transient.wear

    def summary(self) -> dict:
        w = self.wear["summary"]
        tr = self.transient
        return {
            "formulation": self.formulation, "speed": self.speed, "g0_mm": self.g0 * 1e3,
            "closure_mm": self.closure * 1e3, "casing_offset_mm": [v * 1e3 for v in self.offset],
            "liner": self.liner, "t_end_s": tr.t_end, "diverged": tr.diverged, "message": tr.message,
            "max_normal_force_N": float(tr.outputs["F_N"].max()) if tr.outputs["F_N"].size else 0.0,
            "depth_max_mm": w["depth_max"] * 1e3, "depth_mean_mm": w["depth_mean"] * 1e3,
            "removed_volume_mm3": w["volume"] * 1e9, "plastic_work_J": w["plastic_work"],
            "lobes": w["lobes"], "lobes_verdict": lobe_verdict(w)[1],
            "lobes_rule": f"worn evenly (0 lobes) when every harmonic < {LOBE_UNIFORM:g} x the mean depth; else the "
                          f"largest harmonic h when >= {LOBE_DOMINANCE:g} x every harmonic not a multiple of h; else 0",
            "harmonics_mm": [w[f"harmonic_{h}"] * 1e3 for h in range(1, 9)],
            "clearance_before_mm": (self.g0 - self.closure) * 1e3,
            "clearance_effective_mm": w["clearance_effective"] * 1e3,
        }

    FIGURES = ("wear_map", "wear_profile", "forces")

    def figure(self, kind: str = "wear_profile"):
        """``"wear_map"`` (depth over angle and time, the time axis where the wear happens), ``"wear_profile"`` (the
        final profile unrolled, polar and its spectrum with the lobe verdict) or ``"forces"`` (against the yield)."""
        if kind not in self.FIGURES:
            raise ParameterError(f"kind: '{kind}' unknown; accepted: {', '.join(self.FIGURES)}")
        draw = {"wear_map": self._figure_map, "wear_profile": self._figure_profile, "forces": self._figure_forces}
        return draw[kind]()

    def wear_window(self) -> tuple[float, float] | None:
        """(first, last) record time at which the profile's deepest cell changes by more than WEAR_SETTLED of its
        final depth: where the wear happens (None: no wear recorded)."""
        w = self.wear
        prof, t = w["profiles"], w["t"]
        if not prof.size or prof.max() <= 0:
            return None
        deep = prof.max(axis=1)
        tol = WEAR_SETTLED * float(deep[-1])
        first = int(np.argmax(deep > tol))
        moving = np.flatnonzero(np.abs(np.diff(deep)) > tol * 0.1)
        last = int(moving[-1]) + 1 if moving.size else first
        return float(t[first]), float(t[min(last, len(t) - 1)])

    def _title(self) -> str:
        return (f"{self.formulation}, Ω = {self.speed:.3g} Ω_ref, g0 = {self.g0 * 1e3:.3g} mm, "
                f"F_y = {self.liner['yield_force_N']:g} N")

    def _figure_map(self):
        plt = pyplot()
        w = self.wear
        fig, ax = plt.subplots(figsize=(9, 4.5))
        prof = w["profiles"] * 1e6
        if prof.size:
            t = w["t"]
            im = ax.imshow(prof, aspect="auto", origin="lower", cmap="magma_r", interpolation="nearest",
                           extent=(0.0, 360.0, float(t[0] - 0.5 * (t[1] - t[0]) if len(t) > 1 else 0.0),
                                   float(t[-1])), vmin=0.0, vmax=max(float(prof.max()), 1e-9))
            chord = " (mean over the chord)" if self.formulation == "3D" else ""
            fig.colorbar(im, ax=ax, label=f"worn depth [µm]{chord}")
        else:
            ax.text(0.5, 0.5, "no record: the run was shorter than one wear record", transform=ax.transAxes,
                    ha="center")
        ax.set_xlabel("angle on the casing θ [deg] (fixed frame)")
        ax.set_ylabel("time [s]")
        ax.set_xticks(range(0, 361, 45))
        title = f"wear map: {self._title()}"
        win = self.wear_window()
        if win is not None and prof.size:
            t = w["t"]
            span = max(win[1] - win[0], 2 * (t[1] - t[0]) if len(t) > 1 else 0.05)
            lo, hi = max(float(t[0]) - 0.5 * (t[1] - t[0] if len(t) > 1 else 0), win[0] - 0.15 * span), \
                min(float(t[-1]), win[1] + 0.15 * span)
            if hi - lo < 0.8 * (float(t[-1]) - float(t[0])):
                ax.set_ylim(lo, hi)
                title += (f"\nall the wear between {win[0]:.3g} and {win[1]:.3g} s of the {float(t[-1]):.3g} s run "
                          "(the profile is unchanged after; time axis cut to it)")
        ax.set_title(title, fontsize=9)
        return fig

    def _figure_profile(self):
        plt = pyplot()
        w = self.wear
        th = np.degrees(w["angles"])
        depth = w["depth"] * 1e6
        fig = plt.figure(figsize=(13, 4.2))
        ax = fig.add_subplot(1, 3, 1)
        rows = ("tip",) if depth.shape[0] == 1 else ("leading edge", "trailing edge")
        for r, name in enumerate(rows):
            ax.plot(th, depth[r], lw=1, label=name)
        if depth.shape[0] > 1:
            ax.plot(th, depth.mean(axis=0), "k", lw=1.4, label="mean over the chord")
        ax.set_xlabel("angle on the casing θ [deg]")
        ax.set_ylabel("worn depth [µm]")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 90))
        ax.set_title("final profile, unrolled", fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
        pax = fig.add_subplot(1, 3, 2, projection="polar")
        mean = depth.mean(axis=0)
        # radial scale: depth measured inwards from the unworn circle, which sits at 3 x the deepest wear (the
        # casing's radius is not to scale: the wear magnified to be seen); the ticks read the depth in µm
        r0 = max(float(mean.max()), 1e-9) * 3.0
        pax.plot(np.radians(np.append(th, th[0])), r0 - np.append(mean, mean[0]), "k", lw=1.2, label="worn surface")
        pax.plot(np.linspace(0, 2 * np.pi, 361), np.full(361, r0), ":", color="0.5", lw=1, label="unworn surface")
        pax.set_ylim(0, r0 * 1.05)
        ticks = np.array([0.0, 0.5, 1.0]) * float(mean.max())
        pax.set_yticks(r0 - ticks)
        pax.set_yticklabels([f"{d:.3g} µm" for d in ticks], fontsize=6.5, color="0.35")
        pax.set_rlabel_position(100)
        pax.set_title("final profile, polar (mean over the chord): depth inwards from the unworn circle,\n"
                      "radial scale in µm of wear, not the casing's radius (magnified)", fontsize=8)
        pax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.15))
        bax = fig.add_subplot(1, 3, 3)
        s = w["summary"]
        lobes, why = lobe_verdict(s)
        mean_um = s["depth_mean"] * 1e6
        amps = np.array([s[f"harmonic_{h}"] * 1e6 for h in range(1, 9)])
        if mean_um > 0:  # relative to the mean depth on a log axis: the rule's 5 % line and bars 100 x below it
            rel = 100.0 * amps / mean_um
            bax.bar(range(1, 9), np.maximum(rel, 1e-6), color=["C3" if h == lobes else "C0" for h in range(1, 9)])
            bax.set_yscale("log")
            bax.axhline(100 * LOBE_UNIFORM, color="k", ls="--", lw=0.9,
                        label=f"{LOBE_UNIFORM:.0%} of the mean depth: all below = worn evenly")
            bax.set_ylim(max(min(rel.min(), 100 * LOBE_UNIFORM) / 3, 1e-4), max(rel.max(), 100 * LOBE_UNIFORM) * 3)
            bax.legend(fontsize=7, loc="upper right")
            bax.set_ylabel("amplitude / mean depth [%] (log)")
        else:
            bax.bar(range(1, 9), amps)
            bax.set_ylabel("amplitude [µm]")
        bax.set_xlabel("harmonic of the profile (lobes) [-]")
        bax.set_xticks(range(1, 9))
        bax.set_title(f"spectrum (mean depth {mean_um:.3g} µm, largest harmonic {amps.max():.3g} µm):\n"
                      f"{_wrap(why, 60)}", fontsize=8)
        bax.grid(alpha=0.3, axis="y")
        fig.suptitle(self._title(), fontsize=10)
        fig.tight_layout()
        return fig

    def _figure_forces(self):
        plt = pyplot()
        tr = self.transient
        fig, ax = plt.subplots(figsize=(9, 3.8))
        plot_blade_forces(ax, tr.t, tr.outputs["F_N"])
        ax.axhline(self.liner["yield_force_N"], color="k", ls="--", lw=1, label="liner yield force F_y")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("normal contact force F_N [N]")
        ax.set_title(f"contact forces against the liner: {self._title()}", fontsize=9)
        ax.grid(alpha=0.3)
        legend_outside(ax)
        return fig

    def save(self, out: str | Path) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        for kind in self.FIGURES:
            save_figure(self.figure(kind), out / f"{kind}.png")
        s = self.summary()
        write_json(out / "wear.json", s)
        w = self.wear
        np.savez_compressed(out / "wear.npz", t=w["t"], angles=w["angles"], profiles=w["profiles"], depth=w["depth"],
                            t_outputs=self.transient.t, F_N=self.transient.outputs["F_N"])
        return s


def run_wear(model: Model, formulation: str, speed: float, g0: float, t_end: float = 20.0, t_ramp: float = 1.0,
             closure: float = 0.0, offset: tuple[float, float] = (0.0, 0.0), wear_record_dt: float = 0.05,
             progress: bool = False, **liner_overrides) -> WearResult:
    """A transient at normalised ``speed`` and clearance ``g0`` [m] against the parameter file's liner (worn),
    with the engine's ``closure`` [m] and casing ``offset`` (x, y) [m]; ``liner_overrides``: yield_force,
    hardening, thickness, n_sectors."""
    smax = model.params.normalisation.speed_max
    if not (math.isfinite(speed) and 0 <= speed <= smax):
        raise ParameterError(f"speed: {speed!r} out of range; accepted range [0, {smax:g}] (normalised)")
    c = make_contact(model, formulation, g0=g0)
    liner = Liner.for_model(model, c, wears=True, closure=closure, offset=tuple(offset), **liner_overrides)
    tr = run_transient(model, c, speed * model.params.normalisation.omega_ref, t_end=t_end, t_ramp=t_ramp,
                       liner=liner, wear_record_dt=wear_record_dt, progress=progress)
    params = {"yield_force_N": liner.yield_force, "hardening_N_per_m": liner.hardening,
              "thickness_mm": liner.thickness * 1e3, "n_sectors": liner.n_sectors,
              "cell_area_mm2": liner.cell_area * 1e6}
    return WearResult(formulation, float(speed), float(g0), float(closure), tuple(map(float, offset)), params, tr)


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


__all__ = ["LOBE_DOMINANCE", "LOBE_UNIFORM", "WearResult", "lobe_verdict", "run_wear"]
