"""fmpy harnesses: the paper's analyses run through the FMU only, each checked against the library.

* :func:`quasi_static_maps`: speed sweeps at a set of clearances in ``quasi_static`` mode
  (Omega stepped as an input, each step warm-started from the last) giving the contact
  and stability maps of the paper's sections 4-5, for 2D and 3D;
* :func:`transient_pair`: the section 6 transients (imbalance ramped in over 1 s by the
  master) at one point, 2D and 3D, with the normal force histories (paper Fig. 12);
* :func:`run_up`: an acceleration through the first critical speed with Omega(t) as input;
* :func:`compare_flavours`: the section-6 point through two FMU flavours (native, pythonfmu) and the library.

The FMU is driven through :class:`fmu_src.masters.fmi2.Slave`; the library side of every
comparison is the library's own analysis of the same case. A master holds inputs over
each communication step, so the library transients are run with ``hold=h`` (the same
zero-order hold): both sides then do the same arithmetic and differ by round-off.
The quasi-static maps are compared with :func:`rotorub_model.analyses.maps.run_stability_map`,
which solves each cell independently (from the linear response and a few restarts)
instead of continuing along the sweep: where several balanced solutions coexist the
two may land on different ones, and the comparison counts those cells.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rotorub_model.analyses.transient import not_settled_words
from rotorub_model.plotting import pyplot, save_figure
from rotorub_model.writing import write_json

from .fmi2 import Slave

H_TRANSIENT = 1e-3  # communication step of the transient harnesses [s]


def _names(n_blades: int, what: str) -> list[str]:
    return [f"blade[{j}].{what}" for j in range(1, n_blades + 1)]


def _extract(fmu: str | Path, where: str | Path) -> str:
    """The FMU unzipped into ``where``, or the extraction already there if it is of the same file: never
    over an extraction whose binary may be loaded in this process (rewriting a mapped shared library
    crashes it)."""
    import hashlib
    import zipfile

    from fmpy import extract

    where = Path(where).resolve()
    stamp = where / ".rotorub_extracted_from"
    digest = hashlib.sha256(Path(fmu).read_bytes()).hexdigest()
    if stamp.exists() and stamp.read_text() == digest:
        return str(where)
    if where.exists() and any(where.iterdir()):
        where = where.with_name(f"{where.name}_{digest[:8]}")
        if (where / ".rotorub_extracted_from").exists():
            return str(where)
    with zipfile.ZipFile(fmu):
        pass  # a clear error for a file that is not an FMU
    out = extract(str(fmu), str(where))
    (Path(out) / ".rotorub_extracted_from").write_text(digest)
    return out


def _progress(total: int, desc: str, show: bool):
    if not show:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="step")


# ----------------------------------------------------------------------------- quasi-static maps
@dataclass
class QuasiStaticMaps:
    speeds: np.ndarray  # normalised
    g0s: np.ndarray  # m
    n_contact: dict[str, np.ndarray]  # formulation -> (n_speeds, n_g0), -1 = no balanced solution
    max_real: dict[str, np.ndarray]
    comparison: dict = field(default_factory=dict)
    seconds: float = 0.0

    def summary(self) -> dict:
        out = {"seconds": self.seconds, "grid": [len(self.speeds), len(self.g0s)]}
        for f, n in self.n_contact.items():
            touching = n > 0
            unstable = touching & (np.nan_to_num(self.max_real[f], nan=-1) > 1e-6)
            out[f"unstable_cells_over_contact_cells_{f}"] = float(unstable.sum() / max(touching.sum(), 1))
            out[f"max_blades_in_contact_{f}"] = int(n.max())
        out["vs_library"] = self.comparison
        return out

    def figure(self):
        """Blades in contact per cell (one discrete colour scale for both panels); unstable cells hatched cell by
        cell (a contour of the boolean spilled the hatch half a cell into its neighbours, in lines a cell apart);
        cells the FMU found no balanced solution for in grey; the clearance axis ends just above the highest
        contact cell (the grid goes on, without contact, to its top, which the title gives)."""
        from matplotlib.colors import BoundaryNorm, ListedColormap
        from matplotlib.patches import Patch, Rectangle

        plt = pyplot()
        forms = list(self.n_contact)
        fig, axes = plt.subplots(1, len(forms), figsize=(11.5, 4.6), sharey=True, squeeze=False)
        axes = axes[0]
        nmax = max(max(int(n.max()) for n in self.n_contact.values()), 1)
        cmap = ListedColormap(plt.get_cmap("viridis")(np.linspace(0.0, 1.0, nmax)))
        norm = BoundaryNorm(np.arange(0.5, nmax + 1.0), nmax)
        se, ge = _cell_edges(self.speeds), _cell_edges(self.g0s * 1e3)
        for ax, f in zip(axes, forms):
            n = self.n_contact[f]
            pc = ax.pcolormesh(se, ge, np.where(n > 0, n, np.nan).T, cmap=cmap, norm=norm)
            ax.pcolormesh(se, ge, np.where(n < 0, 1.0, np.nan).T, cmap=ListedColormap([NO_SOLUTION_COLOUR]))
            unstable = (n > 0) & (np.nan_to_num(self.max_real[f], nan=-1) > 1e-6)
            with plt.rc_context({"hatch.linewidth": 0.7}):
                for i, j in np.argwhere(unstable):
                    r, g, b, _ = cmap(norm(n[i, j]))
                    ink = "k" if 0.299 * r + 0.587 * g + 0.114 * b > 0.45 else "w"  # visible on dark cells too
                    ax.add_patch(Rectangle((se[i], ge[j]), se[i + 1] - se[i], ge[j + 1] - ge[j], fill=False,
                                           hatch=UNSTABLE_HATCH, edgecolor=ink, lw=0.0))
            ax.set_title(f"{f}: static solutions through the FMU")
            ax.set_xlabel("normalised spin speed Ω / Ω_ref [-]")
            fig.colorbar(pc, ax=ax, label="blades in contact [-]", ticks=range(1, nmax + 1))
        axes[0].set_ylabel("initial clearance g0 [mm]")
        handles = [Patch(facecolor="0.75", edgecolor="k", hatch=UNSTABLE_HATCH, label="unstable (max Re(λ) > 0)"),
                   Patch(facecolor="white", edgecolor="0.6", label="no contact")]
        if any((n < 0).any() for n in self.n_contact.values()):
            handles.append(Patch(facecolor=NO_SOLUTION_COLOUR, label="no balanced solution found (FMU step discarded)"))
        fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8.5, frameon=False)
        top = _contact_top(self.g0s * 1e3, [n != 0 for n in self.n_contact.values()])
        if top is not None and top < ge[-1]:
            axes[0].set_ylim(ge[0], top)
            fig.suptitle(f"clearance axis cut at {top:.3g} mm: no contact above, up to the grid's "
                         f"{self.g0s[-1] * 1e3:.3g} mm", fontsize=8.5)
        fig.tight_layout(rect=(0, 0.07, 1, 1))
        return fig

    def save(self, out: str | Path) -> dict:
        """fmu_maps.png and summary.json in ``out``; returns the summary."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        save_figure(self.figure(), out / "fmu_maps.png", layout=False)
        s = self.summary()
        write_json(out / "summary.json", s)
        return s


def _contact_top(g0_mm: np.ndarray, touching: list[np.ndarray]) -> float | None:
    """Where a map's clearance axis should end: a cell and a quarter above the highest clearance at which any
    speed of any panel has a cell other than 'no contact' (None: nothing to show)."""
    rows = [np.flatnonzero(t.any(axis=0)) for t in touching]
    j = max((int(r.max()) for r in rows if r.size), default=None)
    if j is None:
        return None
    step = g0_mm[min(j + 1, len(g0_mm) - 1)] - g0_mm[j] if j + 1 < len(g0_mm) else g0_mm[j] - g0_mm[j - 1]
    return float(g0_mm[j] + 1.25 * step)


UNSTABLE_HATCH = "//////"  # six strokes per hatch unit: a few per cell even on a fine map
NO_SOLUTION_COLOUR = "#9a9a9a"


def _cell_edges(x: np.ndarray) -> np.ndarray:
    """Edges of cells centred on x (midpoints inside, half a spacing beyond the ends)."""
    x = np.asarray(x, dtype=float)
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


def quasi_static_maps(fmu: str | Path, model, speeds: np.ndarray, g0s: np.ndarray, workdir: str | Path,
                      formulations=("2D", "3D"), compare: bool = True, progress: bool = False,
                      **start) -> QuasiStaticMaps:
    """For each g0, one FMU instance in quasi_static mode swept through ``speeds`` (normalised); ``start``:
    other parameters' values (e.g. max_penetration)."""
    w_ref = model.params.normalisation.omega_ref
    me = model.params.imbalance.me
    unzip = _extract(fmu, Path(workdir) / "unzipped")
    t0 = time.perf_counter()
    ncon, mre = {}, {}
    bar = _progress(len(formulations) * len(g0s) * len(speeds), "FMU quasi-static sweeps", progress)
    for f in formulations:
        n = np.full((len(speeds), len(g0s)), -1, dtype=int)
        re = np.full((len(speeds), len(g0s)), np.nan)
        for j, g0 in enumerate(g0s):
            with Slave(fmu, instance_name=f"qs_{f}_{j}", unzip_dir=unzip, mode="quasi_static", formulation=f,
                       g0=float(g0), Omega=float(speeds[0] * w_ref), imbalance=me, **start) as s:
                for i, sp in enumerate(speeds):
                    # a point without a balanced solution ends the FMU's run (fmi2Terminated): the sweep rolls
                    # back to the state before it and goes on, as a master that handles fmi2Discard does
                    before = s.get_state()
                    s.set(Omega=float(sp * w_ref))
                    try:
                        s.step(None, 1.0)  # from the FMU's time: a refused step does not advance it
                    except Exception:  # noqa: BLE001 - no balanced solution here: the cell stays -1
                        if s.get("status") != 1:
                            raise
                        s.set_state(before)
                    else:
                        n[i, j] = s.get("n_contact")
                        re[i, j] = s.get("max_real_eig")
                    s.free_state(before)
                    if bar is not None:
                        bar.update(1)
        ncon[f], mre[f] = n, re
    if bar is not None:
        bar.close()
    res = QuasiStaticMaps(np.asarray(speeds), np.asarray(g0s), ncon, mre, seconds=time.perf_counter() - t0)
    if compare:
        res.comparison = _compare_maps(model, res)
    return res


def _compare_maps(model, res: QuasiStaticMaps) -> dict:
    from rotorub_model.analyses.maps import run_stability_map

    out = {}
    for f in res.n_contact:
        lib = run_stability_map(model, f, res.speeds, res.g0s, progress=False, executor="serial")
        a, b = res.n_contact[f], lib.n_contact
        both = (a >= 0) & (b >= 0)
        same = both & (a == b)
        ra, rb = res.max_real[f], lib.max_real
        ok = same & np.isfinite(ra) & np.isfinite(rb)
        # stability verdicts and eigenvalues where both found the same contact state
        verdict = (ra[ok] > 1e-6) == (rb[ok] > 1e-6)
        scale = np.maximum(np.abs(rb[ok]), 1.0)
        out[f] = {
            "cells": int(a.size),
            "cells_same_blades_in_contact": int(same.sum()),
            "cells_other_branch": int((both & (a != b)).sum()),
            "cells_solved_by_one_only": int(((a >= 0) != (b >= 0)).sum()),
            "same_stability_verdict_fraction": float(verdict.mean()) if verdict.size else 1.0,
            "max_real_max_diff_1_per_s": float(np.max(np.abs(ra[ok] - rb[ok]))) if ok.any() else 0.0,
            "max_real_max_rel_diff": float(np.max(np.abs(ra[ok] - rb[ok]) / scale)) if ok.any() else 0.0,
        }
    return out


# ----------------------------------------------------------------------------- transients
@dataclass
class FMURun:
    t: np.ndarray
    omega: np.ndarray
    F_N: np.ndarray  # (nt, nb)
    fraction: np.ndarray
    friction_torque: np.ndarray
    disk: np.ndarray  # (nt, 2) fixed frame
    status: np.ndarray
    seconds: float


def run_fmu_transient(fmu: str | Path, unzip: str, formulation: str, g0: float, omega_of_t, me_of_t,
                      t_end: float, h: float = H_TRANSIENT, n_blades: int = 10, name: str = "tr",
                      progress: bool = False) -> FMURun:
    """A transient through the FMU: inputs set at each communication point and held over the step."""
    FN, FR = _names(n_blades, "F_N"), _names(n_blades, "contact_fraction")
    outs = FN + FR + ["friction_torque", "disk_displacement.x", "disk_displacement.y"]
    n = int(round(t_end / h))
    rec = np.zeros((n, len(outs)))
    om = np.zeros(n)
    status = np.zeros(n, dtype=int)
    t0 = time.perf_counter()
    bar = _progress(n, f"FMU {formulation} transient", progress)
    with Slave(fmu, instance_name=name, unzip_dir=unzip, formulation=formulation, mode="transient", g0=g0,
               Omega=float(omega_of_t(0.0)), imbalance=float(me_of_t(0.0))) as s:
        k_done = 0
        for k in range(n):
            t = k * h
            om[k] = omega_of_t(t)
            s.set(Omega=float(om[k]), imbalance=float(me_of_t(t)))
            try:
                s.step(t, h)
            except Exception:  # noqa: BLE001 - a diverged run ends the record (status says why)
                status[k] = s.get("status")
                break
            rec[k] = s.get_reals(outs)
            k_done = k + 1
            if bar is not None and k % 100 == 0:
                bar.update(min(100, n - k))
    if bar is not None:
        bar.close()
    m = max(k_done, 0)
    nb = n_blades
    return FMURun((np.arange(m) + 1) * h, om[:m], rec[:m, :nb], rec[:m, nb:2 * nb], rec[:m, 2 * nb],
                  rec[:m, 2 * nb + 1:2 * nb + 3], status[: m + (1 if m < n else 0)], time.perf_counter() - t0)


def force_growth(r: FMURun) -> dict:
    """Growth of the oscillation of the total normal force at the end of the run: the FMU's counterpart of
    the library's state-envelope growth (rotorub_model.analyses.transient.envelope_growth, on the force's
    peak-to-peak range), judged by the same verdict (envelope_grows)."""
    from rotorub_model.analyses.transient import NO_GROWTH, envelope_growth

    return envelope_growth(r.t, r.F_N.sum(axis=1), kind="ptp") if len(r.t) else dict(NO_GROWTH)


def _rel_diff(a: np.ndarray, b: np.ndarray) -> float:
    m = min(len(a), len(b))
    scale = max(float(np.abs(b[:m]).max()) if m else 0.0, 1e-30)
    return float(np.abs(a[:m] - b[:m]).max() / scale) if m else 0.0


def _verdict(s: dict) -> str:
    """A run's verdict in words, the two meanings apart (as in the library's transient figures)."""
    g = s.get("envelope_growth") or {}
    if s.get("penetration_limit_hit"):
        return "diverged: the penetration limit was hit"
    if g.get("factor") is None:
        return "no growth verdict (a run shorter than 4 s)"
    what = (f"force envelope ×{g['factor']:.3g} over {g['window_s'][0]:.3g}-{g['window_s'][1]:.3g} s "
            f"({g['rate_per_s']:+.3g} 1/s)")
    if s.get("envelope_growing"):
        return "diverged: " + what
    swing = s.get("force_swing_last_s_N")  # a flat envelope is not a settled rub (as the library's verdict says)
    return "not diverging: " + what + not_settled_words(swing)


def _plot_forces(runs: dict[str, FMURun], path: Path, title: str, verdicts: dict[str, str]) -> Path:
    """One panel per formulation, its verdict in its title; a blade keeps its colour in every panel, legends right
    of the data."""
    from rotorub_model.plotting import legend_outside, plot_blade_forces

    plt = pyplot()
    fig, axes = plt.subplots(len(runs), 1, figsize=(9, 3 * len(runs)), sharex=True, squeeze=False)
    for ax, (f, r) in zip(axes[:, 0], runs.items()):
        plot_blade_forces(ax, r.t, r.F_N, lw=0.8)
        ax.set_ylabel("normal contact force F_N [N]")
        ax.set_title(f"{f}: {title}\n{verdicts[f]}", fontsize=9)
        ax.grid(alpha=0.3)
        legend_outside(ax)
    axes[-1, 0].set_xlabel("time [s]")
    return save_figure(fig, path)


def transient_pair(fmu: str | Path, model, speed: float, g0: float, out: str | Path, t_end: float = 20.0,
                   t_ramp: float = 1.0, h: float = H_TRANSIENT, progress: bool = False) -> dict:
    """Section 6 through the FMU: 2D and 3D at (speed, g0), imbalance ramped over t_ramp by the master."""
    from rotorub_model.analyses.transient import envelope_grows, force_swing, run_transient
    from rotorub_model.contact import make_contact

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    unzip = _extract(fmu, out / "unzipped")
    p = model.params
    omega = speed * p.normalisation.omega_ref
    me = p.imbalance.me

    def me_of_t(t):
        return me * min(t / t_ramp, 1.0) if t_ramp > 0 else me

    runs, summary = {}, {"speed": speed, "g0_mm": g0 * 1e3, "t_end_s": t_end, "h_s": h}
    for f in ("2D", "3D"):
        r = run_fmu_transient(fmu, unzip, f, g0, lambda _t: omega, me_of_t, t_end, h, p.blades.count,
                              name=f"pair_{f}", progress=progress)
        lib = run_transient(model, make_contact(model, f, g0=g0), omega, t_end=t_end, t_ramp=t_ramp, me=me,
                            record_dt=h, hold=h)
        runs[f] = r
        i1 = min(int(round(1.0 / h)) - 1, len(r.t) - 1)
        growth = force_growth(r)
        hit = bool(len(r.status) > len(r.t) and r.status[-1] == 1)
        growing = envelope_grows(growth)
        summary[f] = {
            # the two meanings apart, as in the library's transient JSON; diverged: either
            "diverged": True if hit else growing,
            "penetration_limit_hit": hit,
            "envelope_growing": growing,
            "envelope_growth": {**growth, "about": "the total normal force (peak to peak)"},
            "t_reached_s": float(r.t[-1]) if len(r.t) else 0.0,
            "blades_in_contact_at_1s": int((r.F_N[i1] > 0).sum()) if len(r.t) else 0,
            "max_normal_force_N": float(r.F_N.max()) if r.F_N.size else 0.0,
            # [lowest, highest] F_N [N] of the blade swinging most over the last 2 s where it still swings
            "force_swing_last_s_N": list(sw) if len(r.t) and (sw := force_swing(r.t, r.F_N)) else None,
            "final_chord_fractions": r.fraction[-1].round(4).tolist() if len(r.t) else [],
            "seconds_fmu": r.seconds,
            "library_penetration_limit_hit": bool(lib.penetration_limit_hit),
            "max_rel_diff_F_N_vs_library": _rel_diff(r.F_N, lib.outputs["F_N"]),
        }
    _plot_forces(runs, out / "fmu_contact_forces.png", f"normal contact forces through the FMU, "
                 f"Ω = {speed:.3g} Ω_ref, g0 = {g0 * 1e3:.3g} mm", {f: _verdict(summary[f]) for f in runs})
    np.savez_compressed(out / "fmu_transients.npz", **{f"{f}_{k}": getattr(r, k) for f, r in runs.items()
                                                        for k in ("t", "F_N", "fraction", "friction_torque")})
    write_json(out / "summary.json", summary)
    return summary


def run_up(fmu: str | Path, model, out: str | Path, speed_from: float = 2.6, speed_to: float = 4.4,
           duration: float = 6.0, g0: float = 1.0e-3, formulation: str = "3D", h: float = H_TRANSIENT,
           progress: bool = False) -> dict:
    """Acceleration through the first critical speed, Omega(t) linear, full imbalance from t = 0.

    The library comparison is run_transient with the same Omega(t) and ``hold=h``; the
    Euler (angular-acceleration) terms are left out on both sides: the FMU has only Omega
    as input (their relative size here is dOmega/dt / Omega^2 < 1e-3).
    """
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    unzip = _extract(fmu, out / "unzipped")
    p = model.params
    w_ref, me = p.normalisation.omega_ref, p.imbalance.me

    def omega_of_t(t):
        return w_ref * (speed_from + (speed_to - speed_from) * min(max(t / duration, 0.0), 1.0))

    r = run_fmu_transient(fmu, unzip, formulation, g0, omega_of_t, lambda _t: me, duration, h, p.blades.count,
                          name="run_up", progress=progress)
    lib = run_transient(model, make_contact(model, formulation, g0=g0), omega_of_t, t_end=duration, t_ramp=0.0,
                        me=me, record_dt=h, hold=h)

    from rotorub_model.plotting import legend_outside, plot_blade_forces

    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    axes[0].plot(r.t, r.omega / w_ref, lw=1, color="0.2", label="Ω(t), the FMU's input")
    axes[0].set_ylabel("spin speed Ω / Ω_ref [-]")
    plot_blade_forces(axes[1], r.t, r.F_N, lw=0.6)
    axes[1].set_ylabel("normal contact force F_N [N]")
    axes[2].plot(r.t, np.hypot(*r.disk.T) * 1e3, lw=0.8, label="FMU")
    axes[2].plot(lib.t, np.hypot(*lib.outputs["disk_fixed"].T) * 1e3, "--", lw=0.8, label="library")
    axes[2].set_ylabel("fan-disk displacement [mm]")
    axes[2].set_xlabel("time [s]")
    axes[0].set_title(f"{formulation} run-up through the first critical speed through the FMU, g0 = {g0 * 1e3:g} mm")
    for ax in axes:
        ax.grid(alpha=0.3)
        legend_outside(ax)
    save_figure(fig, out / "run_up.png")
    k_peak = int(np.argmax(np.hypot(*r.disk.T))) if len(r.t) else 0
    summary = {
        "formulation": formulation, "g0_mm": g0 * 1e3, "speed_from": speed_from, "speed_to": speed_to,
        "duration_s": duration, "h_s": h,
        "speed_of_peak_response": float(r.omega[k_peak] / w_ref) if len(r.t) else None,
        "max_normal_force_N": float(r.F_N.max()) if r.F_N.size else 0.0,
        "max_blades_in_contact": int((r.F_N > 0).sum(axis=1).max()) if r.F_N.size else 0,
        "penetration_limit_hit": bool(len(r.status) > len(r.t) and r.status[-1] == 1),
        "seconds_fmu": r.seconds,
        "max_rel_diff_F_N_vs_library": _rel_diff(r.F_N, lib.outputs["F_N"]),
        "max_rel_diff_disk_vs_library": _rel_diff(r.disk, lib.outputs["disk_fixed"]),
    }
    np.savez_compressed(out / "run_up.npz", t=r.t, omega=r.omega, F_N=r.F_N, disk=r.disk)
    write_json(out / "summary.json", summary)
    return summary


def compare_flavours(native: str | Path, pythonfmu: str | Path, model, speed: float, g0: float, out: str | Path,
                     t_end: float = 3.0, h: float = 1e-3) -> dict:
    """2D and 3D transients at (speed, g0) through both flavours and in the library (same held inputs):
    max |F_N difference| / max |F_N| of each pair, and whether the two FMUs agree bit for bit."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    p = model.params
    omega, me = speed * p.normalisation.omega_ref, p.imbalance.me

    def me_of_t(t):
        return me * min(t / 1.0, 1.0)

    s = {"t_end_s": t_end, "h_s": h, "speed": speed, "g0_mm": g0 * 1e3}
    unzipped = {name: (path, _extract(path, out / f"unzipped_{name}"))
                for name, path in (("native", native), ("pythonfmu", pythonfmu))}
    for f in ("2D", "3D"):
        runs = {name: run_fmu_transient(path, unz, f, g0, lambda _t: omega, me_of_t, t_end, h, p.blades.count,
                                        name=f"{name}_{f}")
                for name, (path, unz) in unzipped.items()}
        lib = run_transient(model, make_contact(model, f, g0=g0), omega, t_end=t_end, t_ramp=1.0, me=me,
                            record_dt=h, hold=h)
        a, b = runs["native"].F_N, runs["pythonfmu"].F_N
        s[f] = {"native_vs_pythonfmu": _rel_diff(a, b), "bit_identical": bool(a.shape == b.shape and
                                                                            np.array_equal(a, b)),
                "native_vs_library": _rel_diff(a, lib.outputs["F_N"]),
                "pythonfmu_vs_library": _rel_diff(b, lib.outputs["F_N"]),
                "seconds": {k: r.seconds for k, r in runs.items()}}
    write_json(out / "summary.json", s)
    return s
