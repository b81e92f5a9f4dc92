"""Contact detection maps over (Omega, g0) (paper section 4).

The linear imbalance response q(Omega) of eq. (9) (no contact) is put into the gap
functions of each contact formulation. A point (Omega, g0) of the map is "in
contact" when at least one blade has a negative gap there (3D: at its leading or
trailing edge). Every gap is affine in the nominal clearance,

    gap_p(Omega, g0) = g0 + G_p q(Omega)            (p: blade tip, or LE / TE)

(the rows G_p of :class:`rotorub_model.contact.ContactModel` do not depend on g0),
so the contact set at one speed is exactly {g0 < c(Omega)} with the clearance
closure

    c(Omega) = max_p ( -G_p q(Omega) ),

the upper contour of the map. The closures are computed exactly from this; the
boolean (Omega, g0) map is ``g0[None, :] < c[:, None]`` (400 x 400 costs well under
a millisecond once q(Omega) is known, see benchmarks/bench_detection.py).

Studies (one figure each): 2D vs full 3D; the degraded 3D variants vs 2D (the
paper's Fig. 7: closure differences against speed); a sweep of the cone angle
theta and one of the chord l_c (3D full, the other parameter at its default).

An imported blade (``[fe_blade]``, docs/THEORY.md 9) is mapped with its own tip: the 3D closures come
from its chord stations (contact/fe_tip.py). The degraded variants and the chord sweep are the paper's
study of its beam blade (a chord and kinematics the beam's parameters set, which an FE blade has in its
mesh): they are left out, and the summary says so (``skipped``). The cone-angle sweep stays, as another study
than the paper's: casings of other cones facing the same tip, ground to one (the paper cuts its tip to each
cone), so its closures need not grow with theta (paper fact 4 is not checked on an imported blade).

Speed grid: a uniform grid plus the critical speeds of the imbalance response
(:func:`rotorub_model.analyses.linear.run_response`, refined peaks) inserted exactly, plus a
dense cluster of +-2 % around each critical, because the peaks are sharp (mode 1 is
damped at about 1 %).

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> r = run_detection(build_model(), n_speeds=100, n_g0=50, progress=False)
>>> r.map("2D").shape[1]
50
>>> bool(np.all(r.closures["3D"] >= r.closures["2D"]))
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..contact import ContactModel, make_contact
from ..errors import ParameterError
from ..plotting import pyplot, save_figure
from ..structure.model import Model
from ..writing import write_json
from .linear import _check_speed_range, run_response

THETAS_DEG = (0.0, 5.0, 10.0, 20.0, 30.0)
CHORDS_M = (0.01, 0.05, 0.10, 0.20, 0.30)
CLUSTER_HALF_WIDTH = 0.02  # relative half-width of the dense grid around each critical speed
CLUSTER_POINTS = 81
VARIANT_LABELS = {"kinematics_only": "3D kinematics only", "geometry_only": "3D geometry only"}


# ----------------------------------------------------------------------------- core


def linear_responses(model: Model, omegas: np.ndarray, me: float | None = None) -> np.ndarray:
    """q(Omega) of eq. (9) for every Omega [rad/s]: (n_speeds, n_dofs), one batched solve.

    Same numbers as :func:`rotorub_model.analyses.linear.linear_response` at each speed.
    """
    w = np.asarray(omegas, dtype=float)
    K = model.K[None] + (w * w)[:, None, None] * (model.S2 + model.N2)[None] + w[:, None, None] * model.C1[None]
    if model.S4 is not None:  # an imported blade's prestress beyond the quadratic
        K = K + ((w * w) ** 2)[:, None, None] * model.S4[None]
    me = model.params.imbalance.me if me is None else me
    F = (me * w * w)[:, None] * model.f_unit[None]
    return np.linalg.solve(K, F[..., None])[..., 0]


def closure(contact: ContactModel, Q: np.ndarray) -> np.ndarray:
    """Clearance closure c(Omega) = max over contact points of -(G q(Omega)) [m], for the
    responses Q (n_speeds, n_dofs): contact at (Omega, g0) iff g0 < c(Omega)."""
    gaps = contact.with_clearance(0.0).gaps_batch(Q)  # the kernel's gaps, g0 = 0
    return np.max(-gaps.reshape(gaps.shape[0], -1), axis=1)


def contact_map(closures: np.ndarray, g0: np.ndarray) -> np.ndarray:
    """Boolean (n_speeds, n_g0) map: True where at least one blade (point) has a negative gap."""
    return np.asarray(g0)[None, :] < np.asarray(closures)[:, None]


def detection_area(speeds: np.ndarray, closures: np.ndarray) -> float:
    """Area of the map above g0 = 0 in the (normalised speed, g0 [mm]) plane."""
    c = np.clip(closures, 0.0, None) * 1e3
    return float(np.sum(0.5 * (c[1:] + c[:-1]) * np.diff(speeds)))


def speed_grid(
    critical_speeds: list[float], speed_min: float = 0.05, speed_max: float = 10.0, n_speeds: int = 400
) -> np.ndarray:
    """Uniform grid + the critical speeds exactly + a dense cluster (+-2 %) around each."""
    _check_speed_range(speed_min, speed_max, n_speeds)
    parts = [np.linspace(speed_min, speed_max, n_speeds)]
    for c in critical_speeds:
        parts.append(np.array([c]))
        parts.append(c * (1.0 + np.linspace(-CLUSTER_HALF_WIDTH, CLUSTER_HALF_WIDTH, CLUSTER_POINTS)))
    s = np.unique(np.concatenate(parts))
    return s[(s >= speed_min) & (s <= speed_max)]


def _local_spacing(speeds: np.ndarray, s: float) -> float:
    i = int(np.argmin(np.abs(speeds - s)))
    gaps = [speeds[i] - speeds[i - 1]] if i > 0 else []
    if i < speeds.size - 1:
        gaps.append(speeds[i + 1] - speeds[i])
    return float(max(gaps))


# ----------------------------------------------------------------------------- result


@dataclass
class DetectionResult:
    """Clearance closures of every studied formulation on one speed grid.

    ``closures`` maps a label to c(Omega) [m] on ``speeds`` (normalised): '2D', '3D',
    '3D kinematics only', '3D geometry only', 'theta=<deg>', 'chord=<cm>'.
    """

    speeds: np.ndarray  # normalised
    omega_ref: float
    critical_speeds: list[float]  # normalised (linear.run_response, refined)
    base_spacing: float  # spacing of the uniform part of the grid (normalised)
    g0: np.ndarray  # clearance grid of the boolean maps [m]
    closures: dict[str, np.ndarray]
    thetas_deg: tuple[float, ...]
    chords_m: tuple[float, ...]
    defaults: dict[str, float] = field(default_factory=dict)  # theta_deg, chord of the 3D full
    skipped: dict[str, str] = field(default_factory=dict)  # study -> why it was not run (an imported blade)

    def map(self, label: str) -> np.ndarray:
        """Boolean map (n_speeds, n_g0): contact at (speeds[i], g0[j])."""
        if label not in self.closures:
            raise ParameterError(f"label: '{label}' unknown; accepted: {', '.join(self.closures)}")
        return contact_map(self.closures[label], self.g0)

    def theta_label(self, th: float) -> str:
        return f"theta={th:g}"

    def chord_label(self, ch: float) -> str:
        return f"chord={ch * 100:g}"

    def _at(self, label: str, s: float) -> float:
        return float(self.closures[label][int(np.argmin(np.abs(self.speeds - s)))])

    def _sweep(self, labels: list[str]) -> dict:
        maxes = [float(np.max(self.closures[k])) * 1e3 for k in labels]
        areas = [detection_area(self.speeds, self.closures[k]) for k in labels]
        nested = [bool(np.all(self.closures[b] >= self.closures[a])) for a, b in zip(labels, labels[1:])]
        worst = [float(np.min(self.closures[b] - self.closures[a])) * 1e3 for a, b in zip(labels, labels[1:])]
        return {
            "max": maxes,
            "area": areas,
            "range_mm": max(maxes) - min(maxes),
            "max_monotone": bool(np.all(np.diff(maxes) >= 0)),
            "area_monotone": bool(np.all(np.diff(areas) >= 0)),
            "nested_every_speed": bool(all(nested)),
            "min_step_diff_mm": worst,
        }

    def summary(self) -> dict:
        c2, c3 = self.closures["2D"], self.closures["3D"]
        crit1 = self.critical_speeds[0] if self.critical_speeds else None
        i2, i3 = int(np.argmax(c2)), int(np.argmax(c3))
        diff = c3 - c2
        variants = {
            v: float(np.max(np.abs(self.closures[lab] - c2))) * 1e3 if lab in self.closures else None
            for v, lab in VARIANT_LABELS.items()
        }
        th = self._sweep([self.theta_label(t) for t in self.thetas_deg])
        ch = self._sweep([self.chord_label(c) for c in self.chords_m]) if self.chords_m else None
        formulations = [k for k in ("2D", "3D", *VARIANT_LABELS.values()) if k in self.closures]
        g0zero = {k: bool(np.all(self.closures[k] > 0.0)) for k in formulations}
        s: dict = {
            "closure_2d_max_mm": float(c2[i2]) * 1e3,
            "closure_3d_max_mm": float(c3[i3]) * 1e3,
            "speed_of_max_closure": {"2D": float(self.speeds[i2]), "3D": float(self.speeds[i3])},
            "speed_of_max_closure_note": "normalised; argmax of the closure on the speed grid",
            "first_critical_speed": crit1,
            "critical_speeds": list(self.critical_speeds),
            "grid_spacing_at_first_critical": _local_spacing(self.speeds, crit1) if crit1 else None,
            "base_grid_spacing": self.base_spacing,
            "speed_of_max_closure_offset_from_first_critical": (
                {"2D": float(self.speeds[i2] - crit1), "3D": float(self.speeds[i3] - crit1)} if crit1 else None
            ),
            "closure_2d_at_first_critical_mm": self._at("2D", crit1) * 1e3 if crit1 else None,
            "closure_3d_at_first_critical_mm": self._at("3D", crit1) * 1e3 if crit1 else None,
            "closure_diff_3d_2d_at_first_critical_mm": (
                (self._at("3D", crit1) - self._at("2D", crit1)) * 1e3 if crit1 else None
            ),
            "closure_diff_3d_2d_max_mm": float(np.max(diff)) * 1e3,
            "closure_diff_3d_2d_min_mm": float(np.min(diff)) * 1e3,
            "map_3d_contains_2d": bool(np.all(diff >= 0.0)),
            "closure_diff_kinematics_only_mm": variants["kinematics_only"],
            "closure_diff_geometry_only_mm": variants["geometry_only"],
            "closure_diff_full_3d_mm": float(np.max(np.abs(diff))) * 1e3,
            "closure_diff_definition": "max over the speed grid of |closure_variant - closure_2D| [mm]",
            "theta_sweep": {f"{t:g}": m for t, m in zip(self.thetas_deg, th["max"])},
            "chord_sweep": {f"{c * 100:g}": m for c, m in zip(self.chords_m, ch["max"])} if ch else None,
            "sweep_note": (
                "theta_sweep: {theta_deg: max closure mm} at the default chord; chord_sweep: {chord_cm: max "
                "closure mm} at the default theta; area = map area above g0 = 0 in (normalised speed x mm); "
                "nested_every_speed: each step's closure >= the previous one's at every speed"
            ),
            "theta_sweep_detail": {**th, "theta_deg": list(self.thetas_deg)},
            "chord_sweep_detail": {**ch, "chord_cm": [c * 100 for c in self.chords_m]} if ch else None,
            "theta_sweep_range_mm": th["range_mm"],
            "chord_sweep_range_mm": ch["range_mm"] if ch else None,
            "detection_area": {k: detection_area(self.speeds, self.closures[k]) for k in formulations},
            "contact_at_every_speed_at_g0_zero": bool(g0zero["2D"] and g0zero["3D"]),
            "contact_at_every_speed_at_g0_zero_by_formulation": g0zero,
            "defaults_3d": self.defaults,
            "omega_ref_rad_s": self.omega_ref,
            "n_speeds": int(self.speeds.size),
            "speed_range": [float(self.speeds[0]), float(self.speeds[-1])],
            "n_g0": int(self.g0.size),
            "g0_range_mm": [float(self.g0[0]) * 1e3, float(self.g0[-1]) * 1e3],
            "skipped": dict(self.skipped),
        }
        return s

    @property
    def studies(self) -> tuple[str, ...]:
        """The figures this result has: '2d_3d', 'variants', 'theta', 'chord' less what was skipped."""
        return tuple(k for k in ("2d_3d", "variants", "theta", "chord") if k not in self.skipped)

    # ------------------------------------------------------------------ figures
    # Fills come from the closures (the contact set at a speed is exactly g0 < c(Omega)), not from the
    # boolean grid, so a thin band is drawn as thin as it is. The 3D set contains the 2D one: drawn
    # opaque on top, 2D vanishes; under it, 3D did (the figure before this). So 2D is the flat fill
    # at the bottom and 3D a hatch over it: where both detect, the orange shows through the hatch.
    COLOURS = {"2D": "#f4a261", "2D line": "#b3541e", "3D": "#1d3f8a"}
    Z_2D, Z_3D = 1.0, 2.0  # fill z-orders; each formulation's closure line just above its own fill

    def _zoom(self) -> tuple[float, float]:
        """Speed window around the first critical where the closures separate (its peak is ~1 % wide)."""
        c = self.critical_speeds[0] if self.critical_speeds else float(self.speeds[np.argmax(self.closures["3D"])])
        return max(c * 0.94, float(self.speeds[0])), min(c * 1.06, float(self.speeds[-1]))

    def _crit_lines(self, ax) -> None:
        for c in self.critical_speeds:
            ax.axvline(c, color="0.3", ls=":", lw=0.8, zorder=0.5)

    def _speed_axis(self, ax, window: tuple[float, float] | None = None) -> None:
        ax.set_xlim(*(window or (self.speeds[0], self.speeds[-1])))
        ax.set_xlabel("normalised spin speed Ω / Ω_ref [-]")
        ax.grid(alpha=0.3, which="both")

    def _draw_2d_3d(self, ax, window: tuple[float, float] | None = None) -> None:
        s, c2, c3 = self.speeds, self.closures["2D"] * 1e3, self.closures["3D"] * 1e3
        ax.fill_between(s, 0.0, c2, facecolor=self.COLOURS["2D"], edgecolor="none", zorder=self.Z_2D,
                        label="2D contact area", gid="2D")
        ax.fill_between(s, 0.0, c3, facecolor="none", edgecolor=self.COLOURS["3D"], hatch="////", lw=0.0,
                        zorder=self.Z_3D, label="3D contact area (hatched, over 2D)", gid="3D")
        ax.plot(s, c2, color=self.COLOURS["2D line"], lw=1.0, zorder=self.Z_2D + 0.5, label="2D closure", gid="2D")
        ax.plot(s, c3, color=self.COLOURS["3D"], lw=1.2, zorder=self.Z_3D + 0.5, label="3D closure", gid="3D")
        self._crit_lines(ax)
        lo, hi = window or (s[0], s[-1])
        sel = (s >= lo) & (s <= hi)
        ax.set_ylim(0.0, 1.08 * float(np.max(c3[sel])))
        ax.set_ylabel("nominal clearance g0 [mm]")
        self._speed_axis(ax, window)

    def _draw_sweep(self, axes, study: str) -> None:
        """(a) the closures near the first critical; (b) their excess over the 2D closure, whole range."""
        plt = pyplot()
        if study == "theta":
            values, labels = self.thetas_deg, [self.theta_label(t) for t in self.thetas_deg]
            names = [f"θ = {t:g}°" for t in values]
        else:
            values, labels = self.chords_m, [self.chord_label(c) for c in self.chords_m]
            names = [f"l_c = {c * 100:g} cm" for c in values]
        # five nested curves: an ordered palette for the order, a line style and a marker each so that
        # they stay apart where they run close (and in grey print); markers evenly spaced along the drawn
        # line (markevery as a fraction), the speed grid being dense at the criticals
        colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.85, len(labels)))
        styles = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1))]
        markers = ["o", "s", "^", "D", "v"]
        window = self._zoom()
        s = self.speeds
        sel = (s >= window[0]) & (s <= window[1])
        c2 = self.closures["2D"]
        for k, (lab, name) in enumerate(zip(labels, names)):
            kw = {"color": colours[k], "ls": styles[k % len(styles)], "lw": 1.4, "marker": markers[k % len(markers)],
                  "ms": 4.5, "label": f"{name} (max {np.max(self.closures[lab]) * 1e3:.2f} mm)"}
            axes[0].plot(s[sel], self.closures[lab][sel] * 1e3, markevery=0.1, **kw)
            kw.pop("label")
            axes[1].plot(s, (self.closures[lab] - c2) * 1e3, markevery=0.08, **kw)
        axes[0].plot(s[sel], c2[sel] * 1e3, color="k", ls="--", lw=1.0, label=f"2D (max {np.max(c2) * 1e3:.2f} mm)")
        axes[0].set_ylabel("clearance closure c(Ω) [mm]")
        axes[0].set_title("closures around the first critical speed")
        axes[1].set_yscale("symlog", linthresh=1e-3)
        axes[1].set_ylabel("closure − 2D closure [mm]")
        axes[1].set_title("3D excess over 2D, whole speed range")
        self._speed_axis(axes[0], window)
        self._speed_axis(axes[1])
        for ax in axes:
            self._crit_lines(ax)

    def figure(self, study: str = "2d_3d"):
        """The figure of one study: '2d_3d', 'variants', 'theta', 'chord' (open: the caller saves or closes it)."""
        plt = pyplot()
        if study in self.skipped:
            raise ParameterError(f"study: '{study}' was not run ({self.skipped[study]}); accepted: "
                                 f"{', '.join(self.studies)}")
        if study == "2d_3d":
            fig, axes = plt.subplots(1, 2, figsize=(11, 4.3), gridspec_kw={"width_ratios": [1.6, 1]})
            self._draw_2d_3d(axes[0])
            self._draw_2d_3d(axes[1], self._zoom())
            axes[0].set_title("Contact detection over the speed range")
            axes[1].set_title("zoom on the first critical speed")
            h, lab = axes[0].get_legend_handles_labels()
            fig.legend(h, lab, loc="lower center", ncol=4, fontsize=8.5, frameon=False)
            fig.tight_layout(rect=(0, 0.08, 1, 1))
        elif study == "variants":
            fig = plt.figure(figsize=(11, 8.2), layout="constrained")
            grid = fig.add_gridspec(2, 2, width_ratios=[1.6, 1])
            ax = fig.add_subplot(grid[0, :])
            self._draw_2d_3d(ax)
            var = (("3D geometry only", "C2", "--"), ("3D kinematics only", "C4", "-."))
            for lab, col, ls in var:
                ax.plot(self.speeds, self.closures[lab] * 1e3, color=col, ls=ls, lw=1.0, zorder=5,
                        label=f"{lab} closure")
            ax.set_xlabel("")
            ax.set_title("Detection: full 3D over 2D, the degraded 3D closures (≈ 2D)")
            ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
            # |closure - 2D closure| on a log axis (fact 3 is about its largest value, < 0.1 mm): the whole range
            # and a zoom on the first critical, where the degraded closures swing; each curve's largest value marked
            c2 = self.closures["2D"]
            floor = 1e-6  # [mm] where a difference below the plot's resolution is drawn
            window = self._zoom()
            for k, bx in enumerate((fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1]))):
                sel = slice(None) if k == 0 else (self.speeds >= window[0]) & (self.speeds <= window[1])
                for lab, col, ls in (("3D", self.COLOURS["3D"], "-"), *var):
                    d = np.abs(self.closures[lab] - c2) * 1e3
                    i = int(np.argmax(d))
                    bx.plot(self.speeds[sel], np.maximum(d[sel], floor), color=col, ls=ls, lw=1.0,
                            label=f"|{lab} − 2D| (largest {d[i]:.3g} mm at Ω = {self.speeds[i]:.3g})" if k == 0
                            else None)
                    bx.plot(self.speeds[i], d[i], "o", color=col, ms=6, mfc="none", mew=1.5)
                bx.axhline(0.1, color="k", ls=":", lw=1.0, label="0.1 mm: fact 3's bound on the degraded 3D" if k == 0
                           else None)
                self._crit_lines(bx)
                bx.set_yscale("log")
                bx.set_ylim(bottom=floor)
                bx.set_ylabel("|closure − 2D closure| [mm]")
                self._speed_axis(bx, None if k == 0 else window)
            fig.axes[1].set_title("difference with the 2D closure (cf. paper Fig. 7); ○ largest", fontsize=10)
            fig.axes[2].set_title("zoom on the first critical speed", fontsize=10)
            fig.legend(*fig.axes[1].get_legend_handles_labels(), loc="outside lower center", ncol=2, fontsize=8,
                       frameon=False)
        elif study in ("theta", "chord"):
            fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
            self._draw_sweep(axes, study)
            what = (f"cone angle θ (chord {self.defaults.get('chord', 0) * 100:.3g} cm)" if study == "theta"
                    else f"chord l_c (θ = {self.defaults.get('theta_deg', 0):g}°)")
            if self.skipped and study == "theta":  # an imported tip: ground to one cone, facing the others
                what = (f"casing's cone angle θ, facing the imported tip as ground (its chord "
                        f"{self.defaults.get('chord', 0) * 100:.3g} cm)")
            fig.suptitle(f"3D detection, sweep of the {what}")
            h, lab = axes[0].get_legend_handles_labels()
            fig.legend(h, lab, loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=8.5, frameon=False)
            fig.tight_layout()
        else:
            raise ParameterError(f"study: '{study}' unknown; accepted: 2d_3d, variants, theta, chord")
        return fig

    def save(self, out: str | Path) -> dict:
        """Write detection_{2d_3d,variants,theta,chord}.png (those run), summary.json, detection.npz into ``out``."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        for study in self.studies:
            save_figure(self.figure(study), out / f"detection_{study}.png", layout=False)
        np.savez(
            out / "detection.npz",
            speeds=self.speeds,
            g0=self.g0,
            labels=np.array(list(self.closures)),
            closures=np.array(list(self.closures.values())),
            map_2d=self.map("2D"),
            map_3d=self.map("3D"),
        )
        s = self.summary()
        write_json(out / "summary.json", s)
        return s


# ----------------------------------------------------------------------------- driver


IMPORTED_SKIPS = {
    "variants": "the degraded 3D variants are the paper's study of its beam blade (theta = 0 with a 1 mm chord, or "
                "no rotation and no blade flexure); an imported blade has its chord and kinematics in its mesh",
    "chord": "the chord sweep varies the beam blade's contact chord; an imported blade's chord is its tip's own",
}


def _configurations(model: Model, thetas: tuple[float, ...], chords: tuple[float, ...]) -> list[tuple[str, dict]]:
    confs: list[tuple[str, dict]] = [
        ("2D", {"formulation": "2D"}),
        ("3D", {"formulation": "3D"}),
    ]
    if model.fe_blade is None:
        confs += [(lab, {"formulation": "3D", "variant": v}) for v, lab in VARIANT_LABELS.items()]
    confs += [(f"theta={t:g}", {"formulation": "3D", "theta_deg": float(t)}) for t in thetas]
    confs += [(f"chord={c * 100:g}", {"formulation": "3D", "chord": float(c)}) for c in chords]
    return confs


def run_detection(
    model: Model,
    speeds: np.ndarray | None = None,
    g0_max: float | None = None,
    n_g0: int = 400,
    speed_min: float = 0.05,
    speed_max: float = 10.0,
    n_speeds: int = 400,
    thetas_deg: tuple[float, ...] | None = None,
    chords: tuple[float, ...] | None = None,
    progress: bool = True,
) -> DetectionResult:
    """Detection study (all four): closures of 2D, 3D full, the degraded 3D variants and
    the theta / chord sweeps on one speed grid.

    ``speeds``: normalised speed grid (default: :func:`speed_grid` on
    [speed_min, speed_max] with n_speeds uniform points); the critical speeds of the
    imbalance response found in its range are always inserted exactly.
    ``g0_max`` [m]: top of the clearance grid of the boolean maps (default: 1.05 x the
    largest closure of all studies); the grid is n_g0 points on [0, g0_max].
    ``thetas_deg``, ``chords``: the sweeps (default: the paper's, THETAS_DEG and CHORDS_M, with the configuration's
    own cone angle and chord among them).
    """
    from tqdm import tqdm

    own = model.params.contact
    imported = model.fe_blade is not None
    if thetas_deg is None:
        thetas_deg = tuple(sorted({*THETAS_DEG, float(own.theta_deg)}))
    if chords is None:
        chords = () if imported else tuple(sorted({*CHORDS_M, float(own.chord)}))
    elif imported and chords:
        raise ParameterError(f"chords: {IMPORTED_SKIPS['chord']}; accepted with an imported blade: none")

    if model.params.imbalance.me == 0.0:
        raise ParameterError("imbalance.me: 0 kg m; the detection maps put the imbalance response into the gaps "
                             "(accepted range (0, inf) kg m): without an imbalance every closure is 0")
    if isinstance(n_g0, bool) or not isinstance(n_g0, int | np.integer) or not 2 <= n_g0 <= 100_000:
        raise ParameterError(f"n_g0: {n_g0!r} out of range; accepted: integers in [2, 100000]")
    if g0_max is not None and not (np.isfinite(g0_max) and g0_max > 0):
        raise ParameterError(f"g0_max: {g0_max!r} out of range; accepted range (0, inf) [m]")
    for t in thetas_deg:
        if not (np.isfinite(t) and 0 <= t <= 60):
            raise ParameterError(f"thetas_deg: {t!r} out of range; accepted range [0, 60] deg")
    for c in chords:
        if not (np.isfinite(c) and c > 0):
            raise ParameterError(f"chords: {c!r} out of range; accepted range (0, inf) m")
    if speeds is None:
        _check_speed_range(speed_min, speed_max, n_speeds)
        resp = run_response(model, speed_min, speed_max, n_speeds=max(2000, n_speeds))
        grid = speed_grid(resp.critical_speeds, speed_min, speed_max, n_speeds)
        base = (speed_max - speed_min) / (n_speeds - 1)
    else:
        s = np.asarray(speeds, dtype=float).ravel()
        if s.size < 2 or not np.all(np.isfinite(s)) or np.any(s <= 0):
            raise ParameterError("speeds: need at least 2 finite positive normalised speeds")
        s = np.unique(s)
        resp = run_response(model, float(s[0]), float(s[-1]), n_speeds=max(2000, s.size))
        grid = np.unique(np.concatenate([s, resp.critical_speeds]))
        base = float(np.max(np.diff(s)))
    wref = model.params.normalisation.omega_ref
    Q = linear_responses(model, grid * wref)
    closures: dict[str, np.ndarray] = {}
    confs = _configurations(model, tuple(thetas_deg), tuple(chords))
    for label, kw in tqdm(confs, desc="detection", unit="map", disable=not progress, delay=1.0):
        kw = dict(kw)
        form = kw.pop("formulation")
        variant = kw.pop("variant", "full")
        closures[label] = closure(make_contact(model, form, variant, **kw), Q)
    top = g0_max if g0_max is not None else 1.05 * max(float(np.max(c)) for c in closures.values())
    c = model.params.contact
    return DetectionResult(
        speeds=grid,
        omega_ref=wref,
        critical_speeds=[float(x) for x in resp.critical_speeds],
        base_spacing=float(base),
        g0=np.linspace(0.0, top, n_g0),
        closures=closures,
        thetas_deg=tuple(float(t) for t in thetas_deg),
        chords_m=tuple(float(x) for x in chords),
        defaults={"theta_deg": c.theta_deg, "chord": c.chord if not imported else
                  float(make_contact(model, "3D").geometry.chord)},
        skipped=dict(IMPORTED_SKIPS) if imported else {},
    )


# ----------------------------------------------------------------------------- paper facts 2-4


def paper_facts(s: dict) -> list[dict]:
    """Facts 2, 3, 4 of MODEL-NOTES section 4 checked on a detection summary, each with its named conditions
    (:mod:`rotorub_model.facts`)."""
    from ..facts import ROTOR, condition, with_conditions

    crit = s["first_critical_speed"]
    tol = s["base_grid_spacing"]
    off = s["speed_of_max_closure_offset_from_first_critical"] or {"2D": np.inf, "3D": np.inf}
    d13 = s["closure_diff_3d_2d_at_first_critical_mm"]
    at = s["speed_of_max_closure"]
    f2 = with_conditions({
        "id": 2,
        "statement": "detection maps: contact at g0 = 0 at every speed; largest closure near the first critical "
        "(3.5) for 2D and 3D; the 3D map contains the 2D map; 3D - 2D ~ 1.3 mm at the first critical",
        "paper": {"speed_of_max_closure": 3.5, "closure_diff_3d_2d_mm": 1.3},
        "ours": {
            "contact_at_every_speed_at_g0_zero": s["contact_at_every_speed_at_g0_zero"],
            "speed_of_max_closure": s["speed_of_max_closure"],
            "first_critical_speed": crit,
            "map_3d_contains_2d": s["map_3d_contains_2d"],
            "closure_diff_3d_2d_at_first_critical_mm": d13,
            "closure_2d_max_mm": s["closure_2d_max_mm"],
            "closure_3d_max_mm": s["closure_3d_max_mm"],
        },
        "tolerance": {"speed": f"within the uniform grid spacing {tol:.3g}", "closure_diff_mm": 0.4},
    }, [
        condition("contact at g0 = 0 at every speed", s["contact_at_every_speed_at_g0_zero"],
                  "yes" if s["contact_at_every_speed_at_g0_zero"] else "no"),
        condition(f"the largest 2D closure at the first critical (within the grid spacing {tol:.3g})",
                  abs(off["2D"]) <= tol,
                  f"at Ω = {at['2D']:.4g}, first critical " + ("none" if crit is None else f"{crit:.4g}")),
        condition(f"the largest 3D closure at the first critical (within {tol:.3g})", abs(off["3D"]) <= tol,
                  f"at Ω = {at['3D']:.4g}"),
        condition("the 3D map contains the 2D map", s["map_3d_contains_2d"], "yes" if s["map_3d_contains_2d"] else
                  f"no (3D - 2D down to {s['closure_diff_3d_2d_min_mm']:.3g} mm)"),
        condition("3D - 2D within 0.4 mm of 1.3 mm at the first critical", d13 is not None and abs(d13 - 1.3) <= 0.4,
                  "–" if d13 is None else f"{d13:.3g} mm", ROTOR),
    ])
    th, ch = s["theta_sweep_detail"], s["chord_sweep_detail"]
    if ch is None:
        # an imported blade: the degraded variants and the chord sweep are not run, and its theta sweep is another
        # study than the paper's (a tip ground to one cone facing casings of other cones, not a tip cut to each):
        # fact 2 only
        return [f2]
    kin, geo = s["closure_diff_kinematics_only_mm"], s["closure_diff_geometry_only_mm"]
    full = s["closure_diff_full_3d_mm"]
    f3 = with_conditions({
        "id": 3,
        "statement": "degraded 3D ('kinematics only': theta = 0, l_c = 1 mm; 'geometry only': no rotation, "
        "no blade flexure) each differ from 2D by < 0.1 mm; only the full 3D gives the ~1.3 mm",
        "paper": {"max_diff_mm": 0.1},
        "ours": {"kinematics_only_mm": kin, "geometry_only_mm": geo, "full_3d_mm": full,
                 "definition": s["closure_diff_definition"]},
    }, [
        condition("'kinematics only' within 0.1 mm of 2D at every speed", kin < 0.1, f"{kin:.3g} mm", ROTOR),
        condition("'geometry only' within 0.1 mm of 2D at every speed", geo < 0.1, f"{geo:.3g} mm", ROTOR),
        condition("the full 3D more than 0.9 mm from 2D somewhere", full > 0.9, f"{full:.3g} mm", ROTOR),
    ])
    f4 = with_conditions({
        "id": 4,
        "statement": "sweeps theta = 0..30 deg and l_c = 1..30 cm both widen the 3D detection area; theta matters "
        "more than l_c",
        "paper": {"defaults": {"theta_deg": 5.0, "chord_m": 0.2}},
        "ours": {
            "defaults": s["defaults_3d"],
            "theta_sweep_max_mm": s["theta_sweep"],
            "chord_sweep_max_mm": s["chord_sweep"],
            "theta_range_mm": th["range_mm"],
            "chord_range_mm": ch["range_mm"],
            "theta_area_monotone": th["area_monotone"],
            "chord_area_monotone": ch["area_monotone"],
            "theta_nested_every_speed": th["nested_every_speed"],
            "chord_nested_every_speed": ch["nested_every_speed"],
        },
    }, [
        condition("the detection area grows with θ", th["area_monotone"], "yes" if th["area_monotone"] else "no"),
        condition("the detection area grows with the chord", ch["area_monotone"],
                  "yes" if ch["area_monotone"] else "no"),
        condition("the largest closure grows with θ", th["max_monotone"], "yes" if th["max_monotone"] else "no"),
        condition("the largest closure grows with the chord", ch["max_monotone"],
                  "yes" if ch["max_monotone"] else "no"),
        condition("θ matters more than the chord (a wider spread of the largest closure)",
                  th["range_mm"] > ch["range_mm"], f"{th['range_mm']:.3g} mm against {ch['range_mm']:.3g} mm", ROTOR),
    ])
    return [f2, f3, f4]
