"""Driving an FMI 3.0 co-simulation FMU from fmpy (FMU3Slave).

* :class:`Slave3`: one instance, variables by name (an array by its name, all its elements at once), every
  call's status kept instead of raised, the FMU's log captured;
* :func:`first_event_fmi3`: the first early return of a run (the contact FMU: its first contact);
* :func:`first_event_fmi2_bisection`: the same event of an FMI 2.0 FMU found as a master without events finds
  it: step until a step ends past it (an output crosses 0), roll back to the state before it (fmi2SetFMUstate)
  and bisect the communication step.

The cross-check kit's run through an FMI 3.0 FMU is crosscheck.py's ``run_fmi3``.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4


def fmi3_available() -> str | None:
    """None when fmpy can drive an FMI 3.0 co-simulation FMU here, else why not."""
    try:
        from fmpy.fmi3 import FMU3Slave  # noqa: F401
    except ImportError as exc:
        return f"fmpy has no FMI 3.0 support ({exc}): pip install 'fmpy>=0.3.20'"
    return None


class Slave3:
    """An FMI 3.0 co-simulation instance through fmpy: ``set``/``get`` by name, statuses returned, log kept."""

    def __init__(self, fmu: str | Path, *, early_return: bool = False, name: str = "inst", logging: bool = False,
                 unzipped: str | None = None):
        from fmpy import extract, read_model_description
        from fmpy.fmi3 import FMU3Slave

        self.unzipped = unzipped or extract(str(fmu))
        self.md = read_model_description(self.unzipped)
        self.var = {v.name: v for v in self.md.modelVariables}
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.messages: list[tuple[int, str]] = []

        def log(_env, status, _category, message):
            self.messages.append((int(status), message.decode("utf-8", "replace")))

        self.f = FMU3Slave(guid=self.md.guid, unzipDirectory=self.unzipped,
                           modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.f.instantiate(loggingOn=logging, earlyReturnAllowed=early_return, logMessage=log)
        self.t = 0.0

    # ------------------------------------------------------------------ calls that return their status
    def call(self, fn: str, *args) -> int:
        from fmpy.fmi1 import FMICallException

        try:  # fmpy raises above Warning and returns the status otherwise (a Warning is not OK: fmusim stops on it)
            return int(getattr(self.f, fn)(self.f.component, *args))
        except FMICallException as exc:
            return exc.status

    def size(self, name: str) -> int:
        v = self.var[name]
        return int(np.prod(v.shape)) if getattr(v, "shape", None) else 1

    def set(self, **values) -> int:
        """fmi3Set<type> of each variable by name (a scalar, or a sequence for an array); the worst status."""
        from fmpy.fmi3 import fmi3Float64, fmi3Int32, fmi3Int64, fmi3UInt64, fmi3ValueReference

        status = OK
        for name, value in values.items():
            v = self.var[name]
            fn, ctype = {"Float64": ("fmi3SetFloat64", fmi3Float64), "Int32": ("fmi3SetInt32", fmi3Int32),
                         "Enumeration": ("fmi3SetInt64", fmi3Int64), "UInt64": ("fmi3SetUInt64", fmi3UInt64)}[v.type]
            vals = list(np.atleast_1d(value))
            status = max(status, self.call(fn, (fmi3ValueReference * 1)(v.valueReference), 1,
                                           (ctype * len(vals))(*vals), len(vals)))
        return status

    def get(self, name: str):
        """The value of a variable (an array as a numpy array)."""
        v, n = self.var[name], self.size(name)
        getter = {"Float64": self.f.getFloat64, "Int32": self.f.getInt32, "Enumeration": self.f.getInt64,
                  "UInt64": self.f.getUInt64, "String": self.f.getString}[v.type]
        out = getter([v.valueReference], n)
        if v.type == "String":
            return out[0].decode() if isinstance(out[0], bytes) else out[0]
        return np.array(out) if getattr(v, "shape", None) else out[0]

    def init(self, start: float = 0.0, **values) -> int:
        s = self.call("fmi3EnterInitializationMode", False, 0.0, start, False, 0.0)
        self.t = start
        if values:
            s = max(s, self.set(**values))
        return max(s, self.call("fmi3ExitInitializationMode"))

    def step(self, h: float = 1e-3, t: float | None = None) -> tuple[int, bool, bool, float]:
        """fmi3DoStep(t, h): (status, terminateSimulation, earlyReturn, lastSuccessfulTime); self.t follows."""
        from fmpy.fmi3 import fmi3Boolean, fmi3Float64

        t = self.t if t is None else t
        ev, term, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        s = self.call("fmi3DoStep", t, h, fmi3Boolean(True), ctypes.byref(ev), ctypes.byref(term),
                      ctypes.byref(early), ctypes.byref(last))
        if s <= WARNING:  # an early return, or a step that ended the run, stops at the FMU's last successful time
            self.t = last.value if early.value or term.value else t + h
        return s, bool(term.value), bool(early.value), float(last.value)

    def logged(self, since: int = 0, level: int = ERROR) -> str:
        return " | ".join(m for st, m in self.messages[since:] if st >= level)

    def free(self) -> None:
        self.f.freeInstance()

    def __enter__(self) -> Slave3:
        return self

    def __exit__(self, *exc) -> None:
        self.free()


def first_event_fmi3(fmu: str | Path, h: float, t_end: float, **start) -> dict:
    """Step a fresh instance (early return allowed) at h from the start values ``start`` until its first early
    return; its time, the steps before it and the FMU's internal substep (the contact FMU's outputs at it)."""
    with Slave3(fmu, early_return=True, name="first_contact3") as s:
        if s.init(**start) > WARNING:
            raise RuntimeError(s.logged())
        k = 0
        while s.t < t_end:
            t0 = s.t
            status, _term, early, last = s.step(h)
            if status > WARNING:
                raise RuntimeError(f"step at t = {t0}: status {status}: {s.logged()}")
            if early:
                return {"t": last, "t_step": t0, "steps": k, "dt_internal": float(s.get("dt_internal")),
                        "gap_min": float(s.get("gap_min")), "n_contact": int(s.get("n_contact")),
                        "early_returns": 1}
            k += 1
    raise RuntimeError(f"no contact before t = {t_end}")


def first_event_fmi2_bisection(fmu: str | Path, h: float, t_end: float, tol: float = 1e-9,
                               indicator: str = "gap_min", **start) -> dict:
    """The first time the output ``indicator`` of an FMI 2.0 FMU is below 0, found as a master without events
    finds it: steps of h, each from a state saved before it (fmi2GetFMUstate), until a step ends with it below 0;
    then bisection of that communication step with rollbacks (fmi2SetFMUstate): [lo, hi] with the indicator >= 0
    after a step of lo and < 0 after a step of hi, until hi - lo <= tol. Returns t0 + hi (the first time known
    past the event) and t0 + lo."""
    from .fmi2 import Slave

    with Slave(fmu, instance_name="bisection2", **start) as s:
        state = s.get_state()
        t = 0.0
        while True:
            s.step(t, h)
            if s.get(indicator) < 0.0:
                break
            if t + h >= t_end:
                raise RuntimeError(f"no event ({indicator} < 0) before t = {t_end}")
            t += h
            s.free_state(state)
            state = s.get_state()
        lo, hi, trials = 0.0, h, 0
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            s.set_state(state)
            s.step(t, mid)
            trials += 1
            if s.get(indicator) < 0.0:
                hi = mid
            else:
                lo = mid
        s.free_state(state)
        return {"t": t + hi, "t_lo": t + lo, "t_step": t, "trials": trials}
