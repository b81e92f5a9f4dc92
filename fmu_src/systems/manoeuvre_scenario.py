"""The engine scenario with a manoeuvre (issue 27.6): the engine side ovalizes the fan case, the blades rub the two
tight sides of the oval and wear the liner in two lobes.

    python -m fmu_src.systems.manoeuvre_scenario OUT_DIR [--full]

Four native FMUs in one SSP package (``RotorRubEngineManoeuvre.ssp``): the LP spool held at the run-up's top speed
(224.28 rad/s, above the first critical), TipClearance (the closure at that speed, warm), CasingLoad (a pull-up to
2.5 g: the casing ovalized 0.3 mm per g, widest on the vertical, and its centre moved up 0.05 mm per g;
fmu_src/models/casing_load/) and RotorCasingContact with the abradable liner on. Connections: those of the wear
package (spool.Omega -> contact.Omega and clearance.Omega, clearance.closure -> contact.clearance_closure,
contact.friction_torque -> spool.friction_torque) and casing_load.casing_lobe2.amplitude, .casing_lobe2.phase,
.casing_offset.x, .casing_offset.y -> the contact's inputs of the same names.

The reference is the same package in level flight (casing_load's load_factor_peak = 1: nothing distorted). Both
run as written in fmpy (:func:`~fmu_src.systems.ssp.run_ssp_fmpy`, the reference master), libcosim and the C master
(no Python in the process) where they are installed; the summary holds the differences between them.

Imbalance: half the reference's (11 kg mm). At the top speed its response leaves the blades 0.25 mm from the
casing in level flight; the oval's 0.45 mm at 2.5 g closes the two sides 90 degrees from the vertical past the
liner's elastic limit (F_y / k_r = 0.067 mm): the blades cut it there and nowhere else.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

from rotorub_model.plotting import pyplot, save_figure
from rotorub_model.writing import write_json

from ..fmi.description import read_description
from ..models.casing_load import crosscheck as casing_closed_form
from ..models.casing_load.builder import build_casing_load_fmu
from ..models.casing_load.variables import DEFAULTS as CASING_DEFAULTS
from .ssp import run_ssp_fmpy, validate_ssp, write_ssp
from .system import G0_RUB, ME_REF, EngineError
from .wear_scenario import build_wear_fmus

SPEED = 224.28  # rad/s: the coupled and wear scenarios' top speed (4.2 omega_ref), above the first critical
IMBALANCE = 0.5 * ME_REF  # kg m: 11 kg mm, see the module docstring
H = 1e-3  # s
LEVEL_FLIGHT = {"load_factor_peak": 1.0}  # the reference: the same package, nothing distorted
# the same pull-up with the casing centre moved across the oval (horizontally, as a pitch manoeuvre's gyroscopic
# moment yaws the rotor) instead of along it: one tight side closes more than the other
OFFSET_ACROSS = {"offset_angle": 0.0}
CASING_OUTPUTS = ("load_factor", "casing_lobe2.amplitude", "casing_lobe2.phase", "casing_offset.x",
                  "casing_offset.y")
CONTACT_OUTPUTS = ("gap_min", "friction_torque", "n_contact", "wear.depth_max", "wear.depth_mean", "wear.volume",
                   "wear.lobes", *(f"wear.harmonic[{k}]" for k in range(1, 9)))


def scenario_settings(quick: bool = True) -> dict:
    """The pull-up starts at t = 2 s, once the rotor has settled on its imbalance response (the imbalance is there
    from t = 0: the first second rings). quick: CasingLoad's default pull-up (0.5 s up, 2 s at 2.5 g, 0.5 s down),
    6 s; full: a slower one (1.5 s up, 4 s held, 1.5 s down), 10 s. The liner's law is rate-independent, so how
    long the peak is held changes the wear little: once cut, a blade passes at the yield force
    (tests/fmu/test_manoeuvre_scenario.py)."""
    casing = {"t_start": 2.0} if quick else {"t_start": 2.0, "t_rise": 1.5, "t_hold": 4.0, "t_fall": 1.5}
    return {"h": H, "t_end": 6.0 if quick else 10.0, "speed": SPEED, "imbalance": IMBALANCE, "g0": G0_RUB,
            "casing_params": casing}


def build_manoeuvre_fmus(fmu_dir: str | Path, platforms: tuple[str, ...] | None = None,
                         omega0: float = SPEED) -> dict[str, Path]:
    """The scenario's four native FMUs: the wear scenario's three (the contact with its liner, the spool, the
    clearance model starting at ``omega0``) and CasingLoad."""
    fmus = build_wear_fmus(fmu_dir, platforms=platforms, omega0=omega0)
    fmus["casing_load"] = build_casing_load_fmu(fmu_dir, platforms=platforms)
    return fmus


def write_manoeuvre_ssp(path: str | Path, fmus: dict[str, Path], cfg: dict, casing_params: dict | None = None,
                        name: str = "RotorRubEngineManoeuvre") -> Path:
    """The four-component package at the scenario's steady speed (``casing_params`` over ``cfg``'s)."""
    w = cfg["speed"]
    return write_ssp(path, fmus["contact"], fmus["spool"], g0=cfg["g0"], imbalance=cfg["imbalance"],
                     spool_params={"Omega0": w, "Omega1": w}, t_end=cfg["t_end"], h=cfg["h"], name=name,
                     parts={"clearance": (fmus["clearance"], None),
                            "casing_load": (fmus["casing_load"], {**cfg["casing_params"], **(casing_params or {})})})


def record_of(contact_fmu: str | Path) -> tuple[tuple[str, str], ...]:
    """What the scenario records: the spool's speed, the closure, the casing load, the contact's gap, friction,
    wear and the normal force of every blade (their count read from the contact FMU)."""
    cvars, _, _ = read_description(contact_fmu)
    nb = sum(1 for n in cvars if n.startswith("blade[") and n.endswith("].F_N"))
    return (("spool", "Omega"), ("clearance", "closure"), *(("casing_load", v) for v in CASING_OUTPUTS),
            *(("contact", v) for v in CONTACT_OUTPUTS), *(("contact", f"blade[{k}].F_N") for k in range(1, nb + 1)))


def casing_gap(theta: np.ndarray, g0: float, closure: float, a2: float, psi: float, ex: float, ey: float) -> np.ndarray:
    """The gap to a centred rotor around the casing (2D; the contact's own reading of its inputs, docs/THEORY.md
    4.1): g0 - closure + a2 cos 2(theta - psi) + ex cos theta + ey sin theta."""
    return g0 - closure + a2 * np.cos(2.0 * (theta - psi)) + ex * np.cos(theta) + ey * np.sin(theta)


def tight_points(g0: float, closure: float, a2: float, psi: float, ex: float, ey: float) -> list[tuple[float, float]]:
    """(angle [deg], gap [m]) of the casing's local minima of :func:`casing_gap` (two for an oval, unless the offset
    outweighs it), from a fine grid refined by a parabola through the three points around each.

    >>> [(round(a), round(g * 1e3, 6)) for a, g in tight_points(1e-3, 0.0, 2e-4, 0.0, 0.0, 0.0)]  # widest at 0 deg
    [(90, 0.8), (270, 0.8)]
    """
    n = 3600
    th = np.arange(n) * 2.0 * math.pi / n
    g = casing_gap(th, g0, closure, a2, psi, ex, ey)
    out = []
    for k in np.flatnonzero((g < np.roll(g, 1)) & (g <= np.roll(g, -1))):
        gm, g_, gp = g[k - 1], g[k], g[(k + 1) % n]
        d = 0.5 * (gm - gp) / (gm - 2.0 * g_ + gp) if (gm - 2.0 * g_ + gp) > 0 else 0.0
        t = th[k] + d * 2.0 * math.pi / n
        out.append((math.degrees(t) % 360.0, float(casing_gap(np.array([t]), g0, closure, a2, psi, ex, ey)[0])))
    return out


def _first(t: np.ndarray, mask: np.ndarray) -> float | None:
    k = np.flatnonzero(mask)
    return float(t[k[0]]) if k.size else None


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference relative to the reference column's largest magnitude (its difference where it is 0)."""
    scale = float(np.abs(b).max())
    d = float(np.abs(np.asarray(a) - b).max())
    return d / scale if scale > 0 else d


def _masters(ssp: Path, cfg: dict, record, fmpy_run: dict) -> dict:
    """The package in libcosim and in the C master: their largest differences from fmpy, per recorded variable,
    and their wall times (None and a note where a master is not installed)."""
    from . import ssp as ssp_mod

    out = {}
    for name, runner in (("libcosim", "run_ssp_libcosim"), ("native_host", "run_ssp_native")):
        t0 = time.perf_counter()
        try:
            other = getattr(ssp_mod, runner)(ssp, cfg["t_end"], cfg["h"], record)
        except (EngineError, RuntimeError, OSError) as exc:
            out[name] = {"max_rel_diff": None, "largest": None, "note": str(exc)}
            continue
        diffs = {f"{c}.{v}": _rel(other[f"{c}.{v}"], fmpy_run[f"{c}.{v}"]) for c, v in record}
        worst = max(diffs, key=diffs.get)
        out[name] = {"max_rel_diff": diffs, "largest": diffs[worst], "largest_in": worst,
                     "wall_time_s": time.perf_counter() - t0}
    return out


def run_manoeuvre_scenario(out_dir: str | Path, quick: bool = True, fmu_dir: str | Path | None = None,
                           fmus: dict[str, Path] | None = None, masters: bool = True) -> dict:
    """Build the FMUs (unless given), write and validate the manoeuvre package and its level-flight reference, run
    both in fmpy, libcosim and the C master (``masters``), save ``manoeuvre_engine.npz``, ``manoeuvre_engine.png``
    and ``summary.json`` in ``out_dir``.

    Returns ``{"summary": ..., "markdown": the report's section, "figures": [(title, file name in out_dir)]}``.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = scenario_settings(quick)
    t0 = time.perf_counter()
    built_here = not fmus
    fmus = fmus or build_manoeuvre_fmus(Path(fmu_dir) if fmu_dir else out / "fmus", omega0=cfg["speed"])
    build_s = time.perf_counter() - t0 if built_here else None  # None ("–"): the FMUs were given
    ssp = write_manoeuvre_ssp(out / "RotorRubEngineManoeuvre.ssp", fmus, cfg)
    level = write_manoeuvre_ssp(out / "RotorRubEngineManoeuvre_level_flight.ssp", fmus, cfg, LEVEL_FLIGHT,
                                name="RotorRubEngineLevelFlight")
    for p in (ssp, level):
        problems = validate_ssp(p)
        if problems:
            raise EngineError(f"{p}: the SSP does not validate", problems)
    record = record_of(fmus["contact"])
    t1 = time.perf_counter()
    run = run_ssp_fmpy(ssp, cfg["t_end"], cfg["h"], record)
    fmpy_s = time.perf_counter() - t1
    ref = run_ssp_fmpy(level, cfg["t_end"], cfg["h"], record)
    across_ssp = write_manoeuvre_ssp(out / "RotorRubEngineManoeuvre_offset_across.ssp", fmus, cfg, OFFSET_ACROSS,
                                     name="RotorRubEngineManoeuvreOffsetAcross")
    wear = (("contact", "wear.depth_max"), ("contact", "wear.lobes"),
            *(("contact", f"wear.harmonic[{k}]") for k in range(1, 9)))
    across = run_ssp_fmpy(across_ssp, cfg["t_end"], cfg["h"], wear)
    np.savez_compressed(out / "manoeuvre_engine.npz", **{k.replace(".", "__"): v for k, v in run.items()},
                        **{f"level_flight__{k.replace('.', '__')}": v for k, v in ref.items()})
    contact_vars, _, _ = read_description(fmus["contact"])
    liner = {"yield_force_N": float(contact_vars["yield_force"].start), "k_r_N_m": float(contact_vars["k_r"].start)}
    summary = summarize(run, ref, cfg, liner)
    summary.update({"offset_across_oval_wear_depth_max_mm": float(across["contact.wear.depth_max"][-1]) * 1e3,
                    "offset_across_oval_wear_lobes": int(across["contact.wear.lobes"][-1]),
                    "offset_across_oval_wear_harmonics_mm": [float(across[f"contact.wear.harmonic[{k}]"][-1]) * 1e3
                                                             for k in range(1, 9)]})
    summary.update({"quick": quick, "ssp": str(ssp), "ssp_level_flight": str(level), "ssp_valid": True,
                    "build_time_s": build_s, "fmpy_wall_time_s": fmpy_s})
    plot_manoeuvre_scenario(run, ref, summary, out / "manoeuvre_engine.png", across)
    if masters:
        for key, package, fmpy_run in (("masters", ssp, run), ("masters_level_flight", level, ref)):
            summary[key] = _masters(package, cfg, record, fmpy_run)
        worst = [m["largest"] for k in ("masters", "masters_level_flight") for m in summary[k].values()
                 if m["largest"] is not None]
        summary["masters_max_rel_diff"] = max(worst) if worst else None
    write_json(out / "summary.json", summary)
    figures = [("Engine manoeuvre: load factor, ovalization, gap, blade forces, the liner's wear and its lobes",
                "manoeuvre_engine.png")]
    return {"summary": summary, "markdown": report_section(summary), "figures": figures}


def summarize(run: dict, ref: dict, cfg: dict, liner: dict) -> dict:
    """The scenario's numbers from the fmpy runs of the manoeuvre (``run``) and of level flight (``ref``)."""
    t = run["t"]
    p = {**CASING_DEFAULTS, **cfg["casing_params"]}
    t_start = p["t_start"]
    t_end_manoeuvre = t_start + p["t_rise"] + p["t_hold"] + p["t_fall"]
    before = (t > t_start - 0.5) & (t <= t_start)
    dn = p["load_factor_peak"] - 1.0
    a2, e = p["ovalization_per_g"] * dn, p["offset_per_g"] * dn
    ex, ey = e * math.cos(p["offset_angle"]), e * math.sin(p["offset_angle"])
    closure = float(run["clearance.closure"][-1])
    # the recorded casing load against its closed form (after each step: the rows are t_1 .. t_N)
    closed = casing_closed_form.closed_form(t, **cfg["casing_params"])
    casing_err = max(_rel(run[f"casing_load.{v}"], closed[v]) for v in CASING_OUTPUTS)
    blades = sorted(k for k in run if k.startswith("contact.blade["))
    F = np.column_stack([run[k] for k in blades]) if blades else np.zeros((len(t), 0))
    harmonics = [float(run[f"contact.wear.harmonic[{k}]"][-1]) for k in range(1, 9)]
    contact = run["contact.n_contact"] > 0
    return {
        "t_end_s": cfg["t_end"], "h_s": cfg["h"], "speed_rad_s": cfg["speed"], "imbalance_kg_m": cfg["imbalance"],
        "g0_mm": cfg["g0"] * 1e3, "closure_mm": closure * 1e3,
        "load_factor_peak": p["load_factor_peak"], "manoeuvre_s": [t_start, t_end_manoeuvre],
        "ovalization_peak_mm": a2 * 1e3, "ovalization_phase_deg": math.degrees(p["ovalization_phase"]),
        "offset_peak_mm": e * 1e3, "offset_angle_deg": math.degrees(p["offset_angle"]),
        "casing_load_vs_closed_form_max_rel_diff": casing_err,
        "tight_points_at_peak": [{"angle_deg": a, "gap_to_centred_rotor_mm": g * 1e3}
                                 for a, g in tight_points(cfg["g0"], closure, a2, p["ovalization_phase"], ex, ey)],
        "liner_elastic_limit_mm": liner["yield_force_N"] / liner["k_r_N_m"] * 1e3,
        "liner_yield_force_N": liner["yield_force_N"],
        "gap_min_level_flight_before_manoeuvre_mm": float(run["contact.gap_min"][before].min()) * 1e3,
        "gap_min_during_manoeuvre_mm": float(run["contact.gap_min"].min()) * 1e3,
        "t_first_contact_s": _first(t, contact),
        "contact_time_s": float(np.count_nonzero(contact) * cfg["h"]),
        "max_contact_force_N": float(F.max()) if F.size else 0.0,
        "spool_speed_dip_rad_s": float(np.max(ref["spool.Omega"] - run["spool.Omega"])),
        "wear_depth_max_mm": float(run["contact.wear.depth_max"][-1]) * 1e3,
        "wear_depth_mean_mm": float(run["contact.wear.depth_mean"][-1]) * 1e3,
        "wear_volume_mm3": float(run["contact.wear.volume"][-1]) * 1e9,
        "wear_lobes": int(run["contact.wear.lobes"][-1]),
        "wear_harmonics_mm": [h * 1e3 for h in harmonics],
        "t_wear_done_s": _first(t, run["contact.wear.depth_max"] >= run["contact.wear.depth_max"][-1]),
        "level_flight_gap_min_mm": float(ref["contact.gap_min"].min()) * 1e3,
        "level_flight_contact_time_s": float(np.count_nonzero(ref["contact.n_contact"] > 0) * cfg["h"]),
        "level_flight_wear_depth_max_mm": float(ref["contact.wear.depth_max"][-1]) * 1e3,
        "level_flight_wear_lobes": int(ref["contact.wear.lobes"][-1]),
    }


def plot_manoeuvre_scenario(run: dict, ref: dict, s: dict, path: Path, across: dict | None = None) -> Path:
    """Six panels: the casing load, gap_min, the blades' normal forces, the worn depth (and, given ``across``, that
    of the run whose offset lies across the oval), the wear's harmonics and lobes over time, and the casing's gap
    around the circumference at the peak."""
    plt = pyplot()
    t = run["t"]
    fig, ax = plt.subplots(3, 2, figsize=(13, 10.5))
    a = ax[0, 0]
    a.plot(t, run["casing_load.load_factor"], "k", lw=1.4, label="load factor n")
    a.set_ylabel("load factor n [g]")
    a.set_title(f"pull-up to {s['load_factor_peak']:g} g at Ω = {s['speed_rad_s']:g} rad/s (steady), imbalance "
                f"{s['imbalance_kg_m'] * 1e3:g} kg·mm", fontsize=9)
    b = a.twinx()
    b.plot(t, run["casing_load.casing_lobe2.amplitude"] * 1e3, "C0", lw=1.2, label="ovalization a₂ (lobe 2)")
    b.plot(t, np.hypot(run["casing_load.casing_offset.x"], run["casing_load.casing_offset.y"]) * 1e3, "C1", lw=1.2,
           label="casing centre offset |e|")
    b.set_ylabel("casing distortion [mm]")
    lines = a.get_legend_handles_labels()[0] + b.get_legend_handles_labels()[0]
    a.legend(lines, [ln.get_label() for ln in lines], fontsize=7, loc="upper left")

    a = ax[0, 1]
    a.plot(t, ref["contact.gap_min"] * 1e3, "k--", lw=1, label="level flight (reference package)")
    a.plot(t, run["contact.gap_min"] * 1e3, "C3", lw=1.2, label="manoeuvre")
    a.axhline(0.0, color="0.5", lw=0.8)
    a.axhline(-s["liner_elastic_limit_mm"], color="C2", lw=0.8, ls=":",
              label=f"−F_y/k_r = −{s['liner_elastic_limit_mm'] * 1e3:.0f} µm: the liner yields")
    a.set_ylabel("gap_min (smallest blade gap) [mm]")
    a.set_title("the oval's tight sides close the gap", fontsize=9)
    a.set_ylim(bottom=-0.28)  # room for the legend below the curves
    a.legend(fontsize=7, loc="lower left")

    a = ax[1, 0]
    # the blades strike the two tight sides twice a revolution each: a revolution's largest force and its mean
    # total force read better than ten impulse trains
    blades = [k for k in run if k.startswith("contact.blade[")]
    F = np.column_stack([run[k] for k in blades])
    n = max(1, int(round(2.0 * math.pi / (s["speed_rad_s"] * s["h_s"]))))
    m = len(t) // n * n
    tw = t[:m].reshape(-1, n).mean(axis=1)
    a.plot(tw, F[:m].reshape(-1, n * F.shape[1]).max(axis=1), "C3", lw=1.2,
           label="largest blade force in each revolution")
    a.plot(tw, F[:m].sum(axis=1).reshape(-1, n).mean(axis=1), "C0", lw=1.2,
           label="total normal force, mean over each revolution")
    Fr = np.column_stack([ref[k] for k in blades])
    a.plot(t, Fr.max(axis=1), "k--", lw=1, label="level flight: largest blade force")
    a.axhline(s["liner_yield_force_N"], color="C2", lw=0.8, ls=":", label="the liner's yield force F_y")
    a.set_ylabel("normal contact force [N]")
    a.set_title(f"blade forces ({len(blades)} blades, a revolution = {n} steps; max {s['max_contact_force_N']:.0f} N)",
                fontsize=9)
    a.legend(fontsize=7, loc="center left")

    a = ax[1, 1]
    a.plot(t, run["contact.wear.depth_max"] * 1e6, "C3", lw=1.4, label="deepest wear")
    a.plot(t, run["contact.wear.depth_mean"] * 1e6, "C3", lw=1, ls="-.", label="mean worn depth")
    a.plot(t, ref["contact.wear.depth_max"] * 1e6, "k--", lw=1, label="level flight: deepest wear")
    if across is not None:
        a.plot(across["t"], across["contact.wear.depth_max"] * 1e6, "C4:", lw=1.2,
               label=f"offset across the oval instead: deepest wear ({s['offset_across_oval_wear_lobes']} lobe)")
    a.set_ylabel("worn depth of the liner [µm]")
    a.set_title(f"wear {s['wear_depth_max_mm'] * 1e3:.1f} µm deep, {s['wear_volume_mm3']:.3g} mm³ "
                f"(level flight: {s['level_flight_wear_depth_max_mm'] * 1e3:g} µm)", fontsize=9)
    # between the mean worn depth (a few µm) and the deepest wear: the one free band of the panel
    a.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 0.09))

    a = ax[2, 0]
    for k in range(1, 5):
        a.plot(t, run[f"contact.wear.harmonic[{k}]"] * 1e6, f"C{k - 1}", lw=1.2 if k == 2 else 0.9,
               label=f"harmonic {k} ({k} lobe{'s' if k > 1 else ''})")
    a.set_ylabel("worn profile's harmonic amplitude [µm]")
    a.set_xlabel("time [s]")
    b = a.twinx()
    b.step(t, run["contact.wear.lobes"], "k", lw=0.8, where="post", label="wear.lobes (the kernel's rule)")
    b.set_ylabel("lobes")
    b.set_ylim(-0.2, 4.2)
    lines = a.get_legend_handles_labels()[0] + b.get_legend_handles_labels()[0]
    a.legend(lines, [ln.get_label() for ln in lines], fontsize=7, loc="upper left")
    a.set_title(f"the wear's lobes: {s['wear_lobes']} (harmonic 4 is 2's multiple: two narrow cuts)", fontsize=9)

    a = ax[2, 1]
    th = np.linspace(0.0, 2.0 * math.pi, 721)
    e, ang = s["offset_peak_mm"] * 1e-3, math.radians(s["offset_angle_deg"])
    g = casing_gap(th, s["g0_mm"] * 1e-3, s["closure_mm"] * 1e-3, s["ovalization_peak_mm"] * 1e-3,
                   math.radians(s["ovalization_phase_deg"]), e * math.cos(ang), e * math.sin(ang))
    a.plot(np.degrees(th), g * 1e3, "C0", lw=1.4, label=f"at the peak ({s['load_factor_peak']:g} g)")
    a.axhline((s["g0_mm"] - s["closure_mm"]), color="k", lw=1, ls="--", label="level flight (round, centred)")
    reach = s["g0_mm"] - s["closure_mm"] - s["gap_min_level_flight_before_manoeuvre_mm"]
    a.axhline(reach, color="C3", lw=1, ls=":",
              label=f"the blades' reach in level flight ({reach:.2f} mm): they touch below it")
    for tp in s["tight_points_at_peak"]:
        a.axvline(tp["angle_deg"], color="C3", lw=0.6, alpha=0.6)
    a.set_xlim(0, 360)
    a.set_xticks(range(0, 361, 45))
    a.set_xlabel("fixed-frame angle θ [deg] (90: up)")
    a.set_ylabel("casing gap to a centred rotor [mm]")
    a.set_title("the casing at the peak: two tight sides, 180° apart (2D sketch)", fontsize=9)
    a.legend(fontsize=7, loc="upper right")
    for x in ax.flat:
        x.grid(alpha=0.3)
    for x in ax[:2].flat:
        x.set_xlabel("time [s]")
    return save_figure(fig, path)


def _lobes(n: int) -> str:
    return "no lobe dominating" if n == 0 else f"{n} lobe" + ("s" if n > 1 else "")


def report_section(s: dict) -> str:
    """The report's markdown about the scenario's summary ``s``."""
    def largest(key: str, master: str) -> str:
        m = s.get(key, {}).get(master) or {}
        return f"{m['largest']:.1e}" if m.get("largest") is not None else "not run (" + str(m.get("note", "")) + ")"

    tp = ", ".join(f"{p['angle_deg']:.0f}°" for p in s["tight_points_at_peak"])
    return "\n".join([
        "", "## Engine manoeuvre (spool + clearance + casing load + contact with its liner)", "",
        f"The spool held at {s['speed_rad_s']:g} rad/s with {s['imbalance_kg_m'] * 1e3:g} kg·mm of imbalance and "
        f"g0 = {s['g0_mm']:g} mm ({s['closure_mm']:.3g} mm closed warm): in level flight the blades keep "
        f"{s['gap_min_level_flight_before_manoeuvre_mm']:.3g} mm and never touch (wear "
        f"{s['level_flight_wear_depth_max_mm']:g} mm). A pull-up to {s['load_factor_peak']:g} g "
        f"(CasingLoad.fmu: {s['manoeuvre_s'][0]:g}–{s['manoeuvre_s'][1]:g} s) ovalizes the casing "
        f"{s['ovalization_peak_mm']:.3g} mm (widest at {s['ovalization_phase_deg']:.0f}°) and moves its centre "
        f"{s['offset_peak_mm']:.3g} mm: the sides at {tp} close, the blades rub from t = "
        f"{s['t_first_contact_s']} s (up to {s['max_contact_force_N']:.0f} N) and cut the liner "
        f"{s['wear_depth_max_mm'] * 1e3:.1f} µm deep in **{s['wear_lobes']} lobes** "
        f"({s['wear_volume_mm3']:.3g} mm³). The same pull-up with the offset across the oval (horizontal, as the "
        f"gyroscopic moment yaws the rotor) closes one side more than the other: "
        f"{s['offset_across_oval_wear_depth_max_mm'] * 1e3:.1f} µm deep, {_lobes(s['offset_across_oval_wear_lobes'])}: "
        "the lobes tell which load dominated. The package and its level-flight reference run the same in fmpy, in "
        f"libcosim (largest relative difference {largest('masters', 'libcosim')}; level flight "
        f"{largest('masters_level_flight', 'libcosim')}) and in the C master ({largest('masters', 'native_host')}; "
        f"{largest('masters_level_flight', 'native_host')}).", ""])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--full", action="store_true", help="the slower pull-up, 9 s (default: 5 s)")
    ns = ap.parse_args(argv)
    try:
        r = run_manoeuvre_scenario(ns.out_dir, quick=not ns.full)
    except EngineError as exc:
        print(f"manoeuvre: error: {exc}", file=sys.stderr)
        return 2
    s = r["summary"]
    print({k: v for k, v in s.items() if not k.startswith("masters")})
    print(f"verdict: the manoeuvre wears the liner {s['wear_depth_max_mm'] * 1e3:.1f} µm deep in {s['wear_lobes']} "
          f"lobes (level flight: {s['level_flight_wear_depth_max_mm'] * 1e3:g} µm); the masters agree to "
          f"{s.get('masters_max_rel_diff')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
