"""The main job: reproduce the paper's analyses on a configuration and summarise them.

Each analysis writes its PNG/JSON into its own sub-folder of ``out``; the summary
gathers the paper's facts (MODEL-NOTES section 4) with our values and whether
they hold.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

from ..facts import FINDING, ROTOR, condition, with_conditions  # noqa: F401
from ..structure.model import Model
from ..writing import write_json


def fact1(resp: dict) -> dict:
    c = resp["critical_speeds"]
    a = resp["peak_amplitudes_m"]
    ratio = a[0] / a[1] if len(a) > 1 and a[1] > 0 else None
    f = {
        "id": 1,
        "statement": "two critical speeds in 0 < Omega <= 10, near 3.5 and 8, first peak > 5x the second",
        "paper": {"critical_speeds": [3.5, 8.0], "peak_ratio_min": 5.0},
        "ours": {"critical_speeds": c, "peak_ratio": ratio},
    }
    speeds = ", ".join(f"{x:.3g}" for x in c) or "none"
    return with_conditions(f, [
        condition("two critical speeds in (0, 10]", len(c) == 2, f"{len(c)} ({speeds})", ROTOR),
        condition("the first within 0.2 of 3.5", len(c) >= 1 and abs(c[0] - 3.5) <= 0.2,
                  f"{c[0]:.3g}" if c else "none", ROTOR),
        condition("the second within 0.5 of 8", len(c) >= 2 and abs(c[1] - 8.0) <= 0.5,
                  f"{c[1]:.3g}" if len(c) > 1 else "none", ROTOR),
        condition("the first peak at least 5 x the second", ratio is not None and ratio >= 5.0,
                  "–" if ratio is None else f"{ratio:.3g} x", ROTOR),
    ])


def fact5(stab: dict) -> dict:
    from ..analyses.maps import STABLE_STRIP_MIN

    u2, u3 = stab["unstable_fraction_2d"], stab["unstable_fraction_3d"]
    m3 = stab["map_3d"]
    b3 = m3["boundary_stable_fraction"]
    f = {
        "id": 5,
        "statement": "static solutions: 2D unstable over almost the whole contact area; 3D a smaller unstable "
                     "fraction with a stable strip around the unstable area",
        "paper": {"unstable_fraction_2d": "almost all", "unstable_fraction_3d": "smaller", "stable_strip_3d": True},
        "ours": {"unstable_fraction_2d": u2, "unstable_fraction_3d": u3, "stable_strip_3d": stab["stable_strip_3d"],
                 "boundary_stable_fraction_3d": b3,
                 "boundary_stable_cells_3d": m3.get("boundary_stable_cells"),
                 "boundary_cells_3d": m3.get("boundary_cells"),
                 "max_blades_in_contact": [stab["max_blades_in_contact_2d"], stab["max_blades_in_contact_3d"]]},
    }
    strip = ("no contact region with a free neighbour: no boundary to be stable" if b3 is None else
             f"{b3:.1%} of the 3D contact region's boundary stable, by area ({m3.get('boundary_stable_cells', '?')} of "
             f"its {m3.get('boundary_cells', '?')} boundary cells; stability/stability_maps.png shows where)")
    return with_conditions(f, [
        condition("2D unstable over almost all the contact area (>= 80 %)", u2 >= 0.8, f"{u2:.0%}"),
        condition("3D unstable over a smaller fraction than 2D", u3 < u2, f"{u3:.0%} against {u2:.0%}"),
        condition(f"a stable strip around the 3D unstable area (>= {STABLE_STRIP_MIN:.0%} of its boundary stable)",
                  stab["stable_strip_3d"], strip),
    ])


def fact6(tr: dict) -> list[dict]:
    pf = tr["partial_chord_fraction_3d"]
    a = {
        "id": "6a",
        "statement": "transient at a point with unstable 2D / stable 3D static solutions: 2D diverges after the "
                     "ramp, 3D settles on its static solution; three blades touch at 1 s, the third one, in "
                     "the 3D state reached, only partly along its chord",
        "paper": {"speed": 3.3, "g0_mm": 0.8, "blades_at_1s": 3, "partial_chord_fraction_3d": 0.88},
        "ours": {k: tr[k] for k in ("speed", "g0_mm", "diverged_2d", "settled_3d", "blades_in_contact_2d_at_1s",
                                    "blades_in_contact_3d_at_1s", "partial_chord_fraction_3d")},
    }
    v2 = (tr.get("verdicts") or {}).get("2D", "")
    a = with_conditions(a, [
        condition("the 2D run diverges after the ramp", tr["diverged_2d"] is True,
                  v2 or ("no verdict" if tr["diverged_2d"] is None else "not diverging")),
        condition("the 3D run settles on its static solution", tr["settled_3d"],
                  "settled" if tr["settled_3d"] else "not settled"),
        condition("three blades touch at 1 s in 2D", tr["blades_in_contact_2d_at_1s"] == 3,
                  f"{tr['blades_in_contact_2d_at_1s']}", ROTOR),
        condition("three blades touch at 1 s in 3D", tr["blades_in_contact_3d_at_1s"] == 3,
                  f"{tr['blades_in_contact_3d_at_1s']}", ROTOR),
        condition("the third 3D blade touches only partly along its chord (paper: 88 %)", 0 < pf < 1,
                  f"{pf:.0%} of its chord", ROTOR),
    ])
    f = tr["max_force_at_1s_N"]
    b = {
        "id": "6b",
        "statement": "at 1 s the 3D contact force is larger than the 2D one (stability is not set by force amplitude)",
        "paper": {"force_3d_gt_2d": True},
        "ours": {"max_force_at_1s_N": f},
    }
    b = with_conditions(b, [condition("the largest 3D normal force at 1 s above the 2D one", f["3D"] > f["2D"],
                                      f"{f['3D']:.1f} N (3D) against {f['2D']:.1f} N (2D)")])
    if not b["holds"]:
        b["note"] = ("the 3D stability at this point comes from the partly touching chord, not from a larger force. "
                     "Friction against the sliding velocity does not change this: at the fact-6 speed the tips slide "
                     "at about 1000 times contact.slip_velocity, where the law is the same Coulomb friction as before "
                     "(docs/THEORY.md section 6)")
    return [a, b]


def parameter_source(model: Model, params_file: str | Path | None = None) -> dict:
    """What the run was computed from: the parameter file and the sha256 of its bytes, or the embedded
    reference and the sha256 of its TOML; and, either way, the sha256 of the parameter values themselves
    (canonical JSON: two files differing in comments only give the same one)."""
    from ..structure.params import REFERENCE_FILE, load_parameters, reference_parameters, to_dict

    values = hashlib.sha256(json.dumps(to_dict(model.params), sort_keys=True).encode()).hexdigest()
    if params_file is not None:
        path = Path(params_file)
        return {"source": str(path), "absolute_path": str(path.resolve()),
                "sha256": hashlib.sha256(path.read_bytes()).hexdigest(), "sha256_of": "the file",
                "values_sha256": values, "file_matches_model": load_parameters(path) == model.params}
    if model.params == reference_parameters():
        return {"source": "embedded reference", "absolute_path": str(REFERENCE_FILE),
                "sha256": hashlib.sha256(REFERENCE_FILE.read_bytes()).hexdigest(),
                "sha256_of": "the embedded reference TOML, rotorub_model/data/reference.toml", "values_sha256": values}
    # parameters built in memory (or a file whose path the caller did not pass): only the values identify them
    return {"source": "parameters given in memory (no file path passed)", "absolute_path": None, "sha256": values,
            "sha256_of": "the canonical JSON of the parameter values", "values_sha256": values}


def run_inputs(model: Model, params_file: str | Path | None, quick: bool, det: dict, stab: dict,
               sizes: dict) -> dict:
    """The inputs record of the summary and the report: parameters, grids, package version."""
    import numpy
    import scipy

    from .. import __version__

    g = stab["grid"]
    return {
        "parameters": parameter_source(model, params_file),
        "grid": {
            "mode": "quick" if quick else "full",
            "response_speeds": sizes["response"],
            "campbell_speeds": sizes["campbell"],
            "detection": {"n_speeds": det["n_speeds"], "speed_range": det["speed_range"], "n_g0": det["n_g0"],
                          "g0_range_mm": det["g0_range_mm"]},
            "stability_maps": {"n_speeds": g["speeds"][2], "speed_range": g["speeds"][:2], "n_g0": g["g0_mm"][2],
                               "g0_range_mm": g["g0_mm"][:2],
                               "g0_spacing": "quadratic (denser at small g0)" if quick else "uniform"},
            "blade_discretisation_speeds": sizes["discretisation"],
            "transient_t_end_s": sizes["transient_t_end_s"],
            "continuation": "quick (fewer orbits per branch)" if quick else "full",
        },
        "package_version": __version__,
        "library_versions": {"numpy": numpy.__version__, "scipy": scipy.__version__},
    }


def imported_blade_summary(model: Model) -> dict:
    """What an imported blade ([fe_blade], docs/THEORY.md 9) brings to the run: its superelement, its reduced dofs,
    its clamped frequencies at rest and at the top speed, its tip's stations and chord."""
    from ..contact import make_contact

    b = model.fe_blade
    top = model.params.normalisation.speed_max * model.params.normalisation.omega_ref
    c = make_contact(model, "3D")
    return {"superelement": model.params.fe_blade.superelement, "dofs_per_blade": b.m, "mass_kg": b.mass,
            "clamped_frequencies_at_rest_hz": b.frequencies(0.0)[:6].tolist(),
            "clamped_frequencies_at_top_speed_hz": b.frequencies(top)[:6].tolist(), "top_speed_rad_s": top,
            "tip_stations": int(c.n_rows), "tip_chord_m": float(c.geometry.chord),
            "note": "the paper's beam studies (degraded 3D variants, chord sweep, the blades' Ritz discretisation) "
                    "are not run on an imported blade"}


def run_reproduce(model: Model, out: str | Path, quick: bool = False, params_file: str | Path | None = None,
                  progress: bool = True) -> dict:
    """Every analysis of the paper on ``model``; ``params_file``: the file it was loaded from (recorded with
    its hash in the summary and the report; None: the embedded reference, or parameters built in memory).
    ``progress``: each stage announced on stderr with its time, a heartbeat when one runs long, the loops' bars."""
    from ..analyses.linear import run_campbell, run_modes, run_response
    from ..progress import stage

    out = Path(out)
    sizes = {"response": 600 if quick else 2000, "campbell": 400,
             "discretisation": 13 if quick else 41, "transient_t_end_s": 20.0}
    timings: dict[str, float] = {}

    def step(name: str, what: str):
        return _timed(stage(what, progress), timings, name)

    with step("linear", "imbalance response, modes at the first critical, Campbell diagram"):
        resp = run_response(model, n_speeds=sizes["response"]).save(out / "response")
        run_modes(model, resp["critical_speeds"][0]).save(out / "modes")
        run_campbell(model, n_speeds=sizes["campbell"]).save(out / "campbell")
    from ..analyses.detection import paper_facts as detection_facts
    from ..analyses.detection import run_detection

    with step("detection", "contact detection maps: 2D, 3D, degraded 3D, θ and chord sweeps"):
        det = run_detection(model, n_speeds=200 if quick else 400, progress=progress).save(out / "detection")
    from ..analyses.discretisation import run_blade_convergence
    from .studies import run_stability_study, run_transient_study

    disc_summary = None
    if model.fe_blade is None:  # the built-in blades' Ritz functions (an imported blade's basis: its import's)
        with step("discretisation", "what the blades' Ritz functions cost (frequency errors against n_ritz)"):
            disc = run_blade_convergence(model.params, n_speeds=sizes["discretisation"])
            disc_summary = disc.save(out / "discretisation")
            disc_summary["table_markdown"] = disc.table_markdown()
    with step("stability", "static and stability maps over (speed, g0), 2D and 3D"):
        stab = run_stability_study(model, out / "stability", quick=quick, progress=progress)
    with step("transient", "section 6: 2D and 3D transients at a point with an unstable 2D and a stable 3D "
                           "static solution"):
        tr = run_transient_study(model, out / "transient", stab_dir=out / "stability",
                                 t_end=sizes["transient_t_end_s"], progress=progress)
    from .studies import run_wear_study

    # the same rub against an abradable liner (the parameter file's, worn): what it leaves behind
    with step("wear", "the same rub against the abradable liner, 2D and 3D"):
        wear = run_wear_study(model, out / "wear", tr["speed"], tr["g0_mm"] * 1e-3, t_end=sizes["transient_t_end_s"],
                              progress=progress)
    from .studies import run_continuation_study

    with step("continuation", "continuation: branches, special points, orbits, boundary curves"):
        # at the section-6 point's speed, so that the branches explain the transients the report shows there (on
        # a configuration where the transient study picks another speed than the paper's, the two used to differ
        # with nothing to say why)
        cont = run_continuation_study(model, out / "continuation", speed=tr["speed"], maps_dir=out / "stability",
                                      quick=quick, progress=progress,
                                      speed_source=f"the section-6 transients' speed ({tr['point']['source']})")
    sections = []
    with step("forced_response", "forced response of an oval casing (harmonic balance, quick)"):
        from .forced_response import run_forced_quick

        _, md = run_forced_quick(model, out / "forced_response")
        sections.append(_section_file(out, "forced_response", md))
    with step("uncertainty", "will it rub? the quick uncertainty studies (tolerances, mistuning)"):
        from ..uncertainty.quick import run_uq_quick

        _, md = run_uq_quick(model, out / "uq", progress=progress)
        sections.append(_section_file(out, "uq", md))
    summary = {
        "inputs": run_inputs(model, params_file, quick, det, stab, sizes),
        "n_dofs": model.n_dofs,
        "omega_ref_rad_s": model.params.normalisation.omega_ref,
        "response": resp,
        "detection": det,
        "stability": {k: v for k, v in stab.items() if not k.startswith("map_")},
        "transient": tr,
        "wear": wear,
        **({"blade_discretisation": disc_summary} if disc_summary is not None else
           {"imported_blade": imported_blade_summary(model)}),
        "continuation": cont,
        "paper_facts": [fact1(resp), *detection_facts(det), fact5(stab), *fact6(tr)],
        "report_sections": sections,
        "timings_s": timings,
    }
    write_json(out / "summary.json", summary)
    from .report import write_report

    write_report(out, summary)
    return summary


def _section_file(out: Path, folder: str, markdown: str) -> str:
    """A report section another analysis wrote, kept next to its files (the report reads it back by this path;
    figure links made relative to ``out``)."""
    import re

    md = re.sub(r"\]\((?!https?:|/)([^)]+)\)", lambda m: f"]({folder}/{m.group(1)})"
                if not m.group(1).startswith(folder + "/") else m.group(0), markdown)
    (out / folder).mkdir(parents=True, exist_ok=True)
    (out / folder / "report_section.md").write_text(md + "\n")
    return f"{folder}/report_section.md"


class _timed:
    """A stage's context, its wall time kept in ``timings[name]``."""

    def __init__(self, ctx, timings: dict, name: str):
        self.ctx, self.timings, self.name = ctx, timings, name

    def __enter__(self):
        import time

        self.t0 = time.perf_counter()
        return self.ctx.__enter__()

    def __exit__(self, *exc):
        import time

        self.timings[self.name] = round(time.perf_counter() - self.t0, 2)
        return self.ctx.__exit__(*exc)


def main_job_verdict(s: dict, out: str | Path, fmu_lines: list[str], fmu: bool = True) -> list[str]:
    """What the main job ends with: the facts that hold (and, for each that does not, its failed conditions), the
    FMU checks (the FMU half's own lines), where the report is."""
    out = Path(out)
    facts = s["paper_facts"]
    ok = [f for f in facts if f["holds"]]
    p = s["inputs"]["parameters"]["source"]
    lines = [f"Main job on {p} ({s['inputs']['grid']['mode']} grids): {len(ok)} of {len(facts)} paper facts hold"
             + (f" ({', '.join(str(f['id']) for f in ok)})" if ok and len(ok) < len(facts) else "") + "."]
    for f in facts:
        if not f["holds"]:
            failed = [c for c in f.get("conditions", []) if not c["holds"]]
            rotor = all(c["kind"] == "the paper's rotor" for c in failed) and failed
            # "expected ...: ours ..." and not "<condition> (ours ...)": the condition is the paper's claim, and
            # "the largest 3D normal force at 1 s above the 2D one (ours 166 N (3D) against 178 N (2D))" read as
            # the reason it failed
            lines.append(f"  fact {f['id']} does not hold: " + "; ".join(f"expected {c['condition']}, ours {c['ours']}"
                                                                        for c in failed)
                         + (" - numbers of the paper's rotor, not a defect of this configuration" if rotor else ""))
    # what the section-6 study said about its own runs (a law's knee one of them never reached, a point whose 2D
    # instability the run may not show): in the study's JSON and on stderr only, so a main job's reader missed it
    tr = s.get("transient") or {}
    for note in (tr.get("verdict_note"), (tr.get("point") or {}).get("note")):
        if note:
            lines.append(f"  section-6 transients: {note}")
    if fmu:
        lines += fmu_lines or ["FMU checks: none reported"]
    else:
        lines.append("FMUs: not built (--no-fmu)")
    lines.append(f"report: {out / 'report.md'}; summary: {out / 'summary.json'}; figures in {out}/*/")
    return lines
