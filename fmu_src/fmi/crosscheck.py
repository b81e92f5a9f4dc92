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


def write_csv(path: Path, columns: dict[str, np.ndarray]) -> None:
    names = list(columns)
    n = len(columns[names[0]])
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(names)
        for k in range(n):
            w.writerow([repr(float(columns[c][k])) for c in names])


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    with Path(path).open() as f:
        rows = list(csv.reader(f))
    head, body = rows[0], np.array(rows[1:], dtype=float)
    return {name: body[:, k] for k, name in enumerate(head)}


def element_columns(variables: list[Var]) -> dict[str, str]:
    """An FMI 2.0 scalar's name -> the FMI 3.0 column of the same value, for every element of every array
    (``blade[3].F_N`` -> ``blade.F_N[3]``: element 3 of the array ``blade.F_N``)."""
    return {v.element.format(k=k): f"{v.name}[{k}]" for v in variables if v.is_array for k in range(1, v.size + 1)}
