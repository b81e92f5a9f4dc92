"""The FMU half of ``rotorub reproduce``: build the FMUs, run the harnesses and the coupled
engine scenario, and add their results to the library's summary and report.

Called by :func:`rotorub_model.app.cli.cmd_reproduce` after the library analyses (whose
summary gives the transient point and the stability grid to compare with).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotorub_model.results import write_json


def _step(msg: str) -> None:
    print(f"[reproduce] {msg}", flush=True)


def run_fmu_part(model, out: str | Path, summary: dict, quick: bool, fmu_dir: str | Path = "fmus",
                 params_file: str | Path | None = None, progress: bool = True) -> dict:
    """Returns the additions to the summary: harness results, fmu_vs_library_max_rel_diff, coupled_run."""
    from ..build.commands import build
    from .analyses import quasi_static_maps, run_up, transient_pair

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

    try:
        from ..engine.coupling import run_coupled_scenario
    except ImportError as exc:  # the engine coupling is part of the package; say so if it is broken
        raise RuntimeError(f"fmu_src.engine.coupling is not importable: {exc}") from exc
    _step("coupled engine scenario: LP spool FMU + contact FMU, fmpy master loop, SSP file")
    coupled = run_coupled_scenario(out / "coupled", quick=quick, contact_fmu=fmu, fmu_dir=fmu_dir)
    res["coupled_run"] = coupled
    from ..engine.wear_scenario import run_wear_scenario

    _step("engine scenario with wear: spool + clearance closure + contact with its abradable liner (SSP, three "
          "masters)")
    wear = run_wear_scenario(out / "coupled_wear", quick=quick, fmu_dir=Path(fmu_dir) / "wear" if fmu_dir else None)
    res["coupled_wear_run"] = {k: v for k, v in wear.items() if k != "figures"}
    res["figures_extra"] = [
        ("Contact and stability maps through the FMU (quasi-static sweeps)", "fmu_quasi_static/fmu_maps.png"),
        ("Normal contact forces through the FMU, 2D vs 3D (paper Fig. 12)", "fmu_transient/fmu_contact_forces.png"),
        ("Run-up through the first critical speed through the FMU", "fmu_run_up/run_up.png"),
        *[(t, str(Path("coupled") / p)) for t, p in coupled.get("figures", [])],
        *[(t, str(Path("coupled_wear") / p)) for t, p in wear.get("figures", [])],
    ]
    return res


def compare_flavours(native: str | Path, pythonfmu: str | Path, model, speed: float, g0: float, out: str | Path,
                     t_end: float = 3.0, h: float = 1e-3) -> dict:
    """2D and 3D transients at (speed, g0) through both flavours and in the library (same held inputs):
    max |F_N difference| / max |F_N| of each pair, and whether the two FMUs agree bit for bit."""
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact

    from .analyses import _extract, _rel_diff, run_fmu_transient

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
