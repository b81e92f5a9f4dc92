"""Misuse of the FMI 2.0 co-simulation API on the native FMUs (RotorCasingContact, LPSpool), each case
in a fresh process, so that a crash or a hang is observed instead of suffered.

    .venv/bin/python benchmarks/fuzz_fmi.py [--json PATH] [--fmu PATH ...] [--only TEXT] [--timeout 30]
                                          [--jobs 2] [--list]
    .venv/bin/python benchmarks/fuzz_fmi.py --case NAME --fmu PATH [--other PATH]   # one case (the children)

Without --fmu both FMUs are built for linux64 into a temporary folder (fmu_src.models.contact.builder and
fmu_src.models.spool.builder; the binaries are cached). Every case drives the FMU's binary through fmpy's
FMU2Slave (the status a call returns is taken as it is; fmpy's exception for a status above fmi2Warning
is caught) with a logger that records (status, message), and makes one call under test, the probe (a
few cases make two: fmi2DeSerializeFMUstate then fmi2SetFMUstate). What is tried, per FMU (the value
cases are generated from its modelDescription.xml):

* values: every settable variable just below its min and just above its max (the next double), NaN,
  +inf, -inf, the setter of another type, and at min and at max (allowed); setting every output; every
  fixed parameter after initialisation; unknown value references (past the end, 0xFFFFFFFF, the gaps of
  the numbering: 4 of RotorCasingContact), the wrong getter, NULL arrays with nvr > 0, nvr = 0 with NULL
  arrays (allowed), an all-or-nothing multi-value set;
* the calling sequence: fmi2DoStep before, during and after initialisation, after fmi2Terminate and
  after fmi2Reset; Enter/ExitInitializationMode out of turn, fmi2SetupExperiment after initialisation,
  fmi2Terminate twice or before initialisation, fmi2Reset in every phase, and the calls FMI 2.0's
  calling-sequence table forbids but an FMU could let pass (a getter before initialisation, fmi2Terminate
  in initialization mode, a setter after a discarded step);
* steps: a communication point that is not the FMU's time (ahead, behind, NaN, inf; within the FMU's
  1e-9 tolerance is allowed), step sizes 0, negative, NaN, +-inf, tiny (1e-300), huge (1e6 and 1e12);
* FMU states: fmi2Get/SetFMUstate in each phase (instantiated, initialization, step, terminated), a state
  of a run restored after fmi2Reset, NULL and garbage states, fmi2FreeFMUstate of NULL and twice,
  fmi2GetFMUstate into an existing state or a NULL pointer, a state of the other FMU (contact vs spool,
  in memory and serialized), serialized states truncated, extended, garbage, or with one field corrupted
  (magic, GUID, phase, sizes, time, a value out of range, the model's data);
* the divergence rule (fmu_src/models/contact/FMU.md): the diverging step is fmi2Discard with a message and
  fmi2GetBooleanStatus(fmi2Terminated) is then true; a further fmi2DoStep is fmi2Error; a rollback
  (fmi2SetFMUstate) or fmi2Reset goes on; no step returns fmi2OK in a state past the divergence limit;
* the rest: fmi2SetDebugLogging with unknown categories, fmi2Get*Status kinds that are not provided
  (fmi2Discard, as the standard says) or a NULL value pointer, input and output derivatives, directional derivatives,
  fmi2CancelStep, fmi2Instantiate with a wrong GUID, the wrong fmuType, an empty or NULL instance name,
  NULL callbacks, and calls on a NULL instance.

After a refusal in step mode the case checks that the instance is as it was (the manual: "fmi2Error
leaves the instance as it was"): the next step gives bit for bit the outputs of the same step without
the refused call; after a refused set the variable keeps its value; every refusal's message must also be
in the 'message' output, a refused value must be named in its message, and no message may carry an
unexpanded printf conversion (%s: the FMI logger's message is a format, and fmpy's logger, like many,
prints it without formatting; fmi2_cs.c formats its messages itself for that reason).

Outcomes: "error+message" (fmi2Error and a log message of status >= fmi2Error), "discard+message" (a
divergence), "ok (allowed)" / "discard (allowed)" (what the standard allows or prescribes), "error, no
message" (only where no logger can be reached: NULL callbacks, a NULL instance), "SILENT OK" (fmi2OK where
the call must be refused, or an fmi2OK step whose result breaks the model's own rule), "FATAL"
(fmi2Fatal), "CRASH" (the process died by a signal), "HANG" (no answer within --timeout seconds).
Prints the table (expected next to observed) and one summary line per FMU; exits 1 if any case is SILENT
OK, FATAL, CRASH, HANG or not as expected. --json PATH writes the table with every logged message.
"""

from __future__ import annotations

import argparse
import json
import math
import random
import re
import signal
import struct
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from ctypes import addressof, byref, c_char_p, c_double, c_int, c_size_t, c_uint, c_void_p, create_string_buffer
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4
STATUS_NAME = {OK: "fmi2OK", WARNING: "fmi2Warning", DISCARD: "fmi2Discard", ERROR: "fmi2Error",
               FATAL: "fmi2Fatal", 5: "fmi2Pending"}
KINDS = {0: "fmi2DoStepStatus", 1: "fmi2PendingStatus", 2: "fmi2LastSuccessfulTime", 3: "fmi2Terminated"}
H = 1e-3  # the communication step of every case
PRINTF = re.compile(r"%[-+ #0-9.]*(hh|h|ll|l|z)?[sdiuxXgGeEfFcp]")

# outcomes
ERR_MSG, DIS_MSG, ALLOWED, DIS_ALLOWED = "error+message", "discard+message", "ok (allowed)", "discard (allowed)"
ERR_NOMSG, SILENT, FATAL_, CRASH, HANG = "error, no message", "SILENT OK", "FATAL", "CRASH", "HANG"
REFUSED = (ERR_MSG, DIS_MSG)
ALLOWED_ALL = (ALLOWED, DIS_ALLOWED)

# how each model is made to diverge, and how a run goes on after a rollback (models/contact/FMU.md, "Divergence")
RECIPES = {
    "RotorCasingContact": dict(params={"max_penetration": 1e-5, "g0": 0.0}, inputs={},
                               recover={"g0": 1e-3}),
    "LPSpool": dict(params={}, inputs={"friction_torque": -1e8}, recover={"friction_torque": 0.0}),
}


class SetupError(Exception):
    """A call that prepares a case (not the one under test) failed."""


# ------------------------------------------------------------------ ctypes arrays

def vrs(*refs):
    return (c_uint * len(refs))(*refs)


def reals(*xs):
    return (c_double * len(xs))(*xs)


def ints(*xs):
    return (c_int * len(xs))(*xs)


def strs(*xs):
    return (c_char_p * len(xs))(*xs)


def same(a, b) -> bool:
    """Bit for bit (NaN == NaN)."""
    if isinstance(a, float) and isinstance(b, float):
        return struct.pack("<d", a) == struct.pack("<d", b)
    return a == b


# ------------------------------------------------------------------ the harness (in the child process)

class Harness:
    """One FMU binary, one instance at a time, every FMI call's status as returned."""

    PHASES = ("instantiated", "initialization", "step", "terminated")

    def __init__(self, unzipdir: str, other_dir: str | None = None):
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.dir = unzipdir
        self.other_dir = other_dir
        self.md = read_model_description(unzipdir)
        self.model = self.md.coSimulation.modelIdentifier
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir, modelIdentifier=self.model,
                             instanceName="fuzz")
        self.log: list[tuple[int, str]] = []
        self.callbacks = make_callbacks(self.log)
        self.c = None
        self.phase = None
        self.t = 0.0
        self.probes: list[dict] = []
        self.problems: list[str] = []
        self.silent = False
        self.keep = []  # ctypes objects the FMU may still point to

    # -- raw calls
    def call(self, fname: str, *args):
        from fmpy.fmi1 import FMICallException
        try:
            return getattr(self.fmu, fname)(*args)
        except FMICallException as e:
            return e.status

    def need(self, fname: str, *args):
        s = self.call(fname, *args)
        if s not in (OK, WARNING):
            last = self.log[-1][1] if self.log else ""
            raise SetupError(f"{fname} returned {STATUS_NAME.get(s, s)} while preparing the case: {last}")
        return s

    def probe(self, fname: str, *args) -> int:
        """The call under test: its status and the messages logged during it are recorded."""
        mark = len(self.log)
        s = self.call(fname, *args)
        if fname == "fmi2Instantiate":
            comp, s = s, (OK if s else ERROR)
            self.keep.append(comp)
            if comp:
                self.call("fmi2FreeInstance", comp)
        msgs = self.log[mark:]
        self.probes.append({"call": fname, "status": s, "messages": msgs})
        refusal = [m for st, m in msgs if st >= DISCARD]
        for _, m in msgs:  # the FMI logger's message is a format: a logger that does not format sees it as is
            conv = PRINTF.search(m.replace("%%", ""))
            if conv:
                self.problem(f"the message carries an unexpanded {conv.group(0)!r} (fmpy's logger prints it as is)")
        # (not before initialisation: FMI 2.0 lets nothing be read there, the message included)
        if s in (DISCARD, ERROR) and refusal and self.c and args and args[0] == self.c and self.phase != "instantiated":
            out = self.get_str("message").replace("%%", "%")
            if out != refusal[-1].replace("%%", "%"):
                self.problem(f"the 'message' output is {out!r}, not the logged {refusal[-1]!r}")
        return s

    @property
    def last_messages(self) -> str:
        return " | ".join(m for _, m in self.probes[-1]["messages"]) if self.probes else ""

    def problem(self, text: str, silent: bool = False):
        self.problems.append(text)
        self.silent = self.silent or silent

    def check(self, cond: bool, text: str, silent: bool = False):
        if not cond:
            self.problem(text, silent)

    # -- bringing an instance to a phase
    def instantiate(self, logging_on: bool = False):
        from pathlib import Path as _P
        comp = self.call("fmi2Instantiate", b"fuzz", 1, self.md.guid.encode(),
                         _P(self.dir, "resources").as_uri().encode(), byref(self.callbacks), 0,
                         1 if logging_on else 0)
        if not comp:
            raise SetupError(f"fmi2Instantiate failed: {self.log[-1:] }")
        self.c, self.phase, self.t = comp, "instantiated", 0.0
        return comp

    def start(self, phase: str = "step", params: dict | None = None, steps: int = 3):
        """A fresh instance in `phase` (step: after `steps` steps of H), `params` set in initialization mode."""
        if self.c is None:
            self.instantiate()
        if phase == "instantiated":
            return
        self.need("fmi2SetupExperiment", self.c, 0, 0.0, 0.0, 0, 0.0)
        self.need("fmi2EnterInitializationMode", self.c)
        self.phase = "initialization"
        for name, x in (params or {}).items():
            self.set(name, x, need=True)
        if phase == "initialization":
            return
        self.need("fmi2ExitInitializationMode", self.c)
        self.phase = "step"
        for _ in range(steps):
            self.step()
        if phase == "terminated":
            self.need("fmi2Terminate", self.c)
            self.phase = "terminated"

    def step(self, h: float = H, accept_discard: bool = False) -> int:
        s = self.call("fmi2DoStep", self.c, self.t, h, 0)
        if s == DISCARD and accept_discard:
            return s
        if s not in (OK, WARNING):
            raise SetupError(f"fmi2DoStep({self.t!r}, {h!r}) returned {STATUS_NAME.get(s, s)}: "
                             f"{self.log[-1][1] if self.log else ''}")
        self.t += h
        return s

    def goes_on(self, accept_discard: bool = False):
        """From the current phase through initialisation to one step: the instance still works."""
        try:
            if self.phase == "instantiated":
                self.need("fmi2SetupExperiment", self.c, 0, 0.0, 0.0, 0, 0.0)
                self.need("fmi2EnterInitializationMode", self.c)
                self.phase = "initialization"
            if self.phase == "initialization":
                self.need("fmi2ExitInitializationMode", self.c)
                self.phase = "step"
            self.step(accept_discard=accept_discard)
        except SetupError as e:
            self.problem(f"the instance does not go on: {e}")

    # -- values
    def var(self, name):
        return self.vars[name]

    def get(self, name):
        v = self.var(name)
        return {"Real": self.get_real, "String": self.get_str}.get(v.type, self.get_int)(name)

    def get_real(self, name) -> float:
        out = reals(0.0)
        self.need("fmi2GetReal", self.c, vrs(self.var(name).valueReference), 1, out)
        return out[0]

    def get_int(self, name) -> int:
        out = ints(0)
        self.need("fmi2GetInteger", self.c, vrs(self.var(name).valueReference), 1, out)
        return out[0]

    def get_str(self, name) -> str:
        out = strs(None)
        self.need("fmi2GetString", self.c, vrs(self.var(name).valueReference), 1, out)
        return (out[0] or b"").decode("utf-8", "replace")

    def set(self, name, x, need: bool = False) -> int:
        v = self.var(name)
        if v.type == "Real":
            args = ("fmi2SetReal", self.c, vrs(v.valueReference), 1, reals(x))
        else:
            args = ("fmi2SetInteger", self.c, vrs(v.valueReference), 1, ints(int(x)))
        return self.need(*args) if need else self.call(*args)

    def readable(self) -> None:
        """Values are read from fmi2EnterInitializationMode on (FMI 2.0): an instance still instantiated is
        taken into initialization mode first."""
        if self.phase == "instantiated":
            self.need("fmi2SetupExperiment", self.c, 0, 0.0, 0.0, 0, 0.0)
            self.need("fmi2EnterInitializationMode", self.c)
            self.phase = "initialization"

    def refused_set(self, name, fname, values):
        """A set that must be refused: the variable keeps its value, and the message names it (before
        initialisation: the value read once in initialization mode is still the start value)."""
        v = self.var(name)
        if self.phase == "instantiated":
            before = {"Real": num, "String": str}.get(v.type, lambda x: int(float(x)))(v.start)
        else:
            before = self.get(name)
        self.probe(fname, self.c, vrs(v.valueReference), 1, values)
        self.readable()
        after = self.get(name)
        if name not in ("status", "message"):  # a refusal sets them (status 2: bad input; its message)
            self.check(same(after, before), f"{name} changed from {before!r} to {after!r}")
        msgs = [m for st, m in self.probes[-1]["messages"] if st >= ERROR]
        self.check(not msgs or name in msgs[-1], f"the message does not name {name}")

    def outputs(self) -> list:
        """Every Real and Integer output and the time reached: what a step leaves."""
        out = []
        for v in self.md.modelVariables:
            if v.causality == "output" and v.type in ("Real", "Integer"):
                out.append((v.name, self.get(v.name)))
        t = c_double(0.0)
        self.call("fmi2GetRealStatus", self.c, 2, byref(t))
        return out + [("lastSuccessfulTime", t.value)]

    # -- FMU states
    def get_state(self) -> c_void_p:
        s = c_void_p()
        self.need("fmi2GetFMUstate", self.c, byref(s))
        self.keep.append(s)
        return s

    def set_state(self, s):
        self.need("fmi2SetFMUstate", self.c, s)

    def serialize(self, s) -> bytes:
        n = c_size_t(0)
        self.need("fmi2SerializedFMUstateSize", self.c, s, byref(n))
        buf = create_string_buffer(n.value)
        self.need("fmi2SerializeFMUstate", self.c, s, buf, n.value)
        return buf.raw

    def deserialize_and_set(self, data: bytes, size: int | None = None) -> int:
        """Probe fmi2DeSerializeFMUstate, then (if it took the bytes) fmi2SetFMUstate."""
        buf = create_string_buffer(data, max(len(data), 1))
        self.keep.append(buf)
        st = c_void_p()
        s = self.probe("fmi2DeSerializeFMUstate", self.c, buf, len(data) if size is None else size, byref(st))
        if s == OK:
            s = self.probe("fmi2SetFMUstate", self.c, st)
        return s

    def refusal_leaves_state(self, action: Callable[[], object]):
        """Run `action` (a refused call) between a saved state and the next step: the step must give bit for
        bit the outputs of the same step without it."""
        saved, t = self.get_state(), self.t
        self.set_state(saved)
        self.step()
        ref = self.outputs()
        self.set_state(saved)
        self.t = t
        action()
        try:
            self.step()
        except SetupError as e:
            self.problem(f"after the refused call, the next step fails: {e}")
            return
        got = self.outputs()
        diff = [(a[0], a[1], b[1]) for a, b in zip(ref, got) if not same(a[1], b[1])]
        if diff:
            name, want, have = diff[0]
            self.problem(f"the refused call changed the instance: after the next step {name} = {have!r} "
                         f"instead of {want!r} ({len(diff)} outputs differ)")

    # -- the other FMU (contact vs spool), loaded in this process
    def other(self):
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave
        md = read_model_description(self.other_dir)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.other_dir,
                        modelIdentifier=md.coSimulation.modelIdentifier, instanceName="other")
        comp = fmu.fmi2Instantiate(b"other", 1, md.guid.encode(), b"", byref(self.callbacks), 0, 0)
        fmu.fmi2SetupExperiment(comp, 0, 0.0, 0.0, 0, 0.0)
        fmu.fmi2EnterInitializationMode(comp)
        fmu.fmi2ExitInitializationMode(comp)
        fmu.fmi2DoStep(comp, 0.0, H, 0)
        s = c_void_p()
        fmu.fmi2GetFMUstate(comp, byref(s))
        self.keep += [fmu, comp, s]
        return fmu, comp, s

    # -- the divergence rule
    def physical_ok(self) -> str | None:
        """The model's own limit, after a step that returned fmi2OK (None: respected)."""
        if self.model == "RotorCasingContact":
            gap, limit = self.get_real("gap_min"), self.get_real("max_penetration")
            if not (gap >= -limit):
                return f"gap_min = {gap!r} m is deeper than max_penetration = {limit!r} m"
        if self.model == "LPSpool":
            w = self.get_real("Omega")
            if not (w >= 0.0 and math.isfinite(w)):
                return f"Omega = {w!r} rad/s"
        return None

    def run_to_divergence(self, params: dict | None = None, max_steps: int = 50):
        """Steps (each one a probe) until one is not fmi2OK; returns (status, state saved before that step)."""
        r = RECIPES[self.model]
        self.start("step", params=dict(r["params"], **(params or {})), steps=0)
        for name, x in r["inputs"].items():
            self.set(name, x, need=True)
        before = None
        for _ in range(max_steps):
            before = self.get_state()
            s = self.probe("fmi2DoStep", self.c, self.t, H, 0)
            if s != OK:
                return s, before
            bad = self.physical_ok()
            if bad:
                self.problem(f"fmi2DoStep({self.t!r}, {H!r}) returned fmi2OK with {bad} (past the divergence "
                             "limit: this step diverged, it must be the fmi2Discard)", silent=True)
            self.t += H
        raise SetupError(f"no divergence in {max_steps} steps")


def make_callbacks(log: list):
    from fmpy.fmi2 import defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    def logger(env, name, status, category, message):
        log.append((int(status), (message or b"").decode("utf-8", "replace")))

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = defaultCallbacks.allocateMemory
    cb.freeMemory = defaultCallbacks.freeMemory
    cb._logger = cb.logger  # keep the ctypes callback alive
    return cb


# ------------------------------------------------------------------ the cases

@dataclass
class Case:
    name: str
    expected: tuple
    run: Callable[[Harness], object] = field(repr=False)
    note: str = ""


def settable(md):
    return [v for v in md.modelVariables if v.causality in ("input", "parameter") and v.type != "String"]


def num(x) -> float:
    return float(x) if x is not None else math.nan


def cases_for(md, has_other: bool) -> list[Case]:
    """Every case for the FMU of model description `md`."""
    model = md.coSimulation.modelIdentifier
    C: list[Case] = []

    def add(name, expected, run, note=""):
        C.append(Case(name, expected if isinstance(expected, tuple) else (expected,), run, note))

    by_vr = {v.valueReference: v for v in md.modelVariables}
    n_vars = max(by_vr) + 1
    gaps = [k for k in range(n_vars) if k not in by_vr]
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    real_out = next(v for v in outputs if v.type == "Real")
    int_out = next(v for v in outputs if v.type == "Integer")
    str_out = next(v for v in outputs if v.type == "String")
    first_input = next(v for v in md.modelVariables if v.causality == "input" and v.type == "Real")
    fixed = [v for v in settable(md) if v.causality == "parameter" and v.variability == "fixed"]
    setter = {"Real": "fmi2SetReal", "Integer": "fmi2SetInteger", "Enumeration": "fmi2SetInteger",
              "String": "fmi2SetString"}

    def arr(v, x):
        return reals(x) if v.type == "Real" else strs(x) if v.type == "String" else ints(int(x))

    # ---- values: every settable variable (inputs and tunables in step mode, fixed parameters before
    #      initialisation, where a master sets them)
    def bad_value(v, fname, value, phase):
        def run(h: Harness):
            h.start(phase)
            vals = reals(value) if fname == "fmi2SetReal" else ints(int(value))

            def act():
                h.refused_set(v.name, fname, vals)
            if phase == "step":
                h.refusal_leaves_state(act)
            else:
                act()
                h.goes_on()
        return run

    def good_value(v, value, phase):
        def run(h: Harness):
            h.start(phase)
            h.probe(setter[v.type], h.c, vrs(v.valueReference), 1, arr(v, value))
            h.readable()
            h.check(same(h.get(v.name), type(h.get(v.name))(value)), f"{v.name} was not stored")
            if phase != "step":
                h.goes_on(accept_discard=True)  # a value in the declared range is a model the FMU can run
        return run

    for v in settable(md):
        phase = "instantiated" if v.variability == "fixed" else "step"
        lo, hi = num(v.min), num(v.max)
        if v.type == "Real":
            values = [("below_min", math.nextafter(lo, -math.inf)), ("above_max", math.nextafter(hi, math.inf)),
                      ("nan", math.nan), ("+inf", math.inf), ("-inf", -math.inf)]
            for tag, x in values:
                if math.isnan(x) and tag != "nan":
                    continue
                add(f"set.{v.name}.{tag}", ERR_MSG, bad_value(v, "fmi2SetReal", x, phase),
                    f"{phase}: {x!r}, declared [{v.min}, {v.max}]")
            add(f"set.{v.name}.wrong_type", ERR_MSG, bad_value(v, "fmi2SetInteger", 0, phase),
                f"{phase}: fmi2SetInteger on a Real")
        else:
            for tag, x in (("below_min", lo - 1), ("above_max", hi + 1)):
                add(f"set.{v.name}.{tag}", ERR_MSG, bad_value(v, "fmi2SetInteger", x, phase),
                    f"{phase}: {int(x)}, declared [{v.min}, {v.max}]")
            add(f"set.{v.name}.wrong_type", ERR_MSG, bad_value(v, "fmi2SetReal", num(v.start), phase),
                f"{phase}: fmi2SetReal on an {v.type}")
        for tag, x in (("at_min", lo), ("at_max", hi)):
            if math.isfinite(x):
                add(f"set.{v.name}.{tag}", ALLOWED, good_value(v, x, phase), f"{phase}: {x!r}")

    def fixed_after_init(v):
        lo, hi, x0 = num(v.min), num(v.max), num(v.start)
        x = (x0 + hi) / 2 if x0 < hi else (x0 + lo) / 2
        if v.type != "Real":
            x = int(lo) if int(x0) != int(lo) else int(hi)

        def run(h: Harness):
            h.start("step")
            h.refusal_leaves_state(lambda: h.refused_set(v.name, setter[v.type], arr(v, x)))
        return run, x

    for v in fixed:
        run, x = fixed_after_init(v)
        add(f"set.{v.name}.after_init", ERR_MSG, run, f"fixed parameter set to {x!r} in step mode")

    # ---- setting every output
    def set_output(v):
        value = {"Real": 0.0, "Integer": 0, "String": b"x"}[v.type]

        def run(h: Harness):
            h.start("step")
            h.refusal_leaves_state(lambda: h.refused_set(v.name, setter[v.type], arr(v, value)))
        return run

    for v in outputs:
        add(f"set_output.{v.name}", ERR_MSG, set_output(v), f"{setter[v.type]} in step mode")

    # ---- unknown value references, wrong getters, NULL arrays, nvr = 0
    def in_step(fname, *args_of_h, note=""):
        def run(h: Harness):
            h.start("step")
            h.refusal_leaves_state(lambda: h.probe(fname, h.c, *[a(h) if callable(a) else a for a in args_of_h]))
        return run

    unknown = [("past_end", n_vars), ("0xFFFFFFFF", 0xFFFFFFFF)] + [(f"gap_{k}", k) for k in gaps]
    for tag, k in unknown:
        for fname, vals in (("fmi2GetReal", reals(0.0)), ("fmi2SetReal", reals(0.0)), ("fmi2GetInteger", ints(0)),
                            ("fmi2SetInteger", ints(0)), ("fmi2GetBoolean", ints(0)), ("fmi2SetBoolean", ints(0)),
                            ("fmi2GetString", strs(None)), ("fmi2SetString", strs(b"x"))):
            if tag == "0xFFFFFFFF" and fname not in ("fmi2GetReal", "fmi2SetReal"):
                continue
            add(f"vr.{tag}.{fname}", ERR_MSG, in_step(fname, vrs(k), 1, vals), f"value reference {k}")
    add("vr.mixed_valid_unknown.fmi2GetReal", ERR_MSG,
        in_step("fmi2GetReal", vrs(real_out.valueReference, n_vars), 2, reals(0.0, 0.0)), "[valid, unknown]")

    def all_or_nothing(h: Harness):
        h.start("step")
        v = first_input
        before = h.get(v.name)
        new = (num(v.start) + num(v.min)) / 2
        h.refusal_leaves_state(lambda: h.probe("fmi2SetReal", h.c, vrs(v.valueReference, v.valueReference), 2,
                                               reals(new, math.nan)))
        h.check(same(h.get(v.name), before), f"{v.name} took the first value of a refused call")
    add("set.all_or_nothing", ERR_MSG, all_or_nothing, f"fmi2SetReal [{first_input.name} = ok, NaN]")

    wrong_getter = [("fmi2GetInteger", real_out, ints(0)), ("fmi2GetReal", int_out, reals(0.0)),
                    ("fmi2GetString", real_out, strs(None)), ("fmi2GetBoolean", real_out, ints(0)),
                    ("fmi2GetReal", str_out, reals(0.0)), ("fmi2GetInteger", str_out, ints(0)),
                    ("fmi2SetBoolean", first_input, ints(1)), ("fmi2SetString", first_input, strs(b"1"))]
    for fname, v, vals in wrong_getter:
        add(f"wrong_type.{fname}.{v.name}", ERR_MSG, in_step(fname, vrs(v.valueReference), 1, vals), v.type)

    null_cases = [("fmi2GetReal", real_out, reals(0.0)), ("fmi2SetReal", first_input, reals(num(first_input.start))),
                  ("fmi2GetInteger", int_out, ints(0)), ("fmi2SetInteger", int_out, ints(0)),
                  ("fmi2GetBoolean", real_out, ints(0)), ("fmi2SetBoolean", real_out, ints(0)),
                  ("fmi2GetString", str_out, strs(None)), ("fmi2SetString", str_out, strs(b"x"))]
    for fname, v, vals in null_cases:
        add(f"null.{fname}.vr_NULL", ERR_MSG, in_step(fname, None, 1, vals), "nvr = 1, vr = NULL")
        add(f"null.{fname}.value_NULL", ERR_MSG, in_step(fname, vrs(v.valueReference), 1, None),
            "nvr = 1, value = NULL")

        def zero(h: Harness, fname=fname):
            h.start("step")
            h.probe(fname, h.c, None, 0, None)
            h.step()
        add(f"null.{fname}.nvr_0", ALLOWED, zero, "nvr = 0, both arrays NULL")

    # ---- the calling sequence
    def seq(phase, fname, *args, then=None, params=None):
        def run(h: Harness):
            h.start(phase, params=params)

            def act():
                h.probe(fname, h.c, *args)
            if phase == "step" and fname != "fmi2DoStep":
                h.refusal_leaves_state(act)
            else:
                act()
            if then:
                then(h)
        return run

    def can_init(h: Harness):  # the instance goes on from where it was
        h.goes_on()

    add("doStep.before_init", ERR_MSG, seq("instantiated", "fmi2DoStep", 0.0, H, 0, then=can_init))
    add("doStep.in_initialization_mode", ERR_MSG, seq("initialization", "fmi2DoStep", 0.0, H, 0, then=can_init))
    add("doStep.after_terminate", ERR_MSG, seq("terminated", "fmi2DoStep", 3 * H, H, 0))

    def reset_then_step(h: Harness):
        h.start("step")
        h.need("fmi2Reset", h.c)
        h.phase, h.t = "instantiated", 0.0
        h.probe("fmi2DoStep", h.c, 0.0, H, 0)
        h.goes_on()
    add("doStep.after_reset_without_init", ERR_MSG, reset_then_step)
    add("enterInit.twice", ERR_MSG, seq("initialization", "fmi2EnterInitializationMode", then=can_init))
    add("enterInit.in_step_mode", ERR_MSG, seq("step", "fmi2EnterInitializationMode"))
    add("enterInit.after_terminate", ERR_MSG, seq("terminated", "fmi2EnterInitializationMode"))
    add("exitInit.without_enter", ERR_MSG, seq("instantiated", "fmi2ExitInitializationMode", then=can_init))
    add("exitInit.twice", ERR_MSG, seq("step", "fmi2ExitInitializationMode"))
    add("setupExperiment.in_initialization_mode", ERR_MSG,
        seq("initialization", "fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0, then=can_init))
    add("setupExperiment.in_step_mode", ERR_MSG, seq("step", "fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0))
    add("setupExperiment.startTime_nan", ERR_MSG,
        seq("instantiated", "fmi2SetupExperiment", 0, 0.0, math.nan, 0, 0.0, then=can_init))
    add("setupExperiment.stop_before_start", ERR_MSG,
        seq("instantiated", "fmi2SetupExperiment", 0, 0.0, 1.0, 1, 0.5, then=can_init))
    add("setupExperiment.twice", ALLOWED, seq("instantiated", "fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0,
                                              then=can_init))
    add("terminate.twice", ERR_MSG, seq("terminated", "fmi2Terminate"))
    add("terminate.before_init", ERR_MSG, seq("instantiated", "fmi2Terminate", then=can_init))
    add("terminate.in_initialization_mode", ERR_MSG, seq("initialization", "fmi2Terminate"),
        "FMI 2.0 calling-sequence table: fmi2Terminate only in stepComplete/stepFailed")
    add("getReal.before_init", ERR_MSG, seq("instantiated", "fmi2GetReal", vrs(real_out.valueReference), 1,
                                            reals(0.0)),
        "FMI 2.0 calling-sequence table: no fmi2Get* in the instantiated state")
    add("set_input.after_terminate", ERR_MSG,
        seq("terminated", "fmi2SetReal", vrs(first_input.valueReference), 1, reals(num(first_input.start))))
    add("getReal.after_terminate", ALLOWED, seq("terminated", "fmi2GetReal", vrs(real_out.valueReference), 1,
                                                reals(0.0)))

    def reset_in(phase):
        def run(h: Harness):
            h.start(phase)
            h.probe("fmi2Reset", h.c)
            h.phase, h.t = "instantiated", 0.0
            h.goes_on()
        return run
    for phase in Harness.PHASES:
        add(f"reset.in_{phase}", ALLOWED, reset_in(phase), "then initialise and step again")

    def set_tunable_in_init(h: Harness):
        h.start("initialization")
        v = first_input
        h.probe("fmi2SetReal", h.c, vrs(v.valueReference), 1, reals(num(v.start)))
        h.goes_on()
    add("set_input.in_initialization_mode", ALLOWED, set_tunable_in_init)

    # ---- steps
    def bad_step(t_of, h_step):
        def run(h: Harness):
            h.start("step")
            h.refusal_leaves_state(lambda: h.probe("fmi2DoStep", h.c, t_of(h), h_step, 0))
        return run

    add("doStep.t_ahead", ERR_MSG, bad_step(lambda h: h.t + H / 2, H), "currentCommunicationPoint = time + h/2")
    add("doStep.t_behind", ERR_MSG, bad_step(lambda h: h.t - H, H), "currentCommunicationPoint = time - h")
    add("doStep.t_nan", ERR_MSG, bad_step(lambda h: math.nan, H))
    add("doStep.t_inf", ERR_MSG, bad_step(lambda h: math.inf, H))
    for tag, hs in (("0", 0.0), ("negative", -H), ("nan", math.nan), ("+inf", math.inf), ("-inf", -math.inf)):
        add(f"doStep.h_{tag}", ERR_MSG, bad_step(lambda h: h.t, hs), f"communicationStepSize = {hs!r}")

    def t_within_tolerance(h: Harness):
        h.start("step")
        h.probe("fmi2DoStep", h.c, h.t * (1 + 1e-12), H, 0)
        h.t += H
        h.step()
    add("doStep.t_within_tolerance", ALLOWED, t_within_tolerance, "time * (1 + 1e-12): the FMU's 1e-9 tolerance")

    def odd_step(hs: float):
        """A step size the standard allows: computed right, or refused with a message."""
        def run(h: Harness):
            h.start("step")
            if h.model == "LPSpool":
                h.set("friction_torque", 10.0, need=True)  # a spool that is not exactly on its schedule
            saved, t = h.get_state(), h.t
            s = h.probe("fmi2DoStep", h.c, h.t, hs, 0)
            if s == OK:
                h.t += hs
                if h.model == "RotorCasingContact":
                    dt, dt_max = h.get_real("dt_internal"), h.get_real("dt_max")
                    h.check(dt <= dt_max, f"fmi2OK with dt_internal = {dt!r} s > dt_max = {dt_max!r} s "
                            f"(n_substeps = {h.get_int('n_substeps')})", silent=True)
                    bad = h.physical_ok()
                    h.check(not bad, f"fmi2OK with {bad}", silent=True)
                if h.model == "LPSpool" and hs > 1e3:
                    w1, cw, tau = h.get_real("Omega1"), h.get_real("c_w"), 10.0
                    want = math.sqrt(w1 * w1 + tau / cw)  # the steady state of J dw/dt = drive - c_w w^2 + tau
                    w = h.get_real("Omega")
                    h.check(abs(w - want) <= 1e-6 * want, f"fmi2OK with Omega = {w!r} rad/s after {hs!r} s "
                            f"instead of the steady state {want!r}", silent=True)
                h.step(accept_discard=True)  # and the run goes on
            elif s == ERROR:
                h.set_state(saved)  # is a refused step without effect? compare with the state before it
                h.t = t
                h.refusal_leaves_state(lambda: h.probe("fmi2DoStep", h.c, h.t, hs, 0))
        return run

    add("doStep.h_tiny_1e-300", (ALLOWED, ERR_MSG), odd_step(1e-300), "computed, or refused with a message")
    add("doStep.h_huge_1e6", (ALLOWED, ERR_MSG), odd_step(1e6), "computed within the timeout, or refused")
    add("doStep.h_huge_1e12", (ALLOWED, ERR_MSG), odd_step(1e12), "ceil(h / cap) substeps overflow an int")

    # ---- FMU states
    def state_in(phase):
        def run(h: Harness):
            h.start(phase)
            s = h.get_state()
            ref = None
            if phase == "step":
                h.step()
                ref = h.outputs()
                h.t -= H
            h.probe("fmi2SetFMUstate", h.c, s)
            if phase == "step":
                h.step()
                h.check(h.outputs() == ref, "the step after the rollback differs from the step before it")
            elif phase == "terminated":
                h.check(h.call("fmi2DoStep", h.c, h.t, H, 0) == ERROR, "fmi2DoStep after restoring a terminated "
                        "state was not refused")
            else:
                h.goes_on()
        return run
    for phase in Harness.PHASES:
        add(f"state.get_set.{phase}", ALLOWED, state_in(phase), "fmi2GetFMUstate then fmi2SetFMUstate")

    def state_after_reset(h: Harness):
        h.start("step")
        s, t = h.get_state(), h.t
        h.step()
        ref = h.outputs()
        h.need("fmi2Reset", h.c)
        h.probe("fmi2SetFMUstate", h.c, s)
        h.phase, h.t = "step", t
        h.step()
        h.check(h.outputs() == ref, "the run restored after fmi2Reset does not continue bit for bit")
    add("state.of_run_after_reset", ALLOWED, state_after_reset, "a state of the run restored in the instantiated "
        "state (fmusim's --initial-fmu-state-file)")

    def instantiated_state_in_step(h: Harness):
        h.instantiate()
        s = h.get_state()
        h.start("step")
        h.probe("fmi2SetFMUstate", h.c, s)
        h.phase, h.t = "instantiated", 0.0
        h.goes_on()
    add("state.instantiated_restored_in_step", ALLOWED, instantiated_state_in_step, "then initialise again")

    def garbage_ptr(fill=0xAB, n=1 << 16):
        buf = create_string_buffer(bytes([fill]) * n, n)
        return buf, c_void_p(addressof(buf))

    def state_set(arg_of_h, note=""):
        def run(h: Harness):
            h.start("step")
            arg = arg_of_h(h)
            h.refusal_leaves_state(lambda: h.probe("fmi2SetFMUstate", h.c, arg))
        return run

    def garbage_state(h):
        buf, p = garbage_ptr()
        h.keep.append(buf)
        return p
    add("state.set_NULL", ERR_MSG, state_set(lambda h: None))
    add("state.set_garbage_pointer", ERR_MSG, state_set(garbage_state), "64 KiB of 0xAB")

    def get_into_garbage(h: Harness):
        h.start("step")
        buf, p = garbage_ptr()
        holder = c_void_p(p.value)
        h.keep += [buf, holder]
        h.refusal_leaves_state(lambda: h.probe("fmi2GetFMUstate", h.c, byref(holder)))
    add("state.get_into_garbage", ERR_MSG, get_into_garbage, "*FMUstate points to garbage")

    def free_null(ptr_null: bool):
        def run(h: Harness):
            h.start("step")
            h.probe("fmi2FreeFMUstate", h.c, None if ptr_null else byref(c_void_p()))
            h.step()
        return run
    add("state.free_NULL", ALLOWED, free_null(True), "fmi2FreeFMUstate(c, NULL)")
    add("state.free_pointer_to_NULL", ALLOWED, free_null(False), "fmi2FreeFMUstate(c, &NULL)")

    def free_twice(h: Harness):
        h.start("step")
        s = h.get_state()
        h.need("fmi2FreeFMUstate", h.c, byref(s))  # sets s to NULL
        h.probe("fmi2FreeFMUstate", h.c, byref(s))
        h.step()
    add("state.free_twice", ALLOWED, free_twice, "the first call set the pointer to NULL")

    def get_into_existing(h: Harness):
        h.start("step")
        s, t = h.get_state(), h.t
        h.step()
        h.probe("fmi2GetFMUstate", h.c, byref(s))  # the standard: an existing state is overwritten
        h.step()
        ref = h.outputs()
        h.set_state(s)
        h.t = t + H
        h.step()
        h.check(h.outputs() == ref, "the overwritten state does not restore the later time")
    add("state.get_into_existing", ALLOWED, get_into_existing, "fmi2GetFMUstate with *FMUstate a state: overwritten")

    def get_null_pointer(h: Harness):
        h.start("step")
        h.refusal_leaves_state(lambda: h.probe("fmi2GetFMUstate", h.c, None))
    add("state.get_NULL_pointer", ERR_MSG, get_null_pointer, "fmi2GetFMUstate(c, NULL)")

    def free_garbage(h: Harness):
        h.start("step")
        buf, p = garbage_ptr()
        holder = c_void_p(p.value)
        h.keep += [buf, holder]
        h.refusal_leaves_state(lambda: h.probe("fmi2FreeFMUstate", h.c, byref(holder)))
    add("state.free_garbage", ERR_MSG, free_garbage)

    def size_of_null(h: Harness):
        h.start("step")
        n = c_size_t(0)
        h.refusal_leaves_state(lambda: h.probe("fmi2SerializedFMUstateSize", h.c, None, byref(n)))
    add("state.serialized_size_of_NULL", ERR_MSG, size_of_null)

    def serialize_small_buffer(h: Harness):
        h.start("step")
        s = h.get_state()
        n = c_size_t(0)
        h.need("fmi2SerializedFMUstateSize", h.c, s, byref(n))
        buf = create_string_buffer(n.value)
        h.refusal_leaves_state(lambda: h.probe("fmi2SerializeFMUstate", h.c, s, buf, n.value - 1))
    add("state.serialize_into_small_buffer", ERR_MSG, serialize_small_buffer, "size - 1")

    def deser_null(which):
        def run(h: Harness):
            h.start("step")
            data = h.serialize(h.get_state())
            buf = create_string_buffer(data, len(data))
            st = c_void_p()
            args = (None, len(data), byref(st)) if which == "bytes" else (buf, len(data), None)
            h.refusal_leaves_state(lambda: h.probe("fmi2DeSerializeFMUstate", h.c, *args))
        return run
    add("state.deserialize_NULL_bytes", ERR_MSG, deser_null("bytes"))
    add("state.deserialize_into_NULL", ERR_MSG, deser_null("state"))

    if has_other:
        def other_in_memory(h: Harness):
            h.start("step")
            _, _, s = h.other()
            h.refusal_leaves_state(lambda: h.probe("fmi2SetFMUstate", h.c, s))
        add("state.of_other_fmu", ERR_MSG, other_in_memory, "fmi2GetFMUstate of the other native FMU, in this process")

        def other_serialized(h: Harness):
            h.start("step")
            fmu, comp, s = h.other()
            n = c_size_t(0)
            fmu.fmi2SerializedFMUstateSize(comp, s, byref(n))
            buf = create_string_buffer(n.value)
            fmu.fmi2SerializeFMUstate(comp, s, buf, n.value)
            h.refusal_leaves_state(lambda: h.deserialize_and_set(buf.raw))
        add("state.serialized_of_other_fmu", ERR_MSG, other_serialized)

    # serialized states: the layout is fmi2_cs.c's (magic 4, GUID 64, phase, n_vars, n_model, stopped 8 each,
    # time, last_good 8 each, then r[n_vars] doubles, i[n_vars] ints, message and stop_reason 1024 each, model)
    HEAD, MSG = 4 + 64 + 4 * 8 + 2 * 8, 1024
    R0, I0 = HEAD, HEAD + 8 * n_vars
    MODEL0 = I0 + 4 * n_vars + 2 * MSG

    def put(data: bytes, at: int, fmt: str, value) -> bytes:
        b = bytearray(data)
        struct.pack_into(fmt, b, at, value)
        return bytes(b)

    enum_var = next((v for v in settable(md) if v.type == "Enumeration"), None)
    corruptions: list[tuple[str, Callable[[bytes], bytes], str]] = [
        ("truncated_by_1", lambda d: d[:-1], ""),
        ("truncated_to_100_bytes", lambda d: d[:100], "shorter than the header"),
        ("empty", lambda d: b"", "size 0"),
        ("extended_by_1", lambda d: d + b"\0", ""),
        ("random_bytes", lambda d: random.Random(1).randbytes(len(d)), "right size"),
        ("zeros", lambda d: bytes(len(d)), "right size"),
        ("magic", lambda d: put(d, 0, "<I", 0x12345678), ""),
        ("guid", lambda d: d[:5] + bytes([d[5] ^ 1]) + d[6:], "one character"),
        ("phase_9", lambda d: put(d, 68, "<Q", 9), ""),
        ("n_vars_plus_1", lambda d: put(d, 76, "<Q", n_vars + 1), ""),
        ("n_model_huge", lambda d: put(d, 84, "<Q", 10**12), ""),
        ("stopped_7", lambda d: put(d, 92, "<Q", 7), ""),
        ("time_nan", lambda d: put(d, 100, "<d", math.nan), ""),
        (f"{first_input.name}_above_max", lambda d: put(d, R0 + 8 * first_input.valueReference, "<d",
                                                         2 * num(first_input.max) + 1), ""),
        (f"{first_input.name}_nan", lambda d: put(d, R0 + 8 * first_input.valueReference, "<d", math.nan), ""),
        ("model_tag", lambda d: put(d, MODEL0, "<d", 12345.0), "the model's first double"),
        ("model_second_nan", lambda d: put(d, MODEL0 + 8, "<d", math.nan), ""),
        ("model_last_nan", lambda d: put(d, len(d) - 8, "<d", math.nan), ""),
        ("phase_step_without_model", lambda d: put(d[:MODEL0], 84, "<Q", 0), "n_model = 0, size to match"),
    ]
    if enum_var is not None:
        corruptions.append((f"{enum_var.name}_out_of_range",
                            lambda d: put(d, I0 + 4 * enum_var.valueReference, "<i", int(num(enum_var.max)) + 1), ""))

    def corrupt(fn):
        def run(h: Harness):
            h.start("step")
            data = fn(h.serialize(h.get_state()))
            h.refusal_leaves_state(lambda: h.deserialize_and_set(data))
        return run
    for tag, fn, note in corruptions:
        add(f"serialized.{tag}", ERR_MSG, corrupt(fn), note or "refused by fmi2DeSerializeFMUstate or fmi2SetFMUstate")

    def serialized_in_fresh_instance(h: Harness):
        h.start("step")
        data = h.serialize(h.get_state())
        t = h.t
        h.step()
        ref = h.outputs()
        h.call("fmi2FreeInstance", h.c)
        h.c = None
        h.instantiate()
        h.deserialize_and_set(data)
        h.phase, h.t = "step", t
        h.step()
        h.check(h.outputs() == ref, "the deserialized run does not continue bit for bit")
    add("serialized.into_fresh_instance", ALLOWED, serialized_in_fresh_instance, "the standard's use of a serialized "
        "state")

    # ---- the divergence rule
    def diverge(h: Harness):
        s, _ = h.run_to_divergence()
        if s != DISCARD:
            return
        b, t = c_int(0), c_double(math.nan)
        h.check(h.call("fmi2GetBooleanStatus", h.c, 3, byref(b)) == OK and b.value == 1,
                "fmi2GetBooleanStatus(fmi2Terminated) is not true after the discard")
        h.check(h.call("fmi2GetRealStatus", h.c, 2, byref(t)) == OK and h.t <= t.value <= h.t + H,
                f"fmi2LastSuccessfulTime = {t.value!r} is not in the discarded step [{h.t!r}, {h.t + H!r}]")
        h.check(h.get_int("status") == 1, f"status = {h.get_int('status')} after the discard, not 1")
        h.check(h.get_str("message") != "", "the 'message' output is empty after the discard")
    add("diverge.step", DIS_MSG, diverge, "the step that diverges; then fmi2Terminated true, status 1")

    def after_divergence(fname, *args, then=None):
        def run(h: Harness):
            s, before = h.run_to_divergence()
            if s != DISCARD:
                h.problem(f"the run did not end by a discard ({STATUS_NAME.get(s, s)})")
                return
            h.probes.clear()  # the case is the call after the discard
            h.probe(fname, h.c, *[a(h, before) if callable(a) else a for a in args])
            if then:
                then(h, before)
        return run

    def still_terminated(h: Harness, before):
        b = c_int(0)
        h.call("fmi2GetBooleanStatus", h.c, 3, byref(b))
        h.check(b.value == 1, "fmi2Terminated is no longer true after the refused step")

    def goes_on_after_rollback(h: Harness, before):
        b = c_int(1)
        h.call("fmi2GetBooleanStatus", h.c, 3, byref(b))
        h.check(b.value == 0, "fmi2Terminated still true after the rollback")
        for name, x in RECIPES[h.model]["recover"].items():
            h.set(name, x, need=True)
        h.goes_on()

    def goes_on_after_reset(h: Harness, before):
        h.phase, h.t = "instantiated", 0.0
        b = c_int(1)
        h.call("fmi2GetBooleanStatus", h.c, 3, byref(b))
        h.check(b.value == 0, "fmi2Terminated still true after fmi2Reset")
        h.goes_on()

    add("diverge.then_doStep", ERR_MSG, after_divergence("fmi2DoStep", lambda h, b: h.t, H, 0, then=still_terminated),
        "the FMU ended the run: a further step is fmi2Error")
    add("diverge.then_doStep_from_last_successful_time", ERR_MSG,
        after_divergence("fmi2DoStep", lambda h, b: last_successful(h), H, 0, then=still_terminated))
    add("diverge.then_rollback", ALLOWED, after_divergence("fmi2SetFMUstate", lambda h, b: b,
                                                           then=goes_on_after_rollback),
        "fmi2SetFMUstate to the state before the step, then a step with " +
        ", ".join(f"{k} = {x}" for k, x in RECIPES[model]["recover"].items()))
    add("diverge.then_reset", ALLOWED, after_divergence("fmi2Reset", then=goes_on_after_reset))
    add("diverge.then_terminate", ALLOWED, after_divergence("fmi2Terminate"))
    add("diverge.then_set_input", ERR_MSG,
        after_divergence("fmi2SetReal", vrs(first_input.valueReference), 1, reals(num(first_input.start))),
        "FMI 2.0 calling-sequence table: no fmi2Set* in stepFailed")

    if model == "RotorCasingContact":
        def last_substep(h: Harness):
            h.run_to_divergence(params={"g0": -5e-7})
        add("diverge.in_a_last_substep", DIS_MSG, last_substep, "g0 = -0.5 um, max_penetration = 10 um: the limit is "
            "crossed at the end of a step (no step may return fmi2OK past it)")

        def g0_rule_at_init(h: Harness):
            h.start("initialization", params={"max_penetration": 1e-5, "g0": -1e-4})
            h.probe("fmi2ExitInitializationMode", h.c)
            h.set("g0", 0.0, need=True)
            h.goes_on()
        add("rule.g0_deeper_than_max_penetration.exitInit", ERR_MSG, g0_rule_at_init,
            "g0 = -0.1 mm, max_penetration = 0.01 mm; then g0 = 0 and fmi2ExitInitializationMode again")
        add("rule.g0_deeper_than_max_penetration.step_mode", ERR_MSG,
            seq("step", "fmi2SetReal", vrs(by_name(md, "g0")), 1, reals(-2e-5), params={"max_penetration": 1e-5}),
            "g0 = -0.02 mm with max_penetration = 0.01 mm, during the run")

    # ---- logging, status queries, what is not provided
    def debug_logging(n, cats, expected):
        def run(h: Harness):
            h.start("step")

            def act():
                h.probe("fmi2SetDebugLogging", h.c, 1, n, cats)
            if expected == ALLOWED:
                act()
                h.step()
            else:
                h.refusal_leaves_state(act)
        return run
    add("debugLogging.unknown_category", ERR_MSG, debug_logging(1, strs(b"logEverything"), ERR_MSG))
    add("debugLogging.known_and_unknown", ERR_MSG, debug_logging(2, strs(b"logAll", b"nope"), ERR_MSG))
    add("debugLogging.categories_NULL", ERR_MSG, debug_logging(1, None, ERR_MSG), "nCategories = 1, NULL array")
    add("debugLogging.category_NULL", ERR_MSG, debug_logging(1, strs(None), ERR_MSG), "a NULL category")
    add("debugLogging.known_categories", ALLOWED, debug_logging(2, strs(b"logStatusError", b"logAll"), ALLOWED))
    add("debugLogging.no_category", ALLOWED, debug_logging(0, None, ALLOWED))

    status_calls = {"fmi2GetRealStatus": (c_double, (0, 1, 3, 99)), "fmi2GetIntegerStatus": (c_int, (0, 1, 2, 3)),
                    "fmi2GetStringStatus": (c_char_p, (0, 1, 2, 3)), "fmi2GetBooleanStatus": (c_int, (0, 1, 2)),
                    "fmi2GetStatus": (c_int, (0, 1))}
    for fname, (ctype, kinds) in status_calls.items():
        for k in kinds:
            def run(h: Harness, fname=fname, ctype=ctype, k=k):
                h.start("step")
                out = ctype()
                h.probe(fname, h.c, k, byref(out))
                h.step()
            add(f"status.{fname}.{KINDS.get(k, k)}", DIS_ALLOWED, run, "a kind not provided: fmi2Discard")
    for fname, ctype, k in (("fmi2GetRealStatus", c_double, 2), ("fmi2GetBooleanStatus", c_int, 3)):
        def run(h: Harness, fname=fname, ctype=ctype, k=k):
            h.start("step")
            h.probe(fname, h.c, k, byref(ctype()))
        add(f"status.{fname}.{KINDS[k]}", ALLOWED, run)

        def null_value(h: Harness, fname=fname, k=k):
            h.start("step")
            h.probe(fname, h.c, k, None)
            h.step()
        add(f"status.{fname}.{KINDS[k]}.value_NULL", (ERR_MSG, DIS_ALLOWED), null_value, "a NULL value pointer")

    out_vr = real_out.valueReference
    in_vr = first_input.valueReference
    add("derivatives.setRealInputDerivatives", ERR_MSG,
        in_step("fmi2SetRealInputDerivatives", vrs(in_vr), 1, ints(1), reals(1.0)))
    add("derivatives.getRealOutputDerivatives", ERR_MSG,
        in_step("fmi2GetRealOutputDerivatives", vrs(out_vr), 1, ints(1), reals(0.0)))
    add("derivatives.getDirectionalDerivative", ERR_MSG,
        in_step("fmi2GetDirectionalDerivative", vrs(out_vr), 1, vrs(in_vr), 1, reals(1.0), reals(0.0)))
    add("cancelStep", ERR_MSG, in_step("fmi2CancelStep"))

    # ---- instantiation
    def inst(name=b"fuzz", kind=1, guid="ours", callbacks="ours"):
        def run(h: Harness):
            from fmpy.fmi2 import fmi2CallbackFunctions
            cb = h.callbacks
            if callbacks is None:
                cb_arg = None
            else:
                if callbacks == "no_logger":
                    cb = fmi2CallbackFunctions()
                    cb.allocateMemory, cb.freeMemory = h.callbacks.allocateMemory, h.callbacks.freeMemory
                elif callbacks == "no_allocator":
                    cb = fmi2CallbackFunctions()
                    cb.logger = h.callbacks.logger
                h.keep.append(cb)
                cb_arg = byref(cb)
            g = h.md.guid.encode() if guid == "ours" else guid
            h.probe("fmi2Instantiate", name, kind, g, Path(h.dir, "resources").as_uri().encode(), cb_arg, 0, 0)
        return run
    add("instantiate.wrong_guid", ERR_MSG, inst(guid=b"{00000000-0000-0000-0000-000000000000}"))
    add("instantiate.empty_guid", ERR_MSG, inst(guid=b""))
    add("instantiate.NULL_guid", ERR_MSG, inst(guid=None))
    add("instantiate.model_exchange", ERR_MSG, inst(kind=0), "fmuType = fmi2ModelExchange")
    add("instantiate.fmuType_7", ERR_MSG, inst(kind=7))
    add("instantiate.empty_name", ERR_MSG, inst(name=b""))
    add("instantiate.NULL_name", ERR_MSG, inst(name=None))
    add("instantiate.NULL_callbacks", ERR_NOMSG, inst(callbacks=None), "returns NULL: no logger to tell")
    add("instantiate.callbacks_without_logger", ERR_NOMSG, inst(callbacks="no_logger"),
        "returns NULL: FMI 2.0 makes the logger mandatory")
    add("instantiate.callbacks_without_allocator", ALLOWED, inst(callbacks="no_allocator"),
        "the FMU does not use the master's allocator")

    def two_instances(h: Harness):
        h.start("step")
        ref_t = h.t
        saved = h.get_state()
        h.step()
        ref = h.outputs()
        h.set_state(saved)
        h.t = ref_t
        other = h.call("fmi2Instantiate", b"second", 1, h.md.guid.encode(), b"", byref(h.callbacks), 0, 0)
        h.probes.append({"call": "fmi2Instantiate (second)", "status": OK if other else ERROR, "messages": []})
        if other:
            h.call("fmi2SetupExperiment", other, 0, 0.0, 0.0, 0, 0.0)
            h.call("fmi2EnterInitializationMode", other)
            h.call("fmi2ExitInitializationMode", other)
            for k in range(5):
                h.call("fmi2DoStep", other, k * H, H, 0)
            h.call("fmi2FreeInstance", other)
        h.step()
        h.check(h.outputs() == ref, "a second instance changed the first one's run")
    add("instantiate.second_instance", ALLOWED, two_instances, "two instances do not share state")

    # ---- a NULL instance (no logger can be reached)
    add("null_instance.doStep", ERR_NOMSG, lambda h: h.probe("fmi2DoStep", None, 0.0, H, 0))
    add("null_instance.setReal", ERR_NOMSG, lambda h: h.probe("fmi2SetReal", None, vrs(in_vr), 1, reals(0.0)))
    add("null_instance.getFMUstate", ERR_NOMSG, lambda h: h.probe("fmi2GetFMUstate", None, byref(c_void_p())))

    def free_null_instance(h: Harness):
        h.call("fmi2FreeInstance", None)
        h.probes.append({"call": "fmi2FreeInstance(NULL)", "status": OK, "messages": []})
    add("null_instance.freeInstance", ALLOWED, free_null_instance, "a no-op (void)")

    names = [c.name for c in C]
    assert len(names) == len(set(names)), "case names must be unique"
    return C


def by_name(md, name) -> int:
    return next(v.valueReference for v in md.modelVariables if v.name == name)


def last_successful(h: Harness) -> float:
    t = c_double(math.nan)
    h.call("fmi2GetRealStatus", h.c, 2, byref(t))
    return t.value


# ------------------------------------------------------------------ one case (the child)

def run_case(name: str, fmu: str, other: str | None) -> int:
    unzipdir = extracted(fmu)
    h = Harness(unzipdir, extracted(other) if other else None)
    case = {c.name: c for c in cases_for(h.md, other is not None)}[name]
    t0 = time.perf_counter()
    try:
        case.run(h)
    except SetupError as e:
        h.problem(f"setup: {e}")
    res = {"probes": h.probes, "problems": h.problems, "silent": h.silent, "seconds": time.perf_counter() - t0}
    print("RESULT " + json.dumps(res), flush=True)
    return 0


def extracted(path: str | None) -> str | None:
    if path is None or Path(path).is_dir():
        return path
    from fmpy import extract
    return extract(path)


# ------------------------------------------------------------------ the parent

def classify(res: dict, expected: tuple) -> str:
    if not res["probes"]:
        return "no probe (setup failed)"
    bad = [p for p in res["probes"] if p["status"] != OK]
    p = bad[0] if bad else res["probes"][-1]
    st = p["status"]
    msgs = [m for s, m in p["messages"] if s >= max(st, DISCARD)]
    if res["silent"]:
        return SILENT
    if st in (OK, WARNING):
        return ALLOWED if ALLOWED in expected else SILENT
    if st == DISCARD:
        return DIS_ALLOWED if DIS_ALLOWED in expected else DIS_MSG if msgs else "discard, no message"
    if st == ERROR:
        return ERR_MSG if msgs else ERR_NOMSG
    if st == FATAL:
        return FATAL_
    return f"status {st}"


def run_one(case: Case, fmu_label: str, fmu: str, other: str | None, timeout: float) -> dict:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--case", case.name, "--fmu", fmu]
    if other:
        cmd += ["--other", other]
    row = {"fmu": fmu_label, "case": case.name, "expected": " | ".join(case.expected), "note": case.note}
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=str(REPO))
    except subprocess.TimeoutExpired:
        row.update(observed=HANG, detail=f"no answer in {timeout:g} s", seconds=timeout, probes=[], problems=[])
        row["as_expected"] = False
        return row
    row["seconds"] = round(time.perf_counter() - t0, 3)
    line = next((ln for ln in p.stdout.splitlines() if ln.startswith("RESULT ")), None)
    if p.returncode < 0:
        try:
            sig = signal.Signals(-p.returncode).name
        except ValueError:
            sig = str(-p.returncode)
        row.update(observed=CRASH, detail=f"killed by {sig}: {p.stderr.strip()[-300:]}", probes=[], problems=[])
    elif line is None:
        row.update(observed="harness error", detail=(p.stderr.strip() or p.stdout.strip())[-600:], probes=[],
                   problems=[])
    else:
        res = json.loads(line[len("RESULT "):])
        row.update(observed=classify(res, case.expected), probes=res["probes"], problems=res["problems"])
        bad = [q for q in res["probes"] if q["status"] != OK] or res["probes"][-1:]
        msg = " | ".join(m for _, m in bad[0]["messages"]) if bad else ""
        row["detail"] = "; ".join(res["problems"] + ([msg] if msg else []))
    row["as_expected"] = row["observed"] in case.expected and not row.get("problems")
    return row


def summary(label: str, rows: list[dict]) -> str:
    n = len(rows)

    def count(*labels):
        return sum(r["observed"] in labels for r in rows)
    refused, allowed = count(*REFUSED), count(*ALLOWED_ALL)
    s, f, c, hg = count(SILENT), count(FATAL_), count(CRASH), count(HANG)
    other = n - refused - allowed - s - f - c - hg
    differ = sum(not r["as_expected"] for r in rows)
    line = (f"{label}: {n} cases: {refused} refused with a message, {allowed} allowed OK, {s} silent OK, {f} fatal, "
            f"{c} crashes, {hg} hangs")
    if other:
        line += f"; {other} other ({count(ERR_NOMSG)} refused with no logger to tell)"
    return line + f"; {differ} not as expected"


def build_fmus(dest: Path) -> list[str]:
    sys.path.insert(0, str(REPO))
    from fmu_src.models.contact.builder import build_native_fmu
    from fmu_src.models.spool.builder import build_native_spool_fmu
    contact = build_native_fmu(dest / "contact", platforms=("linux64",))["fmu"]
    spool = build_native_spool_fmu(dest / "spool", platforms=("linux64",))
    return [str(contact), str(spool)]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fmu", action="append", help="an FMU (file or extracted folder); default: build both")
    ap.add_argument("--case", help="run one case (in this process) and print its RESULT line")
    ap.add_argument("--other", help="with --case: the other FMU, for the foreign-state cases")
    ap.add_argument("--json", type=Path, help="write the table (with every logged message) to this file")
    ap.add_argument("--only", help="only the cases whose name contains this text")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds before a case is a HANG (30)")
    ap.add_argument("--jobs", type=int, default=2, help="cases at once (2)")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    a = ap.parse_args(argv)

    if a.case:
        return run_case(a.case, a.fmu[0], a.other)

    from fmpy import extract, read_model_description
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="fuzz_fmi_") as tmp:
        fmus = a.fmu or build_fmus(Path(tmp))
        dirs = [p if Path(p).is_dir() else extract(p, unzipdir=str(Path(tmp) / f"x{k}")) for k, p in enumerate(fmus)]
        work = []  # (case, label, dir, other dir)
        for k, d in enumerate(dirs):
            other = dirs[1 - k] if len(dirs) == 2 else None
            md = read_model_description(d)
            label = md.coSimulation.modelIdentifier
            for case in cases_for(md, other is not None):
                if a.only and a.only not in case.name:
                    continue
                work.append((case, label, d, other))
        if a.list:
            for case, label, _, _ in work:
                print(f"{label:20s} {case.name:60s} {' | '.join(case.expected):28s} {case.note}")
            return 0
        order = {(w[1], w[0].name): i for i, w in enumerate(work)}  # the table keeps the cases' order
        work.sort(key=lambda w: "huge" not in w[0].name)  # the slowest first: no lone tail at the end
        print(f"{len(work)} cases on {len(dirs)} FMU(s), {a.jobs} at a time, timeout {a.timeout:g} s", file=sys.stderr)
        with ThreadPoolExecutor(max_workers=a.jobs) as pool:
            rows = list(pool.map(lambda w: run_one(w[0], w[1], w[2], w[3], a.timeout), work))
    elapsed = time.perf_counter() - t_start

    rows.sort(key=lambda r: (r["fmu"], order[(r["fmu"], r["case"])]))
    wc = max(len(r["case"]) for r in rows)
    print(f"{'FMU':18s} {'case':{wc}s} {'expected':28s} {'observed':18s}   detail (the FMU's message)")
    for r in rows:
        mark = "  " if r["as_expected"] else "!!"
        detail = (r.get("detail") or r["note"]).replace("\n", " ")
        print(f"{r['fmu']:18s} {r['case']:{wc}s} {r['expected']:28s} {r['observed']:18s} {mark} {detail[:160]}")
    print()
    labels = sorted({r["fmu"] for r in rows})
    for label in labels:
        print(summary(label, [r for r in rows if r["fmu"] == label]))
    odd = [r for r in rows if not r["as_expected"]]
    if odd:
        print(f"\nnot as expected ({len(odd)}):")
        for r in odd:
            print(f"  {r['fmu']} {r['case']}: expected {r['expected']}, observed {r['observed']}\n"
                  f"      {r.get('detail', '')}")
    print(f"\n{len(rows)} cases in {elapsed:.1f} s")
    if a.json:
        a.json.write_text(json.dumps({"elapsed_s": elapsed, "rows": rows}, indent=1))
    bad = {SILENT, FATAL_, CRASH, HANG}
    return 1 if any(r["observed"] in bad or not r["as_expected"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
