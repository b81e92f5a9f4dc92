"""Running any FMU against an FMI cross-check kit (fmu_src/fmi/crosscheck.py) and comparing it with the reference.

The runs read every input column of ``<id>_in.csv`` (set before the step that starts at its row, held over the
step) and record the reference's output columns after initialisation and after each step:

* :func:`run_fmpy`: FMI 2.0 through fmpy's FMU2Slave;
* :func:`run_fmi3`: FMI 3.0 through fmpy's FMU3Slave (fmi3.py), with or without early return (continued from each
  early return to the next communication point); a column ``name[k]`` is element k of the array ``name``;
* :func:`run_libcosim`: FMI 2.0 through OSP libcosim's fixed-step algorithm (inputs by an override manipulator;
  :func:`libcosim_table` runs any input table so, start values too);
* :func:`compare`: the largest difference of each output against the reference, relative to its largest value.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..fmi.crosscheck import read_csv

_ELEMENT = re.compile(r"^(.*)\[(\d+)\]$")


def kit_of(kit: str | Path, identifier: str | None = None) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(inputs, reference) of the kit in folder ``kit`` (its ``*_in.csv``, or ``<identifier>_in.csv``)."""
    kit = Path(kit)
    if identifier is None:
        found = sorted(kit.glob("*_in.csv"))
        if len(found) != 1:
            raise FileNotFoundError(f"{kit}: expected one *_in.csv (a cross-check kit), found {len(found)}")
        identifier = found[0].name[:-len("_in.csv")]
    return read_csv(kit / f"{identifier}_in.csv"), read_csv(kit / f"{identifier}_ref.csv")


def _columns(table: dict) -> list[str]:
    return [c for c in table if c != "time"]


def run_fmpy(fmu: str | Path, kit: str | Path) -> dict[str, np.ndarray]:
    """The kit's run through fmpy's FMU2Slave (inputs held over each step, outputs after each)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    inp, ref = kit_of(kit)
    ins, outs = _columns(inp), _columns(ref)
    unzip = extract(str(fmu))
    md = read_model_description(unzip)
    var = {v.name: v for v in md.modelVariables}
    missing = [c for c in ins + outs if c not in var]
    if missing:
        raise KeyError(f"{fmu}: the kit's column(s) {', '.join(missing)} are not variables of the FMU")
    f = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="crosscheck")
    in_vrs = [var[c].valueReference for c in ins]
    reals = [c for c in outs if var[c].type == "Real"]
    ints = [c for c in outs if var[c].type != "Real"]
    t = inp["time"]
    rows = []

    def read() -> None:
        vals = dict(zip(reals, f.getReal([var[c].valueReference for c in reals])))
        vals.update(zip(ints, f.getInteger([var[c].valueReference for c in ints])))
        rows.append([vals[c] for c in outs])

    f.instantiate()
    f.setupExperiment(startTime=float(t[0]))
    f.enterInitializationMode()
    f.setReal(in_vrs, [float(inp[c][0]) for c in ins])
    f.exitInitializationMode()
    read()
    for k in range(len(t) - 1):
        f.setReal(in_vrs, [float(inp[c][k]) for c in ins])
        f.doStep(currentCommunicationPoint=t[k], communicationStepSize=t[k + 1] - t[k])
        read()
    f.terminate()
    f.freeInstance()
    arr = np.array(rows, dtype=float)
    return {"time": t, **{c: arr[:, i] for i, c in enumerate(outs)}}


def run_fmi3(fmu: str | Path, kit: str | Path, early_return: bool = False) -> dict[str, np.ndarray]:
    """The kit's run through an FMI 3.0 FMU (fmpy's FMU3Slave), in the kit's column names; ``early_returns``:
    how many steps ended early (each continued to its communication point)."""
    from .fmi3 import WARNING, Slave3

    inp, ref = kit_of(kit)
    ins, outs = _columns(inp), _columns(ref)
    where: dict[str, tuple[str, int | None]] = {}
    t = inp["time"]
    rows, early_returns = [], 0
    with Slave3(fmu, early_return=early_return, name="crosscheck3") as s:
        for c in outs:
            m = _ELEMENT.match(c)
            where[c] = (m.group(1), int(m.group(2)) - 1) if m and c not in s.var else (c, None)
            if where[c][0] not in s.var:
                raise KeyError(f"{fmu}: the kit's column {c} is not a variable (or an element of one) of the FMU")
        if s.init(start=float(t[0]), **{c: float(inp[c][0]) for c in ins}) > WARNING:
            raise RuntimeError(f"initialisation failed: {s.logged()}")

        def read() -> None:
            vals = {name: s.get(name) for name in {v for v, _ in where.values()}}
            rows.append([vals[v] if k is None else vals[v][k] for v, k in where.values()])

        read()
        for k in range(len(t) - 1):
            s.set(**{c: float(inp[c][k]) for c in ins})
            status, _term, early, last = s.step(t[k + 1] - t[k], t[k])
            while status <= WARNING and early:  # an early return: go on to the communication point
                early_returns += 1
                status, _term, early, last = s.step(t[k + 1] - last, last)
            if status > WARNING:
                raise RuntimeError(f"step at t = {t[k]}: status {status}: {s.logged()}")
            read()
    arr = np.array(rows, dtype=float)
    return {"time": np.asarray(t), **{c: arr[:, i] for i, c in enumerate(outs)},
            "early_returns": np.array(early_returns)}


def run_libcosim(fmu: str | Path, kit: str | Path) -> dict[str, np.ndarray]:
    """The kit's run through OSP libcosim (its fixed-step algorithm, inputs by an override manipulator); its
    observer has the outputs after each step (not after initialisation)."""
    inp, ref = kit_of(kit)
    return libcosim_table(fmu, inp, _columns(ref), float(inp["time"][1] - inp["time"][0]))


def libcosim_table(fmu: str | Path, inputs: dict[str, np.ndarray], outputs: list[str], step: float,
                   start: dict[str, float | int] | None = None, stop_on_failure: bool = False) -> dict[str, np.ndarray]:
    """An input table's run through OSP libcosim: ``start`` values and the first row set as initial values, each
    row held over the step that starts there (an override manipulator), ``outputs`` after each step (libcosim's
    observer has no row after initialisation). A failed step raises, or with ``stop_on_failure`` ends the run
    with the rows so far (libcosim's execution stops there: a diverged run)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    t = inputs["time"]
    ins = _columns(inputs)
    ex = CosimExecution.from_step_size(round(step * 1e9))
    slave = CosimLocalSlave(fmu_path=str(fmu), instance_name="rotor")
    i = ex.add_local_slave(slave)
    observer = CosimObserver.create_last_value()
    manipulator = CosimManipulator.create_override()
    ex.add_observer(observer)
    ex.add_manipulator(manipulator)
    refs = {v.name.decode(): v.reference for v in ex.slave_variables(i)}
    integer = {v.name.decode() for v in ex.slave_variables(i) if int(v.type) == 1}  # libcosim's variable types
    for name, v in (start or {}).items():
        (ex.integer_initial_value if name in integer else ex.real_initial_value)(i, refs[name], v)
    in_refs = [refs[c] for c in ins]
    for c, r in zip(ins, in_refs):
        ex.real_initial_value(i, r, float(inputs[c][0]))
    rows = []
    for k in range(len(t) - 1):
        manipulator.slave_real_values(i, in_refs, [float(inputs[c][k]) for c in ins])
        if not ex.step(1):
            if stop_on_failure:
                break
            raise RuntimeError(f"libcosim step {k} failed")
        rows.append([observer.last_integer_values(i, [refs[c]])[0] if c in integer
                     else observer.last_real_values(i, [refs[c]])[0] for c in outputs])
    del ex, manipulator, observer, slave
    arr = np.array(rows, dtype=float).reshape(len(rows), len(outputs))
    return {"time": t[1:len(rows) + 1], **{c: arr[:, j] for j, c in enumerate(outputs)}}


def compare(result: dict[str, np.ndarray], kit: str | Path) -> dict[str, float]:
    """Largest difference of each output against the reference, relative to the column's largest value (rows
    matched by time)."""
    _inp, ref = kit_of(kit)
    rows = np.searchsorted(ref["time"], result["time"] - 1e-12)
    out = {}
    for c in _columns(ref):
        scale = max(float(np.abs(ref[c]).max()), 1e-300)
        out[c] = float(np.abs(result[c] - ref[c][rows]).max() / scale)
    return out
