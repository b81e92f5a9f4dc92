"""Markdown report of the main job: the paper's facts, ours, and the figures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

FIGURES = [
    ("Imbalance response at the fan disk (paper Fig. 4)", "response/response.png"),
    ("Campbell diagram, fixed frame", "campbell/campbell.png"),
    ("Contact detection: 3D (dark) and 2D (light, on top) (paper Fig. 5)", "detection/detection_2d_3d.png"),
    ("Full and degraded 3D formulations vs 2D (paper Fig. 6-7)", "detection/detection_variants.png"),
    ("Detection vs cone inclination θ (paper Fig. 8)", "detection/detection_theta.png"),
    ("Detection vs chord length (paper Fig. 9)", "detection/detection_chord.png"),
    ("Static solutions and their stability, 2D and 3D (paper Fig. 10-11)", "stability/stability_maps.png"),
    ("Normal contact forces per blade, 2D vs 3D transient (paper Fig. 12)", "transient/contact_forces.png"),
    ("Continuation: static branches, special points and periodic orbits at the section-6 speed",
     "continuation/continuation.png"),
    ("Stability boundary by continuation over the grid maps", "continuation/boundaries.png"),
    ("Blades' Ritz discretisation: frequency error against the number of functions",
     "discretisation/blade_convergence.png"),
]


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, dict):
        return ", ".join(f"{k}: {_fmt(x)}" for k, x in v.items())
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


def _fmu_section(summary: dict) -> list[str]:
    h = summary["harnesses"]
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
             f"Largest relative difference: **{summary['fmu_vs_library_max_rel_diff']:.2e}** "
             f"({summary.get('fmu_vs_library_note', '')}).", "",
             "| harness (through the FMU, fmpy) | max rel. diff vs library | notes |", "|---|---|---|"]
    lines += [f"| {a} | {b:.2e} | {c} |" for a, b, c in rows]
    fl = summary.get("fmu_flavours")
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
    c = summary.get("coupled_run")
    if c:
        lines += ["", "## Coupled engine scenario (LP spool FMU + contact FMU)", "",
                  "| quantity | value |", "|---|---|"]
        lines += [f"| {k} | {_fmt(v)} |" for k, v in c.items() if not isinstance(v, dict | list)]
    return lines


def _continuation_section(c: dict) -> list[str]:
    lines = ["", "## Continuation: special points, what the instability grows into, the boundary as a curve", "",
             "Static branches in g0 at the section-6 speed (pseudo-arclength through contact events), their Hopf, "
             "fold and contact-induced switch points, the periodic orbits past them (shooting with the transient "
             "kernel, Floquet multipliers), and the stability boundary traced as curves over the grid maps "
             "(`rotorub continuation`; `continuation/continuation.png`, `continuation/boundaries.png`).", "",
             "| formulation | special points (kind @ g0 mm: Re, Im of the critical eigenvalue) | orbits | boundary "
             "curves (points) | grid cells contradicting the curves (beyond one cell) |",
             "|---|---|---|---|---|"]
    for f in ("2D", "3D"):
        if f not in c:
            continue
        sp = "; ".join(f"{s['kind']} @ {s['g0_m'] * 1e3:.6g}: {_fmt(s.get('critical_eigenvalue', ''))}"
                       for s in c[f]["specials"]) or "none"
        b = c[f]["boundary"]
        lines.append(f"| {f} | {sp} | {c[f]['orbits']} | {b.get('curves')} ({b.get('points')}) | "
                     f"{b.get('contradicting_cells', '?')} ({b.get('contradicting_beyond_one_cell', '?')}, "
                     f"{100 * b.get('contradicting_beyond_one_cell_fraction', float('nan')):.1f} %) |")
    return lines


def _discretisation_section(d: dict) -> list[str]:
    n = d["n_ritz_of_the_model"]
    lo, hi = d["model_blade_hz_converged_at_rest_and_top"]
    return [
        "", "## What the blades' discretisation costs", "",
        f"The model's blades bend on {n} polynomial Ritz functions (the paper's choice). Against a converged "
        f"reference (8 functions), the first bending frequency of the reference blade ({lo:.1f} Hz at rest, "
        f"{hi:.1f} Hz at the top of the speed range) is {100 * d['model_blade_error_at_rest']:.2f} % high at rest "
        f"and up to {100 * d['model_blade_max_error']:.1f} % high at {d['model_blade_max_error_at_rad_s']:.0f} rad/s "
        "(spin softening of its in-plane share is what few functions miss). The uniform rotating cantilever of "
        "the literature, first flap and lag frequency error against the number of functions "
        "(mu = Omega / sqrt(EI / rho A l^4)):", "",
        d["table_markdown"], "",
        "The blades' `n_ritz` is a parameter (see the figure below and docs/THEORY.md).",
    ]


def write_report(out: str | Path, summary: dict) -> Path:
    """Write out/report.md from the main job's summary (figures by relative path)."""
    out = Path(out)
    lines = [
        "# rotorub — reproduction of Parent, Thouverez & Chevillot (EURODYN 2014)",
        "",
        f"Model: {summary['n_dofs']} dofs, Ω_ref = {summary['omega_ref_rad_s']:g} rad/s "
        "(speeds below are Ω / Ω_ref). Parameters: `rotorub_model/data/reference.toml` unless "
        "another file was given.",
        "",
        "## The paper's facts",
        "",
        "| fact | statement | paper | ours | holds |",
        "|---|---|---|---|---|",
    ]
    for f in summary["paper_facts"]:
        ours = {k: v for k, v in f["ours"].items() if not isinstance(v, dict | list) or len(str(v)) < 200}
        cells = [str(f["id"]), f["statement"], _fmt(f["paper"]), _fmt(ours)]
        cells = [c.replace("|", "\\|") for c in cells]  # a pipe inside a cell would split it
        lines.append("| " + " | ".join(cells) + f" | {'**yes**' if f['holds'] else '**NO**'} |")
    failing = [f for f in summary["paper_facts"] if not f["holds"]]
    lines += ["", "## What does not hold, and why", ""]
    if not failing:
        lines.append("Every fact holds on this configuration.")
    for f in failing:
        lines.append(f"* Fact {f['id']}: {f.get('why', 'see the values in the table and docs/THEORY.md')}")
    if "continuation" in summary:
        lines += _continuation_section(summary["continuation"])
    if "blade_discretisation" in summary:
        lines += _discretisation_section(summary["blade_discretisation"])
    if "harnesses" in summary:
        lines += _fmu_section(summary)
    lines += ["", "## Figures", ""]
    for title, rel in [*FIGURES, *[tuple(x) for x in summary.get("figures_extra", [])]]:
        if (out / rel).exists():
            lines += [f"### {title}", "", f"![{title}]({rel})", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path
