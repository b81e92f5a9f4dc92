"""The engine scenario with wear (issue 19.5): a run-up in which the clearance closes, a rub that wears the
abradable liner, and the clearance the engine keeps afterwards.

    python -m fmu_src.systems.wear_scenario OUT_DIR [--full]

Three native FMUs in one SSP package (``RotorRubEngineWear.ssp``): the LP spool (its speed schedule through
the first critical speed, as the coupled scenario's), TipClearance (the clearance closure from the spool
speed: centrifugal at once, thermal with a lag) and RotorCasingContact built with the abradable liner on
(the reference parameters with ``abradable.enabled = true``: the liner is the FMU's default, so the package
sets no Enumeration, which libcosim 0.0.6 cannot read). Connections: spool.Omega -> contact.Omega and
clearance.Omega, clearance.closure -> contact.clearance_closure, contact.friction_torque ->
spool.friction_torque. The package runs as written in fmpy (:func:`~fmu_src.systems.ssp.run_ssp_fmpy`), in
libcosim and in the C master (no Python in the process) where they are installed; the summary holds the
differences between them. The same run without the closure FMU's input (a clearance that stays at g0, the
liner still abradable) shows what the closure did.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from rotorub_model.plotting import pyplot, save_figure
from rotorub_model.writing import write_json

from ..models.clearance.builder import build_clearance_fmu
from ..models.contact.builder import build_native_fmu
from ..models.spool.builder import build_native_spool_fmu
from .coupling import scenario_settings
from .ssp import run_ssp_fmpy, validate_ssp, write_ssp
from .system import G0_RUB, EngineError

RECORD = (("spool", "Omega"), ("clearance", "closure"), ("contact", "gap_min"), ("contact", "wear.depth_max"),
          ("contact", "wear.volume"), ("contact", "clearance_effective"), ("contact", "friction_torque"),
          ("contact", "n_contact"))
# a commonly quoted figure for a turbofan's fan and compressor: 0.125 mm more tip clearance costs about 0.5 %
# more fuel burn (issue 19); a rule of thumb for the summary, not a performance model
FUEL_BURN_PCT_PER_MM = 0.5 / 0.125
# a quarter of the coupled scenario's imbalance: through the first critical its response alone stays within
# the 1 mm clearance; the closure makes it rub, and the liner takes a cut, not its whole thickness
IMBALANCE = 0.25 * 22.0e-3  # kg m


def build_wear_fmus(fmu_dir: str | Path, platforms: tuple[str, ...] | None = None,
                    omega0: float = 149.52) -> dict[str, Path]:
    """The scenario's three native FMUs: the contact FMU with the liner on, the spool, the clearance model
    (its speed input starting at the spool's ``omega0``)."""
    from rotorub_model.structure.params import reference_parameters, to_toml

    fmu_dir = Path(fmu_dir)
    fmu_dir.mkdir(parents=True, exist_ok=True)
    params = fmu_dir / "reference_with_liner.toml"
    params.write_text(to_toml(reference_parameters().replace(abradable={"enabled": True})))
    contact = Path(build_native_fmu(fmu_dir / "liner", params_file=params, platforms=platforms)["fmu"])
    return {"contact": contact, "spool": build_native_spool_fmu(fmu_dir, platforms=platforms),
            "clearance": build_clearance_fmu(fmu_dir, platforms=platforms, Omega=omega0)}


def run_wear_scenario(out_dir: str | Path, quick: bool = True, fmu_dir: str | Path | None = None,
                      fmus: dict[str, Path] | None = None, imbalance: float = IMBALANCE,
                      platforms: tuple[str, ...] | None = None) -> dict:
    """Build the FMUs (unless given; ``platforms``: their binaries, None for every platform), write and validate the
    package, run it in fmpy, libcosim and the C master, save ``wear_engine.npz``, ``wear_engine.png`` and
    ``summary.json`` in ``out_dir``; returns the summary."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = scenario_settings(quick)
    t0 = time.perf_counter()
    built_here = not fmus
    fmus = fmus or build_wear_fmus(Path(fmu_dir) if fmu_dir else out / "fmus", platforms=platforms,
                                   omega0=cfg["spool_params"]["Omega0"])
    build_s = time.perf_counter() - t0 if built_here else None  # None ("–"): the FMUs were given
    common = {"g0": G0_RUB, "imbalance": imbalance, "formulation": cfg["formulation"],
              "spool_params": cfg["spool_params"], "t_end": cfg["t_end"], "h": cfg["h"]}
    ssp = write_ssp(out / "RotorRubEngineWear.ssp", fmus["contact"], fmus["spool"], clearance_fmu=fmus["clearance"],
                    name="RotorRubEngineWear", **common)
    problems = validate_ssp(ssp)
    if problems:
        raise EngineError(f"{ssp}: the SSP does not validate", problems)
    # the same system whose clearance does not close (c_centrifugal = c_thermal = 0): what the closure did
    still = write_ssp(out / "RotorRubEngineWear_no_closure.ssp", fmus["contact"], fmus["spool"],
                      clearance_fmu=fmus["clearance"], name="RotorRubEngineWearNoClosure",
                      clearance_params={"c_centrifugal": 0.0, "c_thermal": 0.0}, **common)
    t1 = time.perf_counter()
    run = run_ssp_fmpy(ssp, cfg["t_end"], cfg["h"], RECORD)
    fmpy_s = time.perf_counter() - t1
    ref = run_ssp_fmpy(still, cfg["t_end"], cfg["h"], RECORD)
    np.savez_compressed(out / "wear_engine.npz", **{k.replace(".", "__"): v for k, v in run.items()},
                        **{f"no_closure__{k.replace('.', '__')}": v for k, v in ref.items()})
    plot_wear_scenario(run, ref, out / "wear_engine.png")
    closure_end = float(run["clearance.closure"][-1])
    keep = float(run["contact.clearance_effective"][-1])
    cold = G0_RUB - closure_end  # the clearance an unworn liner would leave at the same speed and temperature
    summary = {
        "t_end_s": cfg["t_end"], "h_s": cfg["h"], "g0_mm": G0_RUB * 1e3, "imbalance_kg_m": imbalance,
        "quick": quick, "ssp": str(ssp),
        "ssp_valid": True, "build_time_s": build_s, "fmpy_wall_time_s": fmpy_s,
        "closure_max_mm": float(run["clearance.closure"].max()) * 1e3, "closure_end_mm": closure_end * 1e3,
        "wear_depth_max_mm": float(run["contact.wear.depth_max"][-1]) * 1e3,
        "wear_volume_mm3": float(run["contact.wear.volume"][-1]) * 1e9,
        "t_first_contact_s": _first(run["t"], run["contact.n_contact"] > 0),
        "clearance_effective_end_mm": keep * 1e3,
        "clearance_without_wear_end_mm": cold * 1e3,
        "clearance_penalty_mm": (keep - cold) * 1e3,
        "fuel_burn_penalty_estimate_pct": (keep - cold) * 1e3 * FUEL_BURN_PCT_PER_MM,
        "fuel_burn_rule": "0.125 mm of tip clearance ~ 0.5 % fuel burn (a commonly quoted figure)",
        "no_closure_wear_depth_max_mm": float(ref["contact.wear.depth_max"][-1]) * 1e3,
        "no_closure_wear_volume_mm3": float(ref["contact.wear.volume"][-1]) * 1e9,
        "spool_speed_end_rad_s": float(run["spool.Omega"][-1]),
    }
    for name, runner in (("libcosim", "run_ssp_libcosim"), ("native_host", "run_ssp_native")):
        try:
            from . import ssp as ssp_mod

            other = getattr(ssp_mod, runner)(ssp, cfg["t_end"], cfg["h"], RECORD)
            summary[f"{name}_max_rel_diff"] = {f"{c}.{v}": _rel(other[f"{c}.{v}"], run[f"{c}.{v}"])
                                              for c, v in RECORD}
        except (EngineError, RuntimeError, OSError) as exc:
            summary[f"{name}_max_rel_diff"] = None
            summary[f"{name}_note"] = str(exc)
    write_json(out / "summary.json", summary)
    summary["figures"] = [("Engine scenario with wear: closure, gap, worn depth and the clearance kept",
                           "wear_engine.png")]
    return summary


def _first(t: np.ndarray, mask: np.ndarray) -> float | None:
    k = np.flatnonzero(mask)
    return float(t[k[0]]) if k.size else None


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    scale = float(np.abs(b).max())
    return float(np.abs(np.asarray(a) - b).max() / scale) if scale > 0 else float(np.abs(np.asarray(a) - b).max())


def plot_wear_scenario(run: dict, ref: dict, path: Path) -> Path:
    plt = pyplot()
    t = run["t"]
    fig, axes = plt.subplots(4, 1, figsize=(9, 9), sharex=True)
    axes[0].plot(t, run["spool.Omega"], "k", lw=1.2)
    axes[0].set_ylabel("spool speed Ω [rad/s]")
    axes[0].set_title("run-up through the first critical speed: the clearance closes, the blades cut the liner",
                      fontsize=10)
    axes[1].plot(t, run["clearance.closure"] * 1e3, "C0", lw=1.2, label="closure (TipClearance.fmu)")
    axes[1].plot(t, ref["clearance.closure"] * 1e3, "C0:", lw=1, label="no closure (the comparison run)")
    axes[1].set_ylabel("clearance closure [mm]")
    axes[2].plot(t, run["contact.wear.depth_max"] * 1e3, "C3", lw=1.2, label="deepest wear, with closure")
    axes[2].plot(t, ref["contact.wear.depth_max"] * 1e3, "C3:", lw=1, label="deepest wear, no closure")
    axes[2].set_ylabel("worn depth [mm]")
    axes[3].plot(t, run["contact.clearance_effective"] * 1e3, "C2", lw=1.2,
                 label="clearance kept: g0 - closure + mean wear")
    axes[3].plot(t, (1e-3 - run["clearance.closure"]) * 1e3, "C2--", lw=1, label="the same without wear")
    axes[3].set_ylabel("tip clearance [mm]")
    axes[3].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return save_figure(fig, path)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--full", action="store_true", help="the 6 s run-up (default: 4 s)")
    ns = ap.parse_args(argv)
    s = run_wear_scenario(ns.out_dir, quick=not ns.full)
    print({k: v for k, v in s.items() if k != "figures"})
    return 0


if __name__ == "__main__":
    sys.exit(main())
