"""Markdown report of the main job: the paper's facts, ours, and the figures."""

from __future__ import annotations

import json
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
]


def _fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    if isinstance(v, dict):
        return ", ".join(f"{k}: {_fmt(x)}" for k, x in v.items())
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


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
    extra = summary.get("fmu")
    if extra:
        lines += ["", "## FMU against the library", "", "```", json.dumps(extra, indent=1), "```"]
    lines += ["", "## Figures", ""]
    for title, rel in FIGURES:
        if (out / rel).exists():
            lines += [f"### {title}", "", f"![{title}]({rel})", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path
