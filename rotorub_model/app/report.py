"""Markdown report of the main job: the paper's facts, ours, and the figures."""

from __future__ import annotations

from pathlib import Path
from typing import Any

FIGURES = [
    ("Imbalance response at the fan disk (paper Fig. 4)", "response/response.png"),
    ("Campbell diagram, fixed frame", "campbell/campbell.png"),
    ("Contact detection: 2D (orange) and 3D (hatched, drawn over it) (paper Fig. 5)",
     "detection/detection_2d_3d.png"),
    ("Full and degraded 3D formulations vs 2D (paper Fig. 6-7)", "detection/detection_variants.png"),
    ("Detection vs cone inclination θ (paper Fig. 8)", "detection/detection_theta.png"),
    ("Detection vs chord length (paper Fig. 9)", "detection/detection_chord.png"),
    ("Static solutions and their stability, 2D and 3D (paper Fig. 10-11)", "stability/stability_maps.png"),
    ("Normal contact forces per blade, 2D vs 3D transient (paper Fig. 12)", "transient/contact_forces.png"),
    ("Wear map: the same rub against an abradable liner, 3D (depth over angle and time)", "wear/3D/wear_map.png"),
    ("Worn profile after the rub, 3D: unrolled, polar, spectrum", "wear/3D/wear_profile.png"),
    ("Worn profile after the rub, 2D", "wear/2D/wear_profile.png"),
    ("Continuation: static branches, special points and periodic orbits at the section-6 speed",
     "continuation/continuation.png"),
    ("Stability boundary by continuation over the grid maps", "continuation/boundaries.png"),
    ("Blades' Ritz discretisation: frequency error against the number of functions",
     "discretisation/blade_convergence.png"),
    ("Will it rub? The rub probability against the build clearance (quick study)",
     "uq/tolerances/uq_rub_vs_clearance.png"),
    ("Mistuned disks: contact against linear amplification (quick study)", "uq/mistuning/uq_mistuning.png"),
]


def _fmt(v: Any) -> str:
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, dict):
        return ", ".join(f"{_label(k)} {_fmt(x)}" for k, x in v.items())
    if isinstance(v, list):
        return ", ".join(_fmt(x) for x in v)
    return "–" if v is None else str(v)


_UNITS = {"mm": "mm", "m": "m", "N": "N", "s": "s", "rad_s": "rad/s", "hz": "Hz", "Hz": "Hz", "deg": "°", "pct": "%",
          "kg_m": "kg·m", "N_m": "N·m", "N_m_s": "N·m·s", "J": "J", "W": "W"}


def _label(key: str) -> str:
    """A summary key as words, its unit suffix in brackets: 'max_normal_force_N' -> 'max normal force [N]'."""
    for suffix, unit in sorted(_UNITS.items(), key=lambda kv: -len(kv[0])):
        if key.endswith("_" + suffix):
            return key[: -len(suffix) - 1].replace("_", " ") + f" [{unit}]"
    return key.replace("_", " ")


def _mm(x: Any) -> str:
    return "–" if x is None else f"{x:.3g} mm"


def _pct(x: Any) -> str:
    return "–" if x is None else f"{100 * x:.1f} %"


def _yes(b: Any) -> str:
    return "–" if b is None else ("yes" if b else "no")


def _speeds(v: Any) -> str:
    return "–" if v is None else ", ".join(f"{x:.3g}" for x in (v if isinstance(v, list) else [v]))


def _by(d: dict, unit: str) -> str:
    """{'0': 5.63, '5': 6.27} -> '0 → 5.63, 5 → 6.27' (sweep value → closure)."""
    return ", ".join(f"{k}{unit} → {v:.3g}" for k, v in d.items())


def _describe_1(o: dict) -> str:
    r = o.get("peak_ratio")
    return (f"critical speeds at Ω = {_speeds(o.get('critical_speeds'))}; first peak "
            f"{'–' if r is None else f'{r:.3g} ×'} the second")


def _describe_2(o: dict) -> str:
    at = o.get("speed_of_max_closure") or {}
    return (f"contact at g0 = 0 at every speed: {_yes(o.get('contact_at_every_speed_at_g0_zero'))}; largest closure at "
            f"Ω = {_speeds(at.get('2D'))} (2D, {_mm(o.get('closure_2d_max_mm'))}) and {_speeds(at.get('3D'))} "
            f"(3D, {_mm(o.get('closure_3d_max_mm'))}), first critical {_speeds(o.get('first_critical_speed'))}; "
            f"3D map contains the 2D map: {_yes(o.get('map_3d_contains_2d'))}; 3D − 2D at the first critical "
            f"{_mm(o.get('closure_diff_3d_2d_at_first_critical_mm'))}")


def _describe_3(o: dict) -> str:
    return (f"largest |closure − 2D closure| over the speeds: kinematics only {_mm(o.get('kinematics_only_mm'))}, "
            f"geometry only {_mm(o.get('geometry_only_mm'))}, full 3D {_mm(o.get('full_3d_mm'))}")


def _describe_4(o: dict) -> str:
    d = o.get("defaults") or {}
    chord = d.get("chord")
    return (f"largest closure against θ (°, chord {'–' if chord is None else f'{chord * 100:g} cm'}): "
            f"{_by(o.get('theta_sweep_max_mm', {}), '°')} mm, a spread of {_mm(o.get('theta_range_mm'))}; against "
            f"l_c (cm, θ = {d.get('theta_deg', '–')}°): {_by(o.get('chord_sweep_max_mm', {}), ' cm')} mm, a spread "
            f"of {_mm(o.get('chord_range_mm'))}; detection area grows with θ: {_yes(o.get('theta_area_monotone'))}, "
            f"with l_c: {_yes(o.get('chord_area_monotone'))}; each map inside the next at every speed: θ "
            f"{_yes(o.get('theta_nested_every_speed'))}, l_c {_yes(o.get('chord_nested_every_speed'))}")


def _describe_5(o: dict) -> str:
    nb = o.get("max_blades_in_contact") or [None, None]
    return (f"unstable over {_pct(o.get('unstable_fraction_2d'))} of the 2D contact area and "
            f"{_pct(o.get('unstable_fraction_3d'))} of the 3D one; stable strip in 3D: "
            f"{_yes(o.get('stable_strip_3d'))} "
            f"({_pct(o.get('boundary_stable_fraction_3d'))} of the 3D contact region's boundary stable, by area; "
            f"{_cells(o)}); at most "
            f"{nb[0]} (2D) and {nb[1]} (3D) blades in contact")


def _cells(o: dict) -> str:
    k, n = o.get("boundary_stable_cells_3d"), o.get("boundary_cells_3d")
    return "boundary cells not counted" if k is None or n is None else f"{k} of its {n} boundary cells"


def _describe_6a(o: dict) -> str:
    pf = o.get("partial_chord_fraction_3d")
    return (f"at Ω = {_speeds(o.get('speed'))}, g0 = {_mm(o.get('g0_mm'))}: 2D diverged: {_yes(o.get('diverged_2d'))}, "
            f"3D settled on its static solution: {_yes(o.get('settled_3d'))}; blades touching at 1 s: "
            f"{o.get('blades_in_contact_2d_at_1s', '–')} (2D), {o.get('blades_in_contact_3d_at_1s', '–')} (3D); "
            f"the partly touching 3D blade's chord in contact: {_pct(pf)}")


def _describe_6b(o: dict) -> str:
    f = o.get("max_force_at_1s_N") or {}
    nan = float("nan")
    return f"largest normal force at 1 s: {f.get('2D', nan):.1f} N (2D), {f.get('3D', nan):.1f} N (3D)"


_DESCRIBE = {"1": _describe_1, "2": _describe_2, "3": _describe_3, "4": _describe_4, "5": _describe_5,
             "6a": _describe_6a, "6b": _describe_6b}


def _describe_paper(f: dict) -> str:
    p = f.get("paper", {})
    kind = str(f["id"])
    if kind == "1":
        return (f"critical speeds near {_speeds(p.get('critical_speeds'))}; first peak > {p.get('peak_ratio_min')} × "
                "the second")
    if kind == "2":
        return (f"largest closure near Ω = {p.get('speed_of_max_closure')}; 3D − 2D ≈ "
                f"{_mm(p.get('closure_diff_3d_2d_mm'))} at the first critical")
    if kind == "3":
        return f"each degraded 3D within {_mm(p.get('max_diff_mm'))} of 2D"
    if kind == "4":
        d = p.get("defaults", {})
        return f"defaults θ = {d.get('theta_deg')}°, l_c = {100 * d.get('chord_m', 0):g} cm; θ matters more"
    if kind == "5":
        return "2D unstable almost everywhere; 3D less, a stable strip around the unstable area"
    if kind == "6a":
        return (f"Ω = {p.get('speed')}, g0 = {_mm(p.get('g0_mm'))}: 2D diverges, 3D settles; {p.get('blades_at_1s')} "
                f"blades at 1 s, the third over {_pct(p.get('partial_chord_fraction_3d'))} of its chord")
    if kind == "6b":
        return "3D force at 1 s larger than 2D"
    return _fmt(p)


def describe_ours(f: dict) -> str:
    """The 'ours' values of a paper fact as a sentence (a fact of unknown id: its values labelled in words)."""
    d = _DESCRIBE.get(str(f["id"]))
    return d(f["ours"]) if d else _fmt(f["ours"])


def _inputs_section(summary: dict) -> list[str]:
    inp = summary.get("inputs")
    if not inp:
        return ["", "Inputs: not recorded (a summary written before the inputs were)."]
    p, g = inp["parameters"], inp["grid"]
    src = p["source"] if p["source"] == "embedded reference" else f"`{p['source']}`"
    if p.get("file_matches_model") is False:
        src += " (**its values differ from the model's**)"
    det, st = g["detection"], g["stability_maps"]
    grid = (f"**{g['mode']}**: response {g['response_speeds']} speeds, Campbell {g['campbell_speeds']}; detection "
            f"{det['n_speeds']} speeds (Ω {det['speed_range'][0]:.3g}–{det['speed_range'][1]:.3g}) × {det['n_g0']} "
            f"clearances; stability maps {st['n_speeds']} speeds (Ω {st['speed_range'][0]:.3g}–"
            f"{st['speed_range'][1]:.3g}) × {st['n_g0']} clearances (0–{st['g0_range_mm'][1]:.3g} mm, "
            f"{st['g0_spacing']}); blade discretisation {g['blade_discretisation_speeds']} speeds; transients "
            f"{g['transient_t_end_s']:g} s; continuation {g['continuation']}")
    libs = ", ".join(f"{k} {v}" for k, v in inp.get("library_versions", {}).items())
    return ["", "## Inputs", "", "| input | value |", "|---|---|",
            f"| parameters | {src} |",
            f"| sha256 | `{p['sha256']}` ({p['sha256_of']}) |",
            f"| sha256 of the parameter values | `{p['values_sha256']}` (canonical JSON: the same for files that "
            "differ in comments only) |",
            f"| grid | {grid} |",
            f"| package | rotorub_model {inp['package_version']}" + (f" ({libs})" if libs else "") + " |"]


def _wear_section(w: dict) -> list[str]:
    lines = ["", "## The section-6 rub against an abradable liner", "",
             f"Not in the paper (its casing is rigid): the same transient at Ω = {w['speed']:.4g}, g0 = "
             f"{w['g0_mm']:.4g} mm against the parameter file's liner, worn (docs/THEORY.md, \"Abradable liner\").",
             "", "| formulation | deepest wear | mean wear | volume removed | plastic work | lobes | clearance "
             "before → after |", "|---|---|---|---|---|---|---|"]
    for f in ("2D", "3D"):
        s = w.get(f)
        if not s:
            continue
        lobes = s["lobes"] if s["lobes"] else "none (worn evenly: a 360° rub)"
        lines.append(f"| {f} | {s['depth_max_mm'] * 1e3:.1f} µm | {s['depth_mean_mm'] * 1e3:.1f} µm | "
                     f"{s['removed_volume_mm3']:.4g} mm³ | {s['plastic_work_J']:.4g} J | {lobes} | "
                     f"{s['clearance_before_mm']:.4g} → {s['clearance_effective_mm']:.4g} mm |")
    return lines


def _continuation_section(c: dict) -> list[str]:
    at = (f"at Ω = {c['speed']:.4g} Ω_ref ({c['speed_source']})" if c.get("speed") is not None
          else "at the section-6 speed")
    lines = ["", "## Continuation: special points, what the instability grows into, the boundary as a curve", "",
             f"Static branches in g0 {at} (pseudo-arclength through contact events), their Hopf, "
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
        lines.append(f"| {f} | {sp} | {_fmt(c[f]['orbits'])} | {b.get('curves')} ({b.get('points')}) | "
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


def _imported_blade_section(d: dict) -> list[str]:
    """The imported blade ([fe_blade]) the run was made with (docs/THEORY.md 9)."""
    f0 = ", ".join(f"{x:.4g}" for x in d["clamped_frequencies_at_rest_hz"])
    ft = ", ".join(f"{x:.4g}" for x in d["clamped_frequencies_at_top_speed_hz"])
    return ["", "## The imported blade", "",
            f"Superelement `{d['superelement']}`: {d['dofs_per_blade']} dofs a blade, {d['mass_kg']:.4g} kg; its tip "
            f"{d['tip_stations']} chord stations over {1e3 * d['tip_chord_m']:.4g} mm. Clamped frequencies [Hz] at "
            f"rest: {f0}; at {d['top_speed_rad_s']:.4g} rad/s: {ft}. {d['note'][0].upper()}{d['note'][1:]}."]


def write_report(out: str | Path, summary: dict, sections: tuple[str, ...] | list[str] = ()) -> Path:
    """Write out/report.md from the main job's summary (figures by relative path); ``sections``: markdown another
    package's part of the job wrote about its own results (the FMU half's), inserted as it is before the figures."""
    out = Path(out)
    lines = [
        "# rotorub — reproduction of Parent, Thouverez & Chevillot (EURODYN 2014)",
        "",
        f"Model: {summary['n_dofs']} dofs, Ω_ref = {summary['omega_ref_rad_s']:g} rad/s "
        "(speeds below are Ω / Ω_ref).",
        *_inputs_section(summary),
        "",
        "## The paper's facts",
        "",
        "| fact | statement | paper | ours | holds |",
        "|---|---|---|---|---|",
    ]
    for f in summary["paper_facts"]:
        cells = [str(f["id"]), f["statement"], _describe_paper(f), describe_ours(f)]
        cells = [c.replace("|", "\\|") for c in cells]  # a pipe inside a cell would split it
        lines.append("| " + " | ".join(cells) + f" | {'**yes**' if f['holds'] else '**NO**'} |")
    failing = [f for f in summary["paper_facts"] if not f["holds"]]
    lines += ["", "## What does not hold, and why", ""]
    if not failing:
        lines.append("Every fact holds on this configuration.")
    for f in failing:
        failed = [c for c in f.get("conditions", []) if not c["holds"]]
        if not failed:
            lines.append(f"* Fact {f['id']}: {f.get('why', 'see the values in the table and docs/THEORY.md')}")
            continue
        lines.append(f"* Fact {f['id']}: {len(failed)} of its {len(f['conditions'])} conditions "
                     + ("fails:" if len(failed) == 1 else "fail:"))
        for c in failed:
            whose = (" — a number of the paper's rotor: another configuration need not have it, not a defect of this "
                     "one" if c["kind"] == "the paper's rotor" else " — the paper's finding does not hold here")
            lines.append(f"  * {c['condition']}: ours {c['ours']}{whose}")
        if f.get("note"):  # a fact's further explanation, where it has one
            lines.append(f"  * {f['note']}")
    if "wear" in summary:
        lines += _wear_section(summary["wear"])
    if "continuation" in summary:
        lines += _continuation_section(summary["continuation"])
    if "blade_discretisation" in summary:
        lines += _discretisation_section(summary["blade_discretisation"])
    for rel in summary.get("report_sections", []):  # sections the library's quick studies wrote next to their files
        if (out / rel).is_file():
            lines += ["", *(out / rel).read_text().rstrip("\n").split("\n")]
    if "imported_blade" in summary:
        lines += _imported_blade_section(summary["imported_blade"])
    for section in sections:
        lines += section.rstrip("\n").split("\n")
    lines += ["", "## Figures", ""]
    for title, rel in [*FIGURES, *[tuple(x) for x in summary.get("figures_extra", [])]]:
        if (out / rel).exists():
            lines += [f"### {title}", "", f"![{title}]({rel})", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path
