"""Compatibility information: what each importer produced on each FMU's reference experiments, and whether it passed.

The layout is the FMI cross-check repository's (the FMI tools page's "compatibility information" links to it), one
folder per FMI version, interface, platform, importer and version, exporter and version, and model::

    compatibility/<fmi version>/cs/<platform>/<importer>/<version>/rotorub/<rotorub version>/<FMU>/
        passed | failed          an empty file: the verdict over every experiment that could run
        results.json             per experiment: verdict, rows, max relative difference per output, why not run
        README.md                date, importer, how it was run (rotorub fmu-check ... --host ...)

``<FMU>`` names the build (``RotorCasingContact-native``, ``RotorCasingContact-pythonfmu``, ``LPSpool``, ...).
:func:`table` turns the folder into the README's host table (``python -m fmu_src.masters.compatibility``).
"""

from __future__ import annotations

import json
import platform as _platform
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2] / "compatibility"


def _build_name(fmu: Path, root) -> str:
    tool = root.get("generationTool", "")
    flavour = "pythonfmu" if "pythonfmu" in tool.lower() else "native"
    name = root.get("modelName", fmu.stem)
    return f"{name}-{flavour}" if name == "RotorCasingContact" else name


def record(fmu: str | Path, host: str, version: str, outcomes: list, dest: str | Path | None = None) -> Path:
    """Write one importer's results on one FMU; returns the folder."""
    from rotorub_model import __version__

    from ..fmi.description import read_description

    fmu = Path(fmu)
    root = read_description(fmu)[2]
    fmi = root.get("fmiVersion", "?")
    plat = {"2": "linux64", "3": "x86_64-linux"}.get(fmi[0], "?") if _platform.system() == "Linux" else \
        _platform.system().lower()
    folder = (Path(dest) if dest else ROOT) / fmi / "cs" / plat / host / version.replace(" ", "-") / "rotorub" / \
        __version__ / _build_name(fmu, root)
    folder.mkdir(parents=True, exist_ok=True)
    ran = [o for o in outcomes if o.verdict != "not run"]
    ok = bool(ran) and all(o.verdict == "passed" for o in ran)
    for f in ("passed", "failed"):
        (folder / f).unlink(missing_ok=True)
    (folder / ("passed" if ok else "failed")).write_text("")
    results = {"fmu": fmu.name, "model": root.get("modelName"), "fmi_version": fmi,
               "token": root.get("instantiationToken") or root.get("guid"), "importer": host,
               "importer_version": version, "platform": plat, "date": date.today().isoformat(),
               "verdict": "passed" if ok else "failed",
               "experiments": [{"name": o.experiment, "verdict": o.verdict, "detail": o.detail,
                                "max_rel_diff": {k: v for k, v in o.diffs.items() if not k.startswith("rows")},
                                "rows": o.diffs.get("rows"), "rows_reference": o.diffs.get("rows_reference")}
                               for o in outcomes]}
    (folder / "results.json").write_text(json.dumps(results, indent=1, allow_nan=True) + "\n")
    (folder / "README.md").write_text(
        f"# {fmu.name} (FMI {fmi}, {_build_name(fmu, root)}) in {host} {version}, {plat}\n\n"
        f"Run on {results['date']} with `rotorub fmu-check {fmu.name} --host {host} --record compatibility`: "
        f"the FMU's own reference experiments (FMI-LS-REF, `extra/org.fmi-standard.fmi-ls-ref/`).\n\n"
        "| experiment | verdict | detail |\n|---|---|---|\n"
        + "".join(f"| {o.experiment} | {o.verdict} | {o.detail} |\n" for o in outcomes))
    return folder


def collect(root: str | Path | None = None) -> list[dict]:
    """Every recorded result under ``root`` (default: the repository's compatibility/)."""
    root = Path(root) if root else ROOT
    return [json.loads(p.read_text()) | {"folder": str(p.parent.relative_to(root))}
            for p in sorted(root.rglob("results.json"))]


def table(root: str | Path | None = None) -> str:
    """The README's host table: one row per importer and version, one column per FMU build."""
    rows = collect(root)
    builds = sorted({(r["folder"].split("/")[-1], r["fmi_version"]) for r in rows})
    importers = sorted({(r["importer"], r["importer_version"], r["platform"]) for r in rows})
    head = "| importer | " + " | ".join(f"{b} (FMI {v})" for b, v in builds) + " |"
    lines = [head, "|---|" + "---|" * len(builds)]
    for imp, ver, plat in importers:
        cells = []
        for b, v in builds:
            hit = [r for r in rows if r["importer"] == imp and r["importer_version"] == ver and r["platform"] == plat
                   and r["fmi_version"] == v and r["folder"].endswith("/" + b)]
            if not hit:
                cells.append("—")
                continue
            ex = hit[0]["experiments"]
            n_pass = sum(e["verdict"] == "passed" for e in ex)
            n_not = sum(e["verdict"] == "not run" for e in ex)
            cells.append(f"{'passed' if hit[0]['verdict'] == 'passed' else 'FAILED'} {n_pass}/{len(ex)}"
                         + (f" ({n_not} not run)" if n_not else "") + f", {hit[0]['date']}")
        lines.append(f"| {imp} {ver} ({plat}) | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(table(), end="")
