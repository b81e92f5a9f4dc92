"""Driving pythonfmu FMUs from fmpy without losing their error messages.

Two traps of the stack this module exists for:

* fmpy raises ``FMICallException("fmi2DoStep failed with status 2 (discard)")``: the
  cause is only in the log, and pythonfmu 0.7 forwards log messages to the master
  only when the instance was created with ``loggingOn = true``. Every instance made
  here has logging on and a logger that keeps the messages, and every failed call
  raises :class:`FMUError` carrying them.
* pythonfmu's fmi2DoStep can only refuse a step with fmi2Discard (an exception in the
  slave would be fmi2Fatal), and ``fmpy.simulate_fmu`` takes a discarded step as an
  early end of the simulation: it returns the rows so far and raises nothing.
  :func:`simulate` raises :class:`FMUError` when the FMU logged a discard or an error.
* ``fmpy.simulate_fmu`` takes the communication step from ``output_interval``.

Example
-------
>>> from fmu_src.masters.fmi2 import Slave                          # doctest: +SKIP
>>> with Slave("fmus/RotorCasingContact.fmu", g0=0.2e-3) as s:  # doctest: +SKIP
...     s.set(Omega=176.0, imbalance=0.022)
...     s.step(0.0, 1e-3)
...     s.get("blade[1].F_N")
"""

from __future__ import annotations

import hashlib
import shutil
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np


class FMUError(RuntimeError):
    """An FMI call failed; ``messages`` holds what the FMU logged (status >= warning)."""

    def __init__(self, what: str, messages: Sequence[str]):
        self.messages = list(dict.fromkeys(messages))  # the same cause is often logged twice
        detail = "; ".join(self.messages) if self.messages else "the FMU logged no message"
        super().__init__(f"{what}: {detail}")


class _Log:
    """Collects the FMU's log messages (fmi2CallbackLogger)."""

    def __init__(self, echo: bool = False):
        self.records: list[tuple[int, str]] = []
        self.echo = echo

    def __call__(self, _env, _instance, status, _category, message) -> None:
        text = message.decode("utf-8", "replace") if isinstance(message, bytes) else str(message)
        self.records.append((int(status), text))
        if self.echo:
            print(text)

    def problems(self, since: int = 0, level: int = 1) -> list[str]:
        """Messages logged since record ``since`` with status >= ``level`` (1 warning, 2 discard, 3 error)."""
        return [m for s, m in self.records[since:] if s >= level]


def simulate(fmu: str | Path, **kwargs) -> np.ndarray:
    """``fmpy.simulate_fmu`` with logging on; a failure raises :class:`FMUError` with the FMU's messages."""
    from fmpy import simulate_fmu

    # Not simulate_fmu(logger=...): fmpy's native log proxy keeps one process-wide pointer to that call's
    # ctypes thunk, which is freed when the run ends, and the next FMU that logs through fmpy's default
    # callbacks (the native FMU logs every refusal, logging on or off) jumps into freed memory: a
    # segfault a few hundred tests later. Our own instance has callbacks of its own, alive as long as it.
    kwargs.pop("debug_logging", None)
    if kwargs.get("start_values"):
        kwargs["start_values"] = enum_values(fmu, kwargs["start_values"])
    slave = Slave(fmu, instance_name="simulate", initialize=False)
    log = slave.log
    try:
        result = simulate_fmu(slave.unzip_dir, fmu_instance=slave.fmu, terminate=False, **kwargs)
        refused = [m for st, m in log.records if st >= 2]  # fmi2Discard, fmi2Error, fmi2Fatal
    except Exception as exc:  # noqa: BLE001 - re-raised with the FMU's own words
        raise FMUError(str(exc), log.problems()) from exc
    finally:
        slave.close()
    if refused:
        t = float(result["time"][-1]) if len(result) else float("nan")
        raise FMUError(f"simulation stopped at t = {t:g} s", refused)
    return result


def enum_values(fmu: str | Path, values: dict) -> dict:
    """``values`` with Enumeration items given by name replaced by their values (fmpy takes integers)."""
    from fmpy import read_model_description

    variables = {v.name: v for v in read_model_description(str(fmu)).modelVariables}
    out = dict(values)
    for name, value in values.items():
        v = variables.get(name)
        if v is not None and v.type == "Enumeration" and isinstance(value, str):
            items = {it.name: int(it.value) for it in v.declaredType.items}
            if value not in items:
                raise KeyError(f"{name}: '{value}' is not one of its items ({', '.join(items)})")
            out[name] = items[value]
    return out


class Slave:
    """One co-simulation instance through fmpy's FMU2Slave, addressed by variable name.

    ``fmu``: a .fmu file or an extracted folder. ``unzip_dir``: where the .fmu is already
    extracted (several instances can share it). ``start`` values are set before
    initialization (parameters, initial inputs); with ``initialize=False`` the instance is
    only instantiated and :meth:`initialize` is the caller's.
    """

    def __init__(self, fmu: str | Path, instance_name: str = "instance", unzip_dir: str | Path | None = None,
                 start_time: float = 0.0, echo_log: bool = False, initialize: bool = True, **start):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import (
            FMU2Slave,
            calloc,
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
            free,
        )

        if unzip_dir is None and Path(fmu).is_dir():
            unzip_dir = fmu
        self._own_dir = unzip_dir is None
        self.unzip_dir = str(Path(extract(str(fmu)) if unzip_dir is None else unzip_dir).resolve())
        self.instance_name = instance_name
        md = read_model_description(self.unzip_dir)
        self.model_description = md
        self.variables = {v.name: v for v in md.modelVariables}
        self.log = _Log(echo_log)
        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(self.log)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._callbacks = cb  # kept alive as long as the instance
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip_dir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance_name)
        self._alive = False
        self._blob_times: dict[bytes, float] = {}
        self._call("fmi2Instantiate", self.fmu.instantiate, callbacks=cb, loggingOn=True)
        self._alive = True
        self.time = start_time
        if initialize:
            try:
                self.initialize(start_time, **start)
            except BaseException:
                self.close()
                raise

    def initialize(self, start_time: float = 0.0, stop_time: float | None = None, **start) -> None:
        """fmi2SetupExperiment, fmi2EnterInitializationMode, the ``start`` values, fmi2ExitInitializationMode."""
        self._call("fmi2SetupExperiment", self.fmu.setupExperiment, startTime=start_time, stopTime=stop_time)
        self._call("fmi2EnterInitializationMode", self.fmu.enterInitializationMode)
        self.set(**start)
        self._call("fmi2ExitInitializationMode", self.fmu.exitInitializationMode)
        self.time = start_time

    # -- plumbing
    def _call(self, what: str, fn, *args, **kwargs):
        n0 = len(self.log.records)
        try:
            return fn(*args, **kwargs)
        except Exception as exc:  # noqa: BLE001 - fmpy's FMICallException and friends
            raise FMUError(f"{what} failed ({exc})", self.log.problems(n0)) from exc

    def _vr(self, name: str):
        try:
            return self.variables[name]
        except KeyError:
            raise KeyError(f"{name}: no such variable in {self.model_description.modelName}") from None

    # -- values
    def set(self, **values) -> None:
        """Set variables by name (Real, Integer, Boolean, String by their declared type; an Enumeration
        by its item name or its value)."""
        for name, value in values.items():
            v = self._vr(name)
            if v.type == "Enumeration" and isinstance(value, str):
                value = self.enum_value(name, value)
            fn = {"Real": self.fmu.setReal, "Integer": self.fmu.setInteger, "Enumeration": self.fmu.setInteger,
                  "Boolean": self.fmu.setBoolean, "String": self.fmu.setString}[v.type]
            self._call(f"set {name}", fn, [v.valueReference], [value])

    def enum_value(self, name: str, item: str) -> int:
        """The value of an Enumeration variable's item, by name."""
        items = {it.name: int(it.value) for it in self._vr(name).declaredType.items}
        if item not in items:
            raise KeyError(f"{name}: '{item}' is not one of its items ({', '.join(items)})")
        return items[item]

    def get(self, name: str):
        """A variable's value (an Enumeration's as its item name)."""
        v = self._vr(name)
        fn = {"Real": self.fmu.getReal, "Integer": self.fmu.getInteger, "Enumeration": self.fmu.getInteger,
              "Boolean": self.fmu.getBoolean, "String": self.fmu.getString}[v.type]
        out = self._call(f"get {name}", fn, [v.valueReference])[0]
        if v.type == "Enumeration":
            return next((it.name for it in v.declaredType.items if int(it.value) == out), out)
        return out.decode() if isinstance(out, bytes) else out

    def get_reals(self, names: Iterable[str]) -> np.ndarray:
        vrs = [self._vr(n).valueReference for n in names]
        return np.array(self._call("fmi2GetReal", self.fmu.getReal, vrs))

    def step(self, t: float | None, h: float) -> None:
        """fmi2DoStep(t, h); raises :class:`FMUError` with the FMU's messages if refused."""
        t = self.time if t is None else t
        self._call(f"fmi2DoStep(t = {t:g} s, h = {h:g} s)", self.fmu.doStep, currentCommunicationPoint=t,
                   communicationStepSize=h)
        self.time = t + h

    def terminated(self) -> bool:
        """fmi2GetBooleanStatus(fmi2Terminated): the FMU ended the run (after a divergence)."""
        from fmpy.fmi2 import fmi2Terminated

        return bool(self._call("fmi2GetBooleanStatus", self.fmu.getBooleanStatus, fmi2Terminated))

    def last_successful_time(self) -> float:
        """fmi2GetRealStatus(fmi2LastSuccessfulTime)."""
        from fmpy.fmi2 import fmi2LastSuccessfulTime

        return float(self._call("fmi2GetRealStatus", self.fmu.getRealStatus, fmi2LastSuccessfulTime))

    # -- rollback
    def get_state(self):
        return self._call("fmi2GetFMUstate", self.fmu.getFMUState), self.time

    def set_state(self, state) -> None:
        s, t = state
        self._call("fmi2SetFMUstate", self.fmu.setFMUState, s)
        self.time = t

    def free_state(self, state) -> None:
        self._call("fmi2FreeFMUstate", self.fmu.freeFMUState, state[0])

    def serialize(self, state) -> bytes:
        data = bytes(self._call("fmi2SerializeFMUstate", self.fmu.serializeFMUState, state[0]))
        self._blob_times[hashlib.sha1(data).digest()] = state[1]  # the FMU's time is in the bytes, not in reach
        return data

    def deserialize(self, data: bytes):
        """(state, its time): the time recorded when these bytes were serialized here, else the current one."""
        t = self._blob_times.get(hashlib.sha1(bytes(data)).digest(), self.time)
        return self._call("fmi2DeSerializeFMUstate", self.fmu.deserializeFMUState, data), t

    def reset(self) -> None:
        self._call("fmi2Reset", self.fmu.reset)

    # -- life cycle
    def close(self) -> None:
        if self._alive:
            self._alive = False
            try:
                self.fmu.terminate()
            except Exception:  # noqa: BLE001 - an instance that failed may refuse to terminate; free it anyway
                pass
            self.fmu.freeInstance()
        if self._own_dir:
            shutil.rmtree(self.unzip_dir, ignore_errors=True)

    def __enter__(self) -> Slave:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


__all__ = ["FMUError", "Slave", "enum_values", "simulate"]
