"""The FMU half of ``rotorub reproduce``: build the FMUs, run the harnesses and the coupled
engine scenarios, and return their summary and the report's section about them.

Called through the entry point ``rotorub.reproduce`` (cli.py) by :func:`rotorub_model.app.cli.cmd_reproduce`
after the library analyses (whose summary gives the transient point and the stability grid to compare with);
the library's report inserts the section as it is (it knows none of the keys here).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def _step(msg: str, progress: bool = True):
    """A stage of the FMU half, on stderr (stdout holds the verdict, or the JSON with --json): announced, a heartbeat
    while it runs, its time at the end."""
    from rotorub_model.progress import stage

    return stage(msg, progress, prefix="reproduce")


def build_all(fmu_dir: str | Path = "fmus", params_file: str | Path | None = None) -> dict:
    """Every FMU the FMU half runs, for this machine only: both flavours of the contact FMU (with their cross-check
    kits), the spool FMU of the coupled scenario, the three FMUs of the scenario with wear and the four of the
    manoeuvre.

    This machine's only, because the harnesses, the masters and the C hosts all run here: a cold ziglang cache
    compiles each target's C library first (measured on 2 cores: linux64 17 s, aarch64-linux 22 s, darwin64 17 s,
    win64 148 s on a loaded machine), which alone would take the main job past its 3 minutes. ``rotorub build-fmu
    --native`` builds the five platforms (README, "The FMUs")."""
    from .fmi.compile import host_platform
    from .models.contact.builder import build_with_kit as build
    from .models.spool.builder import build_native_spool_fmu
    from .systems.coupling import scenario_settings
    from .systems.manoeuvre_scenario import build_manoeuvre_fmus
    from .systems.manoeuvre_scenario import scenario_settings as manoeuvre_settings
    from .systems.wear_scenario import build_wear_fmus

    plats = (host_platform(),)
    fmu_dir = Path(fmu_dir)
    return {"platforms": plats, "pythonfmu": build(fmu_dir, params_file, platforms=plats),
            "native": build(fmu_dir / "native", params_file, native=True, platforms=plats),
            "spool": build_native_spool_fmu(fmu_dir / "native", platforms=plats),
            "wear": build_wear_fmus(fmu_dir / "wear", platforms=plats,
                                    omega0=scenario_settings(True)["spool_params"]["Omega0"]),
            "manoeuvre": build_manoeuvre_fmus(fmu_dir / "manoeuvre", platforms=plats,
                                              omega0=manoeuvre_settings(True)["speed"])}


def start_builds(fmu_dir: str | Path = "fmus", params_file: str | Path | None = None):
    """:func:`build_all` in a background thread, started before the library's analyses: the compilations are
    other processes (ziglang, the C compiler), so they run beside the analyses' Python instead of after them (a
    cold build is half a minute). Returns a future; :func:`run_fmu_part` takes it (``builds=``)."""
    from concurrent.futures import ThreadPoolExecutor

    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="fmu-builds")
    future = pool.submit(build_all, fmu_dir, params_file)
    pool.shutdown(wait=False)
    return future


def run_fmu_part(model, out: str | Path, summary: dict, quick: bool, fmu_dir: str | Path = "fmus",
                 params_file: str | Path | None = None, progress: bool = True, builds=None) -> dict:
    """``{"summary": additions to the summary (harness results, fmu_vs_library_max_rel_diff, coupled_run, ...),
    "markdown": the report's section about them, "verdict": its lines of the main job's verdict}``. ``builds``: a
    :func:`start_builds` future (the FMUs built while the library's analyses ran), else they are built here."""
    from .masters.analyses import compare_flavours, quasi_static_maps, run_up, transient_pair

    out = Path(out)
    with _step(f"the FMUs for this machine (`rotorub build-fmu` builds every platform): pythonfmu into {fmu_dir}/, "
               f"native C into {fmu_dir}/native/, the engine's in {fmu_dir}/wear/, with their cross-check kits"
               + (" (built while the library's analyses ran)" if builds is not None else ""), progress):
        built = builds.result() if builds is not None else build_all(fmu_dir, params_file)
    plats, info_py, info = built["platforms"], built["pythonfmu"], built["native"]
    fmu = info["fmu"]  # the product: the harnesses run it; the pythonfmu one is compared with it below
    res: dict = {"fmu": {"file": fmu, "guid": info["guid"], "platforms": info["platforms"],
                         "variables": info["variables"], "pythonfmu_file": info_py["fmu"]}}

    # sections 4-5 through the FMU: a coarser grid than the library's own maps in --quick
    w = summary["response"]["critical_speeds"][0]
    gmax = 1.6 * summary["response"]["peak_amplitudes_m"][0]
    n_sp, n_g = (20, 16) if quick else (60, 40)
    speeds = np.linspace(max(w - 0.8, 0.05), w + 0.8, n_sp)
    g0s = gmax * np.linspace(0.0, 1.0, n_g) ** 2
    with _step(f"quasi-static sweeps through the FMU ({n_sp} speeds x {n_g} clearances x 2D/3D) vs the library maps",
               progress):
        qs = quasi_static_maps(fmu, model, speeds, g0s, out / "fmu_quasi_static", progress=progress)
        qsum = qs.save(out / "fmu_quasi_static")

    tr = summary["transient"]
    speed, g0 = float(tr["speed"]), float(tr["g0_mm"]) * 1e-3
    t_end = float(tr.get("t_end_s", 20.0))
    with _step(f"section 6 transients through the FMU at speed {speed:.3g}, g0 = {g0 * 1e3:.3g} mm, {t_end:g} s",
               progress):
        pair = transient_pair(fmu, model, speed, g0, out / "fmu_transient", t_end=t_end, progress=progress)
    agree = {f: pair[f]["diverged"] == bool(tr.get(f"diverged_{f.lower()}", pair[f]["diverged"]))
             for f in ("2D", "3D")}
    pair["same_verdict_as_library_study"] = agree

    with _step("run-up through the first critical speed through the FMU (Omega(t) as input)", progress):
        ru = run_up(fmu, model, out / "fmu_run_up", speed_from=max(w - 0.9, 0.1), speed_to=w + 0.9,
                    duration=4.0 if quick else 8.0, progress=progress)

    with _step("the two flavours on the same section-6 scenario (3 s): native vs pythonfmu vs library", progress):
        res["fmu_flavours"] = compare_flavours(fmu, info_py["fmu"], model, speed, g0, out / "fmu_flavours")

    diffs = [pair["2D"]["max_rel_diff_F_N_vs_library"], pair["3D"]["max_rel_diff_F_N_vs_library"],
             ru["max_rel_diff_F_N_vs_library"], ru["max_rel_diff_disk_vs_library"]]
    diffs += [v["max_real_max_rel_diff"] for v in qsum["vs_library"].values()]
    res["harnesses"] = {"quasi_static": qsum, "transient": pair, "run_up": ru}
    res["fmu_vs_library_max_rel_diff"] = float(max(diffs))
    res["fmu_vs_library_note"] = (
        "transients and run-up: max |F_N(FMU) - F_N(library)| / max |F_N(library)| with the library run under "
        "the same zero-order hold (run_transient(hold=h)); quasi-static: max relative difference of the largest "
        "eigenvalue real part over the cells where both found the same contact state (cells on another "
        "branch are counted in harnesses.quasi_static.vs_library)")

    from .systems.coupling import run_coupled_scenario
    from .systems.manoeuvre_scenario import run_manoeuvre_scenario
    from .systems.wear_scenario import run_wear_scenario

    with _step("coupled engine scenario: LP spool FMU + contact FMU, fmpy master loop, SSP file", progress):
        coupled = run_coupled_scenario(out / "coupled", quick=quick, contact_fmu=fmu, spool_fmu=built["spool"],
                                       fmu_dir=fmu_dir, platforms=plats)
    res["coupled_run"] = coupled

    with _step("engine scenario with wear: spool + clearance closure + contact with its abradable liner (SSP, three "
               "masters)", progress):
        wear = run_wear_scenario(out / "coupled_wear", quick=quick, fmus=built["wear"], platforms=plats)
    res["coupled_wear_run"] = {k: v for k, v in wear.items() if k != "figures"}

    with _step("engine scenario with a manoeuvre: a 2.5 g pull-up ovalizes the fan case (CasingLoad FMU), the blades "
               "cut it (SSP, three masters)", progress):
        man = run_manoeuvre_scenario(out / "coupled_manoeuvre", quick=quick, fmus=built["manoeuvre"])
    res["coupled_manoeuvre_run"] = man["summary"]
    if params_file is not None:  # a user's configuration: say what the engine scenarios do not take from it
        res["engine_scenarios_note"] = (
            "the engine scenarios keep their own settings whatever --params says: the coupled run drives this "
            "configuration's contact FMU with the reference's spool schedule (a run-up through the reference's first "
            "critical speed, 186 rad/s); the scenarios with wear and with a manoeuvre run the embedded reference with "
            "its liner on")
    res["figures_extra"] = [
        ("Contact and stability maps through the FMU (quasi-static sweeps)", "fmu_quasi_static/fmu_maps.png"),
        ("Normal contact forces through the FMU, 2D vs 3D (paper Fig. 12)", "fmu_transient/fmu_contact_forces.png"),
        ("Run-up through the first critical speed through the FMU", "fmu_run_up/run_up.png"),
        *[(t, str(Path("coupled") / p)) for t, p in coupled.get("figures", [])],
        *[(t, str(Path("coupled_wear") / p)) for t, p in wear.get("figures", [])],
        *[(t, str(Path("coupled_manoeuvre") / p)) for t, p in man.get("figures", [])],
    ]
    return {"summary": res, "markdown": report_section(res) + man["markdown"], "verdict": verdict_lines(res)}


def verdict_lines(s: dict) -> list[str]:
    """The FMU half's lines of the main job's verdict: the FMU against the library, the two flavours, the engine
    scenarios."""
    lines = [f"FMU checks: native FMU ({', '.join(s['fmu']['platforms'])}) against the library, largest relative "
             f"difference {s['fmu_vs_library_max_rel_diff']:.2g} (transients, run-up, quasi-static maps under the same "
             "held inputs)"]
    fl = s.get("fmu_flavours")
    if fl:
        same = all(fl[f]["bit_identical"] for f in ("2D", "3D"))
        lines.append("  native and pythonfmu FMUs: " + ("the same numbers bit for bit" if same else
                     f"differ by up to {max(fl[f]['native_vs_pythonfmu'] for f in ('2D', '3D')):.2g}"))
    tr = s["harnesses"]["transient"]
    lines.append("  section 6 through the FMU: " + "; ".join(
        f"{f} diverged: {_fmt(tr[f].get('diverged'))} (penetration limit {_fmt(tr[f].get('penetration_limit_hit'))}, "
        f"envelope growing {_fmt(tr[f].get('envelope_growing'))}){_swing(tr[f])}" for f in ("2D", "3D")))
    c = s.get("coupled_run")
    if c:
        lines.append(f"  engine (spool + contact FMUs): the rub costs the spool up to "
                     f"{_fmt(c.get('min_spool_speed_dip_rad_s'))} rad/s, largest contact force "
                     f"{_fmt(c.get('max_contact_force_N'))} N")
    w = s.get("coupled_wear_run")
    if w:
        lines.append(f"  engine with wear: the closing clearance cuts the liner {w['wear_depth_max_mm'] * 1e3:.3g} µm "
                     f"deep; the engine keeps {w['clearance_effective_end_mm']:.4g} mm (fmpy, libcosim, C master "
                     "agree)")
    m = s.get("coupled_manoeuvre_run")
    if m:
        n = m["wear_lobes"]
        lines.append(f"  engine in a {m['load_factor_peak']:g} g pull-up: the ovalized case is cut "
                     f"{m['wear_depth_max_mm'] * 1e3:.3g} µm deep in {n} lobe{'s' if n != 1 else ''}; level flight "
                     f"cuts {m['level_flight_wear_depth_max_mm'] * 1e3:.3g} µm")
    if s.get("engine_scenarios_note"):
        lines.append(f"  note: {s['engine_scenarios_note']}")
    return lines


# ---------------------------------------------------------------------------------------------- the report's section
def _fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.4g}"
    return "–" if v is None else str(v)


_UNITS = {"mm": "mm", "m": "m", "N": "N", "s": "s", "rad_s": "rad/s", "pct": "%", "kg_m": "kg·m", "N_m": "N·m",
          "N_m_s": "N·m·s", "J": "J"}


def _label(key: str) -> str:
    """A summary key as words, its unit suffix in brackets: 'max_friction_torque_N_m' -> 'max friction torque [N·m]'."""
    for suffix, unit in sorted(_UNITS.items(), key=lambda kv: -len(kv[0])):
        if key.endswith("_" + suffix):
            return key[: -len(suffix) - 1].replace("_", " ") + f" [{unit}]"
    return key.replace("_", " ")


def _largest(d: dict | None) -> float | None:
    return None if not d else max(d.values())


def _swing(t: dict) -> str:
    """', not settled: F_N still swings a-b N' for a run whose force still oscillates at its end (a limit cycle: its
    envelope is flat, so 'diverged: no' alone read like a run at rest)."""
    sw = t.get("force_swing_last_s_N")
    # only for a run not called diverged, as the library's verdict: a growing run swings, and says so already
    return f", not settled: F_N still swings {sw[0]:.3g}-{sw[1]:.3g} N" if sw and not t.get("diverged") else ""


def _transient_note(t: dict) -> str:
    """The two meanings of a diverging run apart (as in every JSON): the penetration limit and the growing envelope."""
    g = t.get("envelope_growth") or {}
    grow = "–" if t.get("envelope_growing") is None else _fmt(t.get("envelope_growing"))
    if g.get("factor") is not None:
        grow += f" (×{g['factor']:.3g}, {g['rate_per_s']:+.3g} 1/s)"
    return (f"diverged: {_fmt(t.get('diverged'))} (penetration limit hit: {_fmt(t.get('penetration_limit_hit'))}, "
            f"force envelope growing: {grow}){_swing(t)}, blades at 1 s: {t['blades_in_contact_at_1s']}")


def report_section(s: dict) -> str:
    """The report's markdown about the FMU half's summary ``s`` (what :func:`run_fmu_part` adds to the summary)."""
    h = s["harnesses"]
    tr, ru, qs = h["transient"], h["run_up"], h["quasi_static"]
    rows = [(f"transient {f} (section 6), F_N", tr[f]["max_rel_diff_F_N_vs_library"], _transient_note(tr[f]))
            for f in ("2D", "3D")]
    rows += [
        ("run-up through the first critical, F_N", ru["max_rel_diff_F_N_vs_library"],
         f"peak response at Ω = {_fmt(ru['speed_of_peak_response'])}, max F_N {_fmt(ru['max_normal_force_N'])} N"),
    ]
    for f, v in qs["vs_library"].items():
        rows.append((f"quasi-static map {f}, largest real part", v["max_real_max_rel_diff"],
                     f"{v['cells_same_blades_in_contact']}/{v['cells']} cells same contact state, "
                     f"{v['cells_other_branch']} on another branch, {v['cells_solved_by_one_only']} solved by one "
                     f"side only; same stability verdict in {v['same_stability_verdict_fraction']:.0%}"))
    lines = ["", "## FMU against the library", "",
             f"Largest relative difference: **{s['fmu_vs_library_max_rel_diff']:.2e}** "
             f"({s.get('fmu_vs_library_note', '')}).", "",
             "| harness (through the FMU, fmpy) | max rel. diff vs library | notes |", "|---|---|---|"]
    lines += [f"| {a} | {b:.2e} | {c} |" for a, b, c in rows]
    fl = s.get("fmu_flavours")
    if fl:
        lines += ["", "## The two FMU flavours on the same scenario", "",
                  f"Section-6 point, {fl['t_end_s']:g} s, h = {fl['h_s'] * 1e3:g} ms, inputs held over each step "
                  "(native C FMU, pythonfmu FMU, library `run_transient(hold=h)`).", "",
                  "| formulation | native vs pythonfmu | bit for bit | native vs library | wall time native / "
                  "pythonfmu [s] |", "|---|---|---|---|---|"]
        for f in ("2D", "3D"):
            v = fl[f]
            lines.append(f"| {f} | {v['native_vs_pythonfmu']:.1e} | {v['bit_identical']} | "
                         f"{v['native_vs_library']:.1e} | {v['seconds']['native']:.3f} / "
                         f"{v['seconds']['pythonfmu']:.3f} |")
    c = s.get("coupled_run")
    if c:
        lines += ["", "## Coupled engine scenario (LP spool FMU + contact FMU)", "",
                  "| quantity | value |", "|---|---|"]
        lines += [f"| {_label(k)} | {_fmt(v)} |" for k, v in c.items() if not isinstance(v, dict | list)]
    if s.get("engine_scenarios_note"):
        lines += ["", f"Note: {s['engine_scenarios_note']}."]
    w = s.get("coupled_wear_run")
    if w:
        lines += ["", "## Engine scenario with wear (spool + clearance closure + contact with its liner)", "",
                  f"A run-up through the first critical speed with a quarter of the reference imbalance "
                  f"({w['imbalance_kg_m'] * 1e3:g} kg·mm) and g0 = {w['g0_mm']:g} mm: held at g0 the blades never "
                  f"touch (wear {w['no_closure_wear_depth_max_mm']:g} mm); the engine's closure (up to "
                  f"{w['closure_max_mm']:.3g} mm) makes them rub from t = {_fmt(w['t_first_contact_s'])} s and cut "
                  f"the liner {w['wear_depth_max_mm'] * 1e3:.1f} µm deep ({w['wear_volume_mm3']:.4g} mm³). At the "
                  f"end the engine keeps {w['clearance_effective_end_mm']:.4g} mm where an unworn liner would leave "
                  f"{w['clearance_without_wear_end_mm']:.4g} mm: {w['clearance_penalty_mm'] * 1e3:.1f} µm more, "
                  f"about {w['fuel_burn_penalty_estimate_pct']:.2g} % fuel burn by the rule of thumb "
                  f"({w['fuel_burn_rule']}). The package runs the same in fmpy, in libcosim (largest relative "
                  f"difference {_fmt(_largest(w.get('libcosim_max_rel_diff')))}) and in the C master "
                  f"({_fmt(_largest(w.get('native_host_max_rel_diff')))})."]
    return "\n".join(lines) + "\n"
