"""Writing a result: plain JSON (numpy values as Python's) and the common ``save`` of a figure beside its summary.
(The figures themselves: :mod:`rotorub_model.plotting`.)"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np


def plain(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return plain(x.tolist())
    if isinstance(x, np.bool_):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, float | np.floating):
        # strict JSON has no NaN or infinity: a value that is not a number is written as null
        return float(x) if np.isfinite(x) else None
    return x


def dumps(data: Any, indent: int | None = 2) -> str:
    """Strict JSON of ``data`` (numpy values as Python's, NaN as null), non-ASCII characters as they are (Ω, not
    \\u03a9): what every file and the CLI's ``--json`` print."""
    return json.dumps(plain(data), indent=indent, ensure_ascii=False, allow_nan=False)


def write_json(path: str | Path, data: dict[str, Any]) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(dumps(data) + "\n", encoding="utf-8")
    return path


def save_result(result: Any, out: str | Path, stem: str, summary_name: str | None = None) -> dict:
    """The common ``save`` of a result object: ``out/<stem>.png`` from its ``figure()`` and its
    ``summary()`` as ``out/<summary_name or stem>.json`` side by side; returns the summary."""
    from .plotting import save_figure

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save_figure(result.figure(), out / f"{stem}.png")
    s = result.summary()
    write_json(out / f"{summary_name or stem}.json", s)
    return s
