"""The FMI cross-check kit's files, whatever the model (the FMI cross-check rules' results folder,
https://github.com/modelica/fmi-cross-check, and its successor's "compatibility information"):

* ``<id>_in.csv``: every input of the FMU, one row per communication point (``time`` first): a master sets each
  column's variable before the step that starts there (held over the step, or interpolated: the same);
* ``<id>_ref.csv``: the reference outputs at the same points;
* ``<id>_ref.opt``: StartTime, StopTime, StepSize, RelTol;
* ``ReadMe.txt``: what the run is and how to compare.

A model's crosscheck.py computes its reference and writes its kit with :func:`write_kit`; fmu_src/masters/
crosscheck.py runs any FMU against any kit. Numbers are written with ``repr`` (they read back exactly).
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path

import numpy as np

from .variables import Var


def kit_files(dest: str | Path, identifier: str) -> dict[str, Path]:
    dest = Path(dest)
    return {"in": dest / f"{identifier}_in.csv", "ref": dest / f"{identifier}_ref.csv",
            "opt": dest / f"{identifier}_ref.opt", "readme": dest / "ReadMe.txt"}


def write_kit(dest: str | Path, identifier: str, time: np.ndarray, inputs: dict[str, np.ndarray],
              outputs: dict[str, np.ndarray], step: float, readme: str, rel_tol: float = 1e-6) -> dict[str, Path]:
    """Write the four files into ``dest`` (next to the FMU); ``inputs`` and ``outputs`` by column name, each with one
    value per entry of ``time``."""
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    files = kit_files(dest, identifier)
    write_csv(files["in"], {"time": time, **inputs})
    write_csv(files["ref"], {"time": time, **outputs})
    files["opt"].write_text(f"StartTime, {float(time[0])!r}\nStopTime, {float(time[-1])!r}\nStepSize, {step!r}\n"
                            f"RelTol, {rel_tol!r}\n")
    files["readme"].write_text(readme)
    return files


def csv_text(columns: dict[str, np.ndarray]) -> str:
    """The table as CSV text: a header, then one row per entry, numbers by ``repr`` (they read back exactly); a NaN
    is an empty cell (no value there: a reference's cell that is not compared)."""
    names = list(columns)
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(names)
    for k in range(len(columns[names[0]])):
        w.writerow(["" if math.isnan(x := float(columns[c][k])) else repr(x) for c in names])
    return buf.getvalue()


def parse_csv(text: str) -> dict[str, np.ndarray]:
    """A table written by :func:`csv_text` (an empty cell reads as NaN); ValueError if a cell is not a number or a
    row has another length than the header."""
    rows = list(csv.reader(io.StringIO(text)))
    if not rows:
        raise ValueError("no header")
    head = rows[0]
    if any(len(r) != len(head) for r in rows[1:]):
        raise ValueError(f"every row must have the header's {len(head)} cells")
    body = np.array([[float(x) if x != "" else math.nan for x in r] for r in rows[1:]], dtype=float)
    body = body.reshape(len(rows) - 1, len(head))
    return {name: body[:, k] for k, name in enumerate(head)}


def write_csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    Path(path).write_text(csv_text(columns), newline="")


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    return parse_csv(Path(path).read_text())


def element_columns(variables: list[Var]) -> dict[str, str]:
    """An FMI 2.0 scalar's name -> the FMI 3.0 column of the same value, for every element of every array
    (``blade[3].F_N`` -> ``blade.F_N[3]``: element 3 of the array ``blade.F_N``)."""
    return {v.element.format(k=k): f"{v.name}[{k}]" for v in variables if v.is_array for k in range(1, v.size + 1)}
