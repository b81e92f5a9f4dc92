"""Small helpers shared by the result objects: JSON writing and a headless matplotlib."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str | Path, dpi: int = 120) -> Path:
    """Lay out, write the PNG and release the figure (figures are many in a sweep: never leak one)."""
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
    return Path(path)


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
    if isinstance(x, np.floating):
        return float(x)
    return x


def write_json(path: str | Path, data: dict[str, Any]) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(plain(data), indent=2) + "\n")
    return path


def save_result(result: Any, out: str | Path, stem: str, summary_name: str | None = None) -> dict:
    """The common ``save`` of a result object: ``out/<stem>.png`` from its ``plot`` and its
    ``summary()`` as ``out/<summary_name or stem>.json``; returns the summary."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    result.plot(out / f"{stem}.png")
    s = result.summary()
    write_json(out / f"{summary_name or stem}.json", s)
    return s
