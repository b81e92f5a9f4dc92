"""Running an FMU through the ecos co-simulation engine (``ecospy``): an importer independent of fmpy and fmusim.

ecos (https://github.com/Ecos-platform/ecos, MIT) is a C++ co-simulation engine; ``ecospy`` (PyPI) is its ctypes
binding and ships the engine as one shared library (``ecospy/binaries/libecosc.so``). It loads FMUs through its
own FMI layer (fmilibcpp over fmi4c), not through fmpy, FMIL or the reference fmusim, so it is a third opinion
on an FMU. It imports FMI 1.0, 2.0 and 3.0 co-simulation FMUs. Linux needs the system's oneTBB runtime:
``apt-get install libtbb12`` (libtbb.so.12), then ``pip install ecospy``.

:func:`run` puts the FMU alone in an ecos simulation with its fixed-step algorithm: start values and the first
input row are set before initialisation (ecos writes them in initialisation mode), the outputs are read after
initialisation (t_0) and after each step, and each input row is set before the step that starts at its time and
held over it (ecos buffers the sets and writes them just before ``doStep``).

Limits (what ecos 0.7.2 does, read from its sources and checked here):

* variables are scalars only. FMI 3.0 arrays are registered as if they were scalars (one value reference, one
  value), and because ecos reads all the real outputs of an instance in one ``fmi3GetFloat64`` call, a single
  array among them makes that call fail for all of them (the values are then stale, silently). So array
  variables and their elements (``name[k]``) are refused here: see :func:`unsupported`.
* enumerations (FMI 2.0 and 3.0) are dropped from the model by ecos: they cannot be set or read;
* FMI 3.0 types: Float64, Int32 and Boolean only. ecos batches a type family in one call typed by its first
  value reference (a Float32 next to a Float64 is read as the wrong type) and passes the 8, 16 and 64-bit
  integers through 32-bit buffers; strings and binaries are not numbers (outside this interface);
* no configuration mode: FMI 3.0 structural parameters keep their start values;
* ecos ignores the status of the FMU's calls (``doStep``, get, set): a failing step goes on. :func:`run`
  therefore captures the engine's log (the FMU's log callback, at debug level, goes to the process's stdout)
  and raises when the FMU logged an Error, Fatal or Discard. An FMU that fails without logging is not seen.
  Capturing stdout swaps file descriptor 1 for the duration of the run: do not run two at once in one process;
* fixed communication step (the step the simulation is made with), FMI 3.0 without early return and event mode;
* the start time must be 0: ecos passes the start time to ``enterInitializationMode`` but counts the
  communication points from 0 whatever it is.
"""

from __future__ import annotations

import ctypes
import os
import re
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

_ELEMENT = re.compile(r"^(.*)\[(\d+)\]$")
# the FMU's log lines as ecos writes them: "[ecos] [debug] [<instance>] <status> <message>" (FMI 2.0 statuses are
# spelt fmi2Error etc., FMI 3.0 ones Error etc.)
_FAILED = re.compile(r"\[ecos\] \[\w+\] \[[^\]]*\] (?:fmi2)?(Error|Fatal|Discard)\b")
_INSTANCE = "fmu"
# FMI 3.0 types ecos reads and writes correctly, and which of its property kinds each is
_FMI3_KINDS = {"Float64": "real", "Int32": "int", "Boolean": "bool"}
_FMI2_KINDS = {"Real": "real", "Integer": "int", "Boolean": "bool"}


def available() -> str | None:
    """None when ecospy can run an FMU here, else a one-line reason."""
    try:
        import ecospy  # noqa: F401  (loads libecosc.so, which needs libtbb.so.12)
    except ImportError:
        return "ecospy is not installed (pip install ecospy)"
    except OSError as exc:  # the engine's shared library does not load
        if "libtbb" in str(exc):
            return "ecospy's engine needs the oneTBB runtime libtbb.so.12 (apt-get install libtbb12)"
        return f"ecospy's engine library does not load: {exc}"
    return None


@dataclass(frozen=True)
class _Var:
    name: str
    kind: str | None  # "real", "int", "bool"; None: not usable through ecos (why in `reason`)
    reason: str = ""


def _variables(fmu: str | Path) -> tuple[str, dict[str, _Var], dict[str, str]]:
    """(FMI version, variables by name, array name -> why not) from the FMU's modelDescription.xml (read here,
    not by fmpy: the host has to stand on its own)."""
    with zipfile.ZipFile(fmu) as z:
        root = ElementTree.fromstring(z.read("modelDescription.xml"))
    fmi = root.get("fmiVersion", "")
    out: dict[str, _Var] = {}
    arrays: dict[str, str] = {}
    mv = root.find("ModelVariables")
    for v in (mv if mv is not None else []):
        name = v.get("name", "")
        if fmi.startswith("2"):
            tag = next((c.tag for c in v if c.tag in ("Real", "Integer", "Boolean", "String", "Enumeration")), "")
            kind = _FMI2_KINDS.get(tag)
            why = "" if kind else ("ecos drops enumerations" if tag == "Enumeration" else f"a {tag} (not a number)")
        else:
            tag = v.tag
            if v.find("Dimension") is not None:
                kind, why = None, "an array: ecos handles scalars only"
                arrays[name] = why
            else:
                kind = _FMI3_KINDS.get(tag)
                why = "" if kind else ("ecos drops enumerations" if tag == "Enumeration"
                                       else f"a {tag}: ecos reads and writes only Float64, Int32 and Boolean right")
        out[name] = _Var(name, kind, why)
    return fmi, out, arrays


def unsupported(fmu: str | Path, names: list[str]) -> dict[str, str]:
    """The names among ``names`` that :func:`run` refuses for this FMU, each with the reason (array elements
    ``name[k]``, arrays, enumerations, other types, unknown names)."""
    _fmi, var, arrays = _variables(fmu)
    out = {}
    for n in names:
        m = _ELEMENT.match(n)
        if n not in var and m and m.group(1) in arrays:
            out[n] = f"element {m.group(2)} of the array {m.group(1)}: ecos handles scalars only"
        elif n not in var:
            out[n] = "no such variable"
        elif var[n].kind is None:
            out[n] = var[n].reason
    return out


class _Stdout:
    """File descriptor 1 redirected to a temporary file while inside (ecos logs to the C stdout)."""

    def __enter__(self) -> _Stdout:
        import sys

        sys.stdout.flush()
        self._file = tempfile.TemporaryFile(mode="w+b")
        self._saved = os.dup(1)
        os.dup2(self._file.fileno(), 1)
        self.text = ""
        return self

    def __exit__(self, *exc: object) -> None:
        ctypes.CDLL(None).fflush(None)  # the C library's buffer of stdout, before fd 1 goes back
        os.dup2(self._saved, 1)
        os.close(self._saved)
        self._file.seek(0)
        self.text = self._file.read().decode("utf-8", "replace")
        self._file.close()


def run(fmu: str | Path, start_values: dict[str, float | int], inputs: dict[str, np.ndarray], outputs: list[str],
        step: float) -> dict[str, np.ndarray]:
    """Run ``fmu`` through ecos: ``start_values`` and the first input row set before initialisation, row k of
    every input (``inputs[name]``) held over the step from ``inputs['time'][k]``, the ``outputs`` read after
    initialisation and after each step. Returns ``time`` (``inputs['time']``: t_0 .. t_N) and one array per
    output. Raises ValueError for names ecos cannot handle (:func:`unsupported`), a time grid that is not
    0, step, 2 step..., RuntimeError when the FMU logged a failure."""
    reason = available()
    if reason is not None:
        raise RuntimeError(reason)
    from ecospy import EcosLib

    fmu = Path(fmu).resolve()
    _fmi, var, _arrays = _variables(fmu)
    ins = [c for c in inputs if c != "time"]
    bad = unsupported(fmu, [*start_values, *ins, *outputs])
    if bad:
        raise ValueError(f"{fmu.name}: not through ecos: " + "; ".join(f"{n}: {why}" for n, why in bad.items()))
    t = np.asarray(inputs["time"], dtype=float)
    n = len(t) - 1
    if n < 1:
        raise ValueError("inputs['time'] needs at least two communication points")
    # ecos counts its time from 0 in steps of `step` (see the module's limits): the grid has to be that one
    if t[0] != 0.0 or not np.allclose(np.diff(t), step, rtol=1e-9, atol=0.0):
        raise ValueError(f"ecos runs from t = 0 in fixed steps: inputs['time'] must be 0, {step}, {2 * step}, ...")

    rows = np.empty((n + 1, len(outputs)))
    EcosLib.set_log_level("debug")  # the FMU's log reaches ecos's log at debug level only: it is how failures show
    log = _Stdout()
    try:
        with log:
            _run(fmu, var, start_values, inputs, ins, outputs, step, rows)
    except RuntimeError as exc:  # an initialisation that failed: with what the FMU said
        failed = [line for line in log.text.splitlines() if _FAILED.search(line)]
        raise RuntimeError("\n".join([str(exc), *failed[:20]])) from exc
    failed = [line for line in log.text.splitlines() if _FAILED.search(line)]
    if failed:
        raise RuntimeError(f"{fmu.name} failed under ecos:\n" + "\n".join(failed[:20]))
    return {"time": t, **{c: rows[:, j] for j, c in enumerate(outputs)}}


def _run(fmu: Path, var: dict[str, _Var], start_values: dict[str, float | int], inputs: dict[str, np.ndarray],
         ins: list[str], outputs: list[str], step: float, rows: np.ndarray) -> None:
    """The ecos run of :func:`run` (checked there), the outputs written into ``rows`` (one per point)."""
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

    t = np.asarray(inputs["time"], dtype=float)
    n = len(t) - 1

    def ident(name: str) -> str:
        return f"{_INSTANCE}::{name}"

    structure = EcosSimulationStructure()
    structure.add_model(_INSTANCE, str(fmu))
    sim = EcosSimulation(step_size=step, structure=structure)
    setter = {"real": sim.set_real, "int": sim.set_integer, "bool": sim.set_bool}
    getter = {"real": sim.get_real, "int": sim.get_integer, "bool": sim.get_bool}

    def put(name: str, value: float | int) -> None:
        kind = var[name].kind
        setter[kind](ident(name), float(value) if kind == "real" else int(value))

    try:
        for name, value in start_values.items():
            put(name, value)
        for c in ins:
            put(c, inputs[c][0])
        for c in outputs:
            # ecos reads only the variables asked for before; asked before initialisation, a get raises (its
            # buffer is empty) but marks the variable, which is then read after initialisation and each step
            try:
                getter[var[c].kind](ident(c))
            except Exception as exc:
                if str(exc).startswith("No "):  # "No real property ... found!": not a failed first read
                    raise
        if not sim.init(0.0):
            raise RuntimeError(f"ecos initialisation failed: {EcosLib.get_last_error()}")

        def read(k: int) -> None:
            rows[k] = [getter[var[c].kind](ident(c)) for c in outputs]

        read(0)
        for k in range(n):
            for c in ins:
                put(c, inputs[c][k])
            sim.step(1)
            read(k + 1)
        if abs(sim.get_time() - t[-1]) > 1e-6 * step:
            raise RuntimeError(f"ecos ended at t = {sim.get_time()}, not {t[-1]}")
        sim.terminate()
    finally:
        sim.free()
        structure.free()
        EcosLib.set_log_level("info")  # ecos's default
