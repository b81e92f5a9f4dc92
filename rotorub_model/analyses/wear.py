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
            "lobes": w["lobes"], "harmonics_mm": [w[f"harmonic_{h}"] * 1e3 for h in range(1, 9)],
            "clearance_before_mm": (self.g0 - self.closure) * 1e3,
            "clearance_effective_mm": w["clearance_effective"] * 1e3,
        }

    def plot(self, out: str | Path) -> list[Path]:
        out = Path(out)
        return [self._plot_map(out / "wear_map.png"), self._plot_profile(out / "wear_profile.png"),
                self._plot_forces(out / "forces.png")]

    def _title(self) -> str:
        return (f"{self.formulation}, Ω = {self.speed:.3g} Ω_ref, g0 = {self.g0 * 1e3:.3g} mm, "
                f"F_y = {self.liner['yield_force_N']:g} N")

    def _plot_map(self, path: Path) -> Path:
        plt = pyplot()
        w = self.wear
        fig, ax = plt.subplots(figsize=(9, 4.5))
        prof = w["profiles"] * 1e6
        if prof.size:
            t = w["t"]
            im = ax.imshow(prof, aspect="auto", origin="lower", cmap="magma_r", interpolation="nearest",
                           extent=(0.0, 360.0, float(t[0] - 0.5 * (t[1] - t[0]) if len(t) > 1 else 0.0),
                                   float(t[-1])), vmin=0.0, vmax=max(float(prof.max()), 1e-9))
            fig.colorbar(im, ax=ax, label="worn depth [µm] (mean over the chord)")
        else:
            ax.text(0.5, 0.5, "no record: the run was shorter than one wear record", transform=ax.transAxes,
                    ha="center")
        ax.set_xlabel("angle on the casing θ [deg] (fixed frame)")
        ax.set_ylabel("time [s]")
        ax.set_xticks(range(0, 361, 45))
        ax.set_title(f"wear map: {self._title()}", fontsize=9)
        return save_figure(fig, path)

    def _plot_profile(self, path: Path) -> Path:
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
        r0 = max(float(mean.max()), 1e-9) * 3.0  # the unworn surface drawn at 3x the deepest wear
        pax.plot(np.radians(np.append(th, th[0])), r0 - np.append(mean, mean[0]), "k", lw=1.2, label="worn surface")
        pax.plot(np.linspace(0, 2 * np.pi, 361), np.full(361, r0), ":", color="0.5", lw=1, label="unworn surface")
        pax.set_ylim(0, r0 * 1.05)
        pax.set_yticklabels([])
        pax.set_title("final profile, polar (wear drawn inwards, magnified)", fontsize=9)
        pax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.15))
        bax = fig.add_subplot(1, 3, 3)
        s = w["summary"]
        amps = [s[f"harmonic_{h}"] * 1e6 for h in range(1, 9)]
        bars = bax.bar(range(1, 9), amps, color=["C3" if h == s["lobes"] else "C0" for h in range(1, 9)])
        bax.set_xlabel("harmonic of the profile (lobes) [-]")
        bax.set_ylabel("amplitude [µm]")
        bax.set_xticks(range(1, 9))
        lead = f"{s['lobes']} lobes dominate" if s["lobes"] else "no lobe dominates (no wear, or worn evenly)"
        bax.set_title(f"spectrum: {lead}; mean depth {s['depth_mean'] * 1e6:.3g} µm", fontsize=9)
        bax.grid(alpha=0.3, axis="y")
        del bars
        fig.suptitle(self._title(), fontsize=10)
        return save_figure(fig, path)

    def _plot_forces(self, path: Path) -> Path:
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
        return save_figure(fig, path)

    def save(self, out: str | Path) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        self.plot(out)
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


__all__ = ["WearResult", "run_wear"]
