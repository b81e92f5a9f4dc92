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

from rotorub_model.results import write_json


def _step(msg: str) -> None:
    print(f"[reproduce] {msg}", flush=True)


def run_fmu_part(model, out: str | Path, summary: dict, quick: bool, fmu_dir: str | Path = "fmus",
                 params_file: str | Path | None = None, progress: bool = True) -> dict:
    """``{"summary": additions to the summary (harness results, fmu_vs_library_max_rel_diff, coupled_run, ...),
    "markdown": the report's section about them}``."""
    from .cli import build
    from .masters.analyses import compare_flavours, quasi_static_maps, run_up, transient_pair

    out = Path(out)
    _step(f"building both FMU flavours (pythonfmu into {fmu_dir}/, native C into {fmu_dir}/native/), with their "
          "cross-check kits")
    info_py = build(fmu_dir, params_file)
    info = build(Path(fmu_dir) / "native", params_file, native=True)
    fmu = info["fmu"]  # the product: the harnesses run it; the pythonfmu one is compared with it below
    res: dict = {"fmu": {"file": fmu, "guid": info["guid"], "platforms": info["platforms"],
                         "variables": info["variables"], "pythonfmu_file": info_py["fmu"]}}

    # sections 4-5 through the FMU: a coarser grid than the library's own maps in --quick
    w = summary["response"]["critical_speeds"][0]
    gmax = 1.6 * summary["response"]["peak_amplitudes_m"][0]
    n_sp, n_g = (20, 16) if quick else (60, 40)
    speeds = np.linspace(max(w - 0.8, 0.05), w + 0.8, n_sp)
    g0s = gmax * np.linspace(0.0, 1.0, n_g) ** 2
    _step(f"quasi-static sweeps through the FMU ({n_sp} speeds x {n_g} clearances x 2D/3D) vs the library maps")
    qs = quasi_static_maps(fmu, model, speeds, g0s, out / "fmu_quasi_static", progress=progress)
    qs.plot(out / "fmu_quasi_static" / "fmu_maps.png")
    qsum = qs.summary()
    write_json(out / "fmu_quasi_static" / "summary.json", qsum)

    tr = summary["transient"]
    speed, g0 = float(tr["speed"]), float(tr["g0_mm"]) * 1e-3
    t_end = float(tr.get("t_end_s", 20.0))
    _step(f"section 6 transients through the FMU at speed {speed:.3g}, g0 = {g0 * 1e3:.3g} mm, {t_end:g} s")
    pair = transient_pair(fmu, model, speed, g0, out / "fmu_transient", t_end=t_end, progress=progress)
    agree = {f: pair[f]["diverged"] == bool(tr.get(f"diverged_{f.lower()}", pair[f]["diverged"]))
             for f in ("2D", "3D")}
    pair["same_verdict_as_library_study"] = agree

    _step("run-up through the first critical speed through the FMU (Omega(t) as input)")
    ru = run_up(fmu, model, out / "fmu_run_up", speed_from=max(w - 0.9, 0.1), speed_to=w + 0.9,
                duration=4.0 if quick else 8.0, progress=progress)

    _step("the two flavours on the same section-6 scenario (3 s): native vs pythonfmu vs library")
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

    _step("coupled engine scenario: LP spool FMU + contact FMU, fmpy master loop, SSP file")
    coupled = run_coupled_scenario(out / "coupled", quick=quick, contact_fmu=fmu, fmu_dir=fmu_dir)
    res["coupled_run"] = coupled

    _step("engine scenario with wear: spool + clearance closure + contact with its abradable liner (SSP, three "
          "masters)")
    wear = run_wear_scenario(out / "coupled_wear", quick=quick, fmu_dir=Path(fmu_dir) / "wear" if fmu_dir else None)
    res["coupled_wear_run"] = {k: v for k, v in wear.items() if k != "figures"}

    _step("engine scenario with a manoeuvre: a 2.5 g pull-up ovalizes the fan case (CasingLoad FMU), the blades cut "
          "it (SSP, three masters)")
    man = run_manoeuvre_scenario(out / "coupled_manoeuvre", quick=quick,
                                 fmu_dir=Path(fmu_dir) / "manoeuvre" if fmu_dir else None)
    res["coupled_manoeuvre_run"] = man["summary"]
    res["figures_extra"] = [
        ("Contact and stability maps through the FMU (quasi-static sweeps)", "fmu_quasi_static/fmu_maps.png"),
        ("Normal contact forces through the FMU, 2D vs 3D (paper Fig. 12)", "fmu_transient/fmu_contact_forces.png"),
        ("Run-up through the first critical speed through the FMU", "fmu_run_up/run_up.png"),
        *[(t, str(Path("coupled") / p)) for t, p in coupled.get("figures", [])],
        *[(t, str(Path("coupled_wear") / p)) for t, p in wear.get("figures", [])],
        *[(t, str(Path("coupled_manoeuvre") / p)) for t, p in man.get("figures", [])],
    ]
    return {"summary": res, "markdown": report_section(res) + man["markdown"]}


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


def report_section(s: dict) -> str:
    """The report's markdown about the FMU half's summary ``s`` (what :func:`run_fmu_part` adds to the summary)."""
    h = s["harnesses"]
    tr, ru, qs = h["transient"], h["run_up"], h["quasi_static"]
    rows = [
        ("transient 2D (section 6), F_N", tr["2D"]["max_rel_diff_F_N_vs_library"],
         f"diverged: {tr['2D']['diverged']}, blades at 1 s: {tr['2D']['blades_in_contact_at_1s']}"),
        ("transient 3D (section 6), F_N", tr["3D"]["max_rel_diff_F_N_vs_library"],
         f"diverged: {tr['3D']['diverged']}, blades at 1 s: {tr['3D']['blades_in_contact_at_1s']}"),
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
