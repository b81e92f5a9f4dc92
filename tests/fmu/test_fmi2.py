"""The FMI behaviour a system simulator relies on, one test per rule, for both flavours.

The native FMU honours every rule with the standard's status codes. pythonfmu 0.7 can return
only fmi2OK, fmi2Discard (from fmi2DoStep) or fmi2Fatal (an exception escaping the slave), so
where a rule asks for fmi2Error the pythonfmu FMU does the closest thing it can: it logs the
refusal (status fmi2Error, cause in ``message``) at the call, keeps its state, and refuses the
next fmi2DoStep with fmi2Discard. Those cases are asserted as they are, with
``DOCUMENTED_LIMIT`` naming the entry of fmu_src/models/contact/FMU.md ("What pythonfmu cannot honour").
"""

from __future__ import annotations

import ctypes
import math
import subprocess
import sys

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
pytest.importorskip("pythonfmu")

from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import (  # noqa: E402
    FMU2Slave,
    fmi2Boolean,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Integer,
    fmi2Real,
    fmi2ValueReference,
)

OK, WARNING, DISCARD, ERROR, FATAL = 0, 1, 2, 3, 4
DOCUMENTED_LIMIT = "fmu_src/models/contact/FMU.md, section 'What pythonfmu cannot honour'"


@pytest.fixture(scope="module", params=["pythonfmu", "native"])
def flavour(request):
    return request.param


@pytest.fixture(scope="module")
def unzipped(flavour, request, tmp_path_factory):
    fmu = request.getfixturevalue("contact_fmu" if flavour == "pythonfmu" else "native_fmu")
    return extract(fmu, str(tmp_path_factory.mktemp(f"behaviour_{flavour}")))


class Inst:
    """One instance through fmpy's FMU2Slave, every call returning its fmi2Status (never raising)."""

    def __init__(self, unzipped: str, name: str = "inst"):
        md = read_model_description(unzipped)
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.var = {v.name: v for v in md.modelVariables}
        self.messages: list[tuple[int, str]] = []

        def logger(_env, _name, status, _cat, message):
            self.messages.append((int(status), message.decode("utf-8", "replace")))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmpy.fmi2.fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
        cb.freeMemory = fmpy.fmi2.fmi2CallbackFreeMemoryTYPE(fmpy.free)
        self._cb = cb
        self.f = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                           instanceName=name)
        self.f.instantiate(callbacks=cb, loggingOn=False)  # errors must reach the log even so (native)
        self.t = 0.0

    def call(self, fn: str, *args) -> int:
        try:  # fmpy raises above Warning and returns the status otherwise
            return int(getattr(self.f, fn)(self.f.component, *args))
        except FMICallException as exc:
            return exc.status

    def set_real(self, **values) -> int:
        names = list(values)
        vrs = (fmi2ValueReference * len(names))(*[self.vr[n] for n in names])
        vals = (fmi2Real * len(names))(*values.values())
        return self.call("fmi2SetReal", vrs, len(names), vals)

    def set_int(self, **values) -> int:
        names = list(values)
        vrs = (fmi2ValueReference * len(names))(*[self.vr[n] for n in names])
        vals = (fmi2Integer * len(names))(*values.values())
        return self.call("fmi2SetInteger", vrs, len(names), vals)

    def real(self, name: str) -> float:
        return self.f.getReal([self.vr[name]])[0]

    def integer(self, name: str) -> int:
        return self.f.getInteger([self.vr[name]])[0]

    def message(self) -> str:
        return self.f.getString([self.vr["message"]])[0].decode()

    def init(self, **values) -> int:
        s = max(self.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0), self.call("fmi2EnterInitializationMode"))
        reals = {k: v for k, v in values.items() if self.var[k].type == "Real"}
        ints = {k: v for k, v in values.items() if self.var[k].type in ("Integer", "Enumeration")}
        if reals:
            s = max(s, self.set_real(**reals))
        if ints:
            s = max(s, self.set_int(**ints))
        return max(s, self.call("fmi2ExitInitializationMode"))

    def step(self, h: float = 1e-3, t: float | None = None) -> int:
        t = self.t if t is None else t
        s = self.call("fmi2DoStep", t, h, fmi2Boolean(1))
        if s <= WARNING:
            self.t = t + h
        return s

    def logged(self, since: int = 0, level: int = ERROR) -> str:
        return " | ".join(m for st, m in self.messages[since:] if st >= level)

    def said(self) -> str:
        """What the FMU told about its last refusal: its log (native: errors are logged even with logging
        off) and its 'message' output (pythonfmu forwards nothing with logging off: DOCUMENTED_LIMIT)."""
        return self.logged() + " | " + self.message()

    def free(self) -> None:
        self.f.freeInstance()


@pytest.fixture
def inst(unzipped):
    i = Inst(unzipped)
    yield i
    i.free()


START = {"g0": 0.2e-3, "Omega": 176.2, "imbalance": 0.022}


# ------------------------------------------------------------------------------------------ model description
def test_ranges_nominals_display_units_enumerations_declared(unzipped):
    md = read_model_description(unzipped)
    v = {x.name: x for x in md.modelVariables}
    for x in md.modelVariables:
        if x.causality in ("input", "parameter") and x.type in ("Real", "Integer", "Enumeration"):
            assert x.min is not None and x.max is not None, f"{x.name}: no declared range"
        if x.causality in ("input", "parameter") and x.type == "Real":
            assert x.nominal is not None, f"{x.name}: no nominal"
    assert float(v["Omega"].max) == pytest.approx(12 * 53.4)  # normalisation.speed_max x omega_ref
    assert v["Omega"].displayUnit == "rpm" and v["g0"].displayUnit == "mm" and v["theta"].displayUnit == "deg"
    assert v["blade[1].gap_LE"].displayUnit == "mm"
    units = {u.name: u for u in md.unitDefinitions}
    rpm = next(d for d in units["rad/s"].displayUnits if d.name == "rpm")
    assert float(rpm.factor) == pytest.approx(60 / (2 * math.pi))
    for name, items in (("formulation", ["2D", "3D"]), ("mode", ["transient", "quasi_static"])):
        assert v[name].type == "Enumeration"
        assert [it.name for it in v[name].declaredType.items] == items


def test_numbers_in_the_description_are_the_shortest_decimals(unzipped):
    """Every min, max, nominal, start, display-unit factor and experiment value reads back to its double from its
    shortest decimal (640.8, not 640.79999999999995)."""
    from xml.etree import ElementTree

    root = ElementTree.parse(f"{unzipped}/modelDescription.xml").getroot()
    seen = 0
    for el in root.iter():
        for key in ("min", "max", "nominal", "start", "factor", "startTime", "stopTime", "stepSize"):
            text = el.get(key)
            if text is None or el.tag == "String":
                continue
            assert text == repr(float(text)) or text == str(int(float(text))), (el.tag, key, text)
            seen += 1
    assert seen > 50


def test_refusal_messages_write_the_shortest_decimals(inst, flavour):
    inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
    inst.call("fmi2EnterInitializationMode")
    inst.set_real(Omega=700.0)
    assert "accepted range [0.0, 640.8]" in inst.message() or "accepted range [0, 640.8]" in inst.message()
    assert "640.79999" not in inst.said()


def test_default_experiment_shows_rubbing(unzipped):
    """Run as is (fmpy with no argument: the default experiment, every start value), the FMU rubs: the
    section-6 speed and the reference imbalance from t = 0, the reference clearance, 2 s."""
    md = read_model_description(unzipped)
    v = {x.name: x for x in md.modelVariables}
    assert float(v["Omega"].start) == pytest.approx(3.3 * 53.4) and float(v["imbalance"].start) > 0.0
    assert float(md.defaultExperiment.stopTime) == 2.0
    r = fmpy.simulate_fmu(unzipped, output=["n_contact", "gap_min", "status"])
    assert r["time"][-1] == pytest.approx(2.0) and np.all(r["status"] == 0)
    assert r["n_contact"].max() >= 1 and r["gap_min"].min() < 0.0


def test_g0_declares_the_range_the_model_can_start_from(unzipped):
    """Down to an interference as deep as max_penetration (its start value): deeper is a divergence at t = 0."""
    md = read_model_description(unzipped)
    v = {x.name: x for x in md.modelVariables}
    assert float(v["g0"].min) == -float(v["max_penetration"].start)


def test_transient_outputs_declare_no_direct_feedthrough(unzipped):
    """No output depends directly on an input: coupling the spool's Omega to this FMU and its friction
    torque back is no algebraic loop."""
    md = read_model_description(unzipped)
    assert md.outputs and all(u.dependencies == [] for u in md.outputs)


@pytest.mark.parametrize("flavour_qs", ["pythonfmu", "native"])
def test_quasi_static_build_declares_and_has_its_feedthrough(flavour_qs, tmp_path):
    """Built with mode = quasi_static, the outputs depend on Omega and imbalance, and they are the balanced
    solution at the inputs just set: read before any step, they follow the input."""
    if flavour_qs == "pythonfmu":
        from fmu_src.models.contact.builder import build_fmu

        fmu = build_fmu(tmp_path / "qs", platforms=("linux64",), mode="quasi_static")["fmu"]
    else:
        from fmu_src.models.contact.builder import build_native_fmu

        fmu = build_native_fmu(tmp_path / "qs", platforms=("linux64",), mode="quasi_static")["fmu"]
    unz = extract(fmu, str(tmp_path / "qs_unz"))
    md = read_model_description(unz)
    inputs = {v for v in md.modelVariables if v.causality == "input"}
    lobes = {f"casing_lobe{n}.{q}" for n in (2, 3, 4) for q in ("amplitude", "phase")}
    assert {v.name for v in inputs} == {"Omega", "imbalance", "clearance_closure", "casing_offset.x",
                                        "casing_offset.y", *lobes}
    # the casing's offset and lobes are transient-mode inputs: the balanced solution does not depend on them
    assert all({d.name for d in u.dependencies} == {"Omega", "imbalance", "clearance_closure"} for u in md.outputs)
    i = Inst(unz)
    try:
        assert i.init(g0=0.5e-3, Omega=150.0, imbalance=0.022) <= WARNING
        f0 = i.real("blade[1].F_N")
        assert i.set_real(Omega=3.4 * 53.4) == OK
        f1 = i.real("blade[1].F_N")  # no step in between
        assert f1 > 0.0 and f1 != f0 and i.integer("n_contact") >= 1
    finally:
        i.free()


# ------------------------------------------------------------------------------------------ ranges and values
@pytest.mark.parametrize("name, value", [
    ("Omega", -1.0), ("Omega", 1e4), ("Omega", float("nan")), ("imbalance", -0.01), ("imbalance", float("inf")),
    ("g0", -0.02), ("k_r", 0.0), ("mu", -0.1), ("theta", math.pi / 2), ("chord", 0.0), ("dt_max", 0.0),
    ("max_penetration", 0.0)])
def test_out_of_range_value_is_refused(inst, flavour, name, value):
    inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
    inst.call("fmi2EnterInitializationMode")
    before = inst.real(name)
    s = inst.set_real(**{name: value})
    assert name in inst.said() and "accepted range" in inst.said()
    assert inst.real(name) == before  # the value was not taken
    if flavour == "native":
        assert s == ERROR
        assert inst.call("fmi2ExitInitializationMode") == OK  # the instance goes on with the old value
    else:  # DOCUMENTED_LIMIT: logged at the set, refused at exit-init / the first step
        assert s == OK
        inst.call("fmi2ExitInitializationMode")
        assert inst.step() == DISCARD and name in inst.message()


@pytest.mark.parametrize("name, value", [("formulation", 0), ("formulation", 3), ("mode", 5)])
def test_enumeration_outside_its_items_is_refused(inst, flavour, name, value):
    inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
    inst.call("fmi2EnterInitializationMode")
    s = inst.set_int(**{name: value})
    assert name in inst.said()
    if flavour == "native":
        assert s == ERROR
    else:  # DOCUMENTED_LIMIT
        assert s == OK
        inst.call("fmi2ExitInitializationMode")
        assert inst.step() == DISCARD


def test_setting_an_output_is_an_error(inst, flavour):
    assert inst.init(**START) == OK
    s = inst.set_real(**{"blade[1].F_N": 5.0})
    assert "output" in inst.said()
    assert inst.real("blade[1].F_N") == 0.0
    if flavour == "native":
        assert s == ERROR
        assert inst.step() == OK  # nothing else is affected
    else:  # DOCUMENTED_LIMIT
        assert s == OK and inst.step() == DISCARD


def test_fixed_parameter_after_initialisation_is_an_error(inst, flavour):
    assert inst.init(**START) == OK
    s = inst.set_real(k_r=2e6)
    assert "fixed parameter" in inst.said()
    assert s == (ERROR if flavour == "native" else OK)
    assert inst.real("k_r") == 1.5e6


def test_tunable_g0_may_change_between_steps(inst):
    assert inst.init(**START) == OK
    assert inst.step() == OK
    assert inst.set_real(g0=0.05) == OK and inst.step() == OK
    assert inst.real("gap_min") > 0.04


_UNKNOWN_VR = r'''
import sys
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi1 import FMICallException
unz, what = sys.argv[1], sys.argv[2]
md = read_model_description(unz)
vr = {v.name: v.valueReference for v in md.modelVariables}
f = FMU2Slave(guid=md.guid, unzipDirectory=unz, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
f.instantiate(loggingOn=True)
f.setupExperiment(startTime=0.0); f.enterInitializationMode(); f.exitInitializationMode()
try:
    if what == "unknown":
        f.getReal([len(md.modelVariables) + 7])
    else:
        f.getInteger([vr["Omega"]])
    print("status 0")
except FMICallException as e:
    print("status", e.status)
if what and "native" in sys.argv[3]:
    f.doStep(0.0, 1e-3)  # the instance still works
    print("still works")
'''


@pytest.mark.parametrize("what", ["unknown", "type"])
def test_unknown_value_reference_or_type_mismatch(unzipped, flavour, what, tmp_path):
    """Native: fmi2Error, and the instance goes on. pythonfmu: the slave's exception is fmi2Fatal (the
    instance is lost): DOCUMENTED_LIMIT. In a separate process (a fatal instance must not be touched again)."""
    script = tmp_path / "probe.py"
    script.write_text(_UNKNOWN_VR)
    r = subprocess.run([sys.executable, str(script), unzipped, what, flavour], capture_output=True, text=True,
                       timeout=120)
    if flavour == "native":
        assert "status 3" in r.stdout and "still works" in r.stdout, r.stdout + r.stderr
    else:
        assert "status 4" in r.stdout, r.stdout + r.stderr


# ------------------------------------------------------------------------------------------ stepping
def test_communication_point_must_match_the_fmu_time(inst, flavour):
    assert inst.init(**START) == OK
    assert inst.step() == OK
    for t in (0.0, 0.005):  # backwards, ahead
        s = inst.step(t=t)
        assert s == (ERROR if flavour == "native" else DISCARD)  # pythonfmu: DOCUMENTED_LIMIT
        assert "does not match the FMU's time" in inst.message()
    assert inst.step() == OK  # at its own time, it goes on


def test_do_step_after_terminate_is_an_error(inst, flavour):
    assert inst.init(**START) == OK
    assert inst.step() == OK
    assert inst.call("fmi2Terminate") == OK
    assert inst.step() == (ERROR if flavour == "native" else DISCARD)  # pythonfmu: DOCUMENTED_LIMIT
    assert "terminate" in inst.message().lower()


def test_internal_step_does_not_remember_a_tiny_step(inst):
    """A 1e-9 s step, then 1 ms steps: the internal step is back to h/ceil(h/cap) at once (it depends only on
    h, dt_max and the stability limit), and the run equals one without the tiny step to its O(1e-9 s) effect."""
    ref = Inst(inst.f.unzipDirectory, "ref")
    try:
        for i in (inst, ref):
            assert i.init(**START) == OK
        assert inst.step(1e-9) == OK and inst.integer("n_substeps") == 1
        inst.t = ref.t = 0.0  # compare at the same number of 1 ms steps
        inst_t0 = 1e-9
        for k in range(300):
            assert inst.step(1e-3, t=inst_t0 + k * 1e-3) == OK and ref.step(1e-3) == OK
            assert inst.integer("n_substeps") == ref.integer("n_substeps") == 2
        a = np.array(inst.f.getReal([inst.vr[f"blade[{j}].F_N"] for j in range(1, 11)]))
        b = np.array(ref.f.getReal([ref.vr[f"blade[{j}].F_N"] for j in range(1, 11)]))
        assert b.max() > 10.0
        assert np.abs(a - b).max() <= 1e-3 * b.max()
        assert inst.real("dt_internal") == ref.real("dt_internal") == 0.5e-3
    finally:
        ref.free()


# ------------------------------------------------------------------------------------------ configuration
def test_configuration_error_is_reported_at_the_end_of_initialisation(inst, flavour):
    """Parameters each in range that together make no model. Native: g0 = -2 mm with max_penetration = 1 mm (an
    interference deeper than the liner: a divergence at t = 0) is refused by fmi2ExitInitializationMode, the
    first call that sees both (fmi2Error, the reason logged); corrected, the same call succeeds. pythonfmu: the
    same, and a parameter file it cannot use, are logged there with fmi2OK (DOCUMENTED_LIMIT) and every step
    is refused."""
    inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
    inst.call("fmi2EnterInitializationMode")
    assert inst.set_real(g0=-2e-3, max_penetration=1e-3) == OK  # each in its declared range
    s = inst.call("fmi2ExitInitializationMode")
    if flavour == "native":
        assert s == ERROR and "max_penetration" in inst.logged() and inst.integer("status") == 2
        assert inst.set_real(max_penetration=3e-3) == OK
        assert inst.call("fmi2ExitInitializationMode") == OK and inst.step() == OK
        return
    assert s == OK and "max_penetration" in inst.message() and inst.step() == DISCARD


def test_unusable_parameter_file_is_a_configuration_error(unzipped, flavour):
    """pythonfmu: a param_file it cannot read is found by fmi2ExitInitializationMode (logged, fmi2OK:
    DOCUMENTED_LIMIT) and every step is refused. Native: there is no param_file at all (its model is built
    in): not declared, and its value reference 4 is unknown."""
    i = Inst(unzipped)
    try:
        if flavour == "native":
            assert "param_file" not in i.vr and 4 not in i.vr.values()
            i.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
            i.call("fmi2EnterInitializationMode")
            s = i.call("fmi2SetString", (fmi2ValueReference * 1)(4), 1, (ctypes.c_char_p * 1)(b"/x.toml"))
            assert s == ERROR and "unknown value reference 4" in i.logged()
            return
        i.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
        i.call("fmi2EnterInitializationMode")
        s = i.call("fmi2SetString", (fmi2ValueReference * 1)(i.vr["param_file"]), 1,
                   (ctypes.c_char_p * 1)(b"/nonexistent/params.toml"))
        assert s == OK
        assert i.call("fmi2ExitInitializationMode") == OK
        assert "params.toml" in i.said() and i.integer("status") == 2 and "params.toml" in i.message()
        assert i.step() == DISCARD
    finally:
        i.free()


# ------------------------------------------------------------------------------------------ rollback
def _terminated(i: Inst) -> bool:
    flag = fmi2Boolean()
    assert i.f.dll.fmi2GetBooleanStatus(i.f.component, 3, ctypes.byref(flag)) == OK  # 3: fmi2Terminated
    return bool(flag.value)


def _last_successful_time(i: Inst) -> float:
    t = fmi2Real()
    assert i.f.dll.fmi2GetRealStatus(i.f.component, 2, ctypes.byref(t)) == OK  # 2: fmi2LastSuccessfulTime
    return t.value


DIVERGES = {**START, "max_penetration": 0.2e-3}  # rubs beyond 0.2 mm at about 0.08 s


def test_divergence_ends_the_run_then_rollback_and_retry_with_a_smaller_step(inst, flavour):
    """The step that diverges is fmi2Discard with the reason; fmi2Terminated is true from then on and a further
    step is refused; fmi2SetFMUstate to a state saved before clears it (native: the flag belongs to the state;
    pythonfmu's binary keeps reporting true once a step was discarded: DOCUMENTED_LIMIT) and a retry with a
    smaller step succeeds."""
    assert inst.init(**DIVERGES) == OK
    assert not _terminated(inst)
    state = ctypes.c_void_p()
    for k in range(2000):
        if k % 50 == 0:
            assert inst.call("fmi2GetFMUstate", ctypes.byref(state)) == OK  # (re)uses one state object
            t_saved = inst.t
        s = inst.step()
        if s != OK:
            break
    assert s == DISCARD and inst.integer("status") == 1 and "diverged" in inst.message()
    assert _terminated(inst)
    assert inst.t <= _last_successful_time(inst) <= inst.t + 1e-3
    s = inst.step()
    assert s == (ERROR if flavour == "native" else DISCARD)  # pythonfmu: DOCUMENTED_LIMIT
    assert "ended this simulation" in inst.message()
    assert inst.call("fmi2SetFMUstate", state) == OK
    inst.t = t_saved
    assert _terminated(inst) is (flavour != "native")
    assert inst.set_real(g0=5e-3) == OK  # open the clearance: no divergence this time
    assert inst.step(0.5e-3) == OK and inst.integer("status") == 0
    for _ in range(100):
        assert inst.step() == OK
    assert inst.call("fmi2FreeFMUstate", ctypes.byref(state)) == OK


@pytest.mark.parametrize("master", ["fmpy.simulate_fmu", "fmusim loop"])
def test_a_diverging_run_ends_in_standard_masters(unzipped, flavour, master):
    """fmpy's simulate_fmu and a loop written as the Modelica Reference-FMUs' fmusim (v0.0.39) writes it (on
    fmi2Discard: continue from fmi2LastSuccessfulTime unless fmi2Terminated) end a diverging run at once with
    the result so far, instead of retrying the same step forever (9 GiB, 1 GB of log before the fix)."""
    import time

    t0 = time.perf_counter()
    if master == "fmpy.simulate_fmu":
        r = fmpy.simulate_fmu(unzipped, start_values=DIVERGES, stop_time=5.0, output_interval=1e-3,
                              output=["gap_min", "status"])
        assert 0.02 < r["time"][-1] < 1.0 and r["status"][-1] == 1 and r["gap_min"][-1] < -0.2e-3
    else:
        i = Inst(unzipped)
        try:
            assert i.init(**DIVERGES) == OK
            t, stop, calls = 0.0, 5.0, 0
            while t < stop and calls < 100_000:
                calls += 1
                s = i.call("fmi2DoStep", t, 1e-3, fmi2Boolean(1))
                if s == DISCARD:
                    t = _last_successful_time(i)
                    if _terminated(i):
                        break
                elif s > WARNING:
                    break
                else:
                    t += 1e-3
            assert s == DISCARD and 0.02 < t < 1.0 and calls < 1000, (s, t, calls)
            assert i.call("fmi2Terminate") == OK
        finally:
            i.free()
    assert time.perf_counter() - t0 < 30.0


QS_DIVERGES_AT_START = {"mode": 2, "g0": 0.0, "max_penetration": 1e-5, "Omega": 176.2, "imbalance": 0.022}


@pytest.mark.parametrize("master", ["fmpy.simulate_fmu", "fmusim loop"])
def test_a_quasi_static_divergence_at_initialisation_gives_every_master_a_row(unzipped, flavour, master):
    """Issue 24.7: no balanced solution at the initial inputs (here one deeper than max_penetration) made the native
    fmi2ExitInitializationMode return fmi2Warning, and fmusim, which stops at any status above OK (its CALL macro),
    wrote an empty result. It is fmi2OK now with status = 1 and the reason in 'message' (and in the log, a warning):
    every master has the initial row and reads why there; the first step then ends the run (fmi2Discard,
    fmi2Terminated)."""
    if master == "fmpy.simulate_fmu":
        r = fmpy.simulate_fmu(unzipped, start_values=QS_DIVERGES_AT_START, stop_time=1.0, output_interval=1e-3,
                              output=["status", "gap_min"])
        assert len(r) == 2 and (r["status"] == 1).all() and r["time"][0] == 0.0
        return
    i = Inst(unzipped)
    try:
        rows = []
        if i.init(**QS_DIVERGES_AT_START) == OK:  # fmusim: CALL(FMI2ExitInitializationMode(S)), any status > OK ends
            rows.append((0.0, i.integer("status"), i.message()))
            s = i.call("fmi2DoStep", 0.0, 1e-3, fmi2Boolean(1))
            assert s == DISCARD and _terminated(i)
            rows.append((_last_successful_time(i), i.integer("status"), i.message()))
        assert [r[:2] for r in rows] == [(0.0, 1), (0.0, 1)]
        assert "penetrates the casing" in rows[0][2] and "max_penetration" in rows[0][2]
        if flavour == "native":  # logged as a warning whether or not logging is on (pythonfmu: DOCUMENTED_LIMIT)
            assert "penetrates the casing" in i.logged(level=WARNING)
    finally:
        i.free()


def test_numbers_in_messages_read_as_a_person_reads_them(inst, flavour):
    """Issue 24.7: messages wrote 20 as 2e+01 and the declared maximum imbalance as 4.093319999999999. Now the
    shortest decimal that reads back as the same double, without an exponent between 1e-4 and 1e16, with the unit
    (native; the pythonfmu slave writes Python's repr: 20.0)."""
    assert inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0) == OK
    assert inst.call("fmi2EnterInitializationMode") == OK
    inst.set_real(imbalance=20.0)
    said = inst.said()
    assert "e+01" not in said and "4.093319999999999" not in said, said
    if flavour == "native":
        assert "imbalance = 20 kg.m out of range; accepted range [0, 4.09332] kg.m" in said, said
    else:
        assert "imbalance = 20.0 out of range; accepted range [0.0, 4.09332]" in said, said
    inst.set_real(k_r=2e10)
    assert ("k_r = 20000000000 N/m out of range; accepted range [1000, 10000000000] N/m" if flavour == "native"
            else "k_r = 20000000000.0 out of range") in inst.said()


def test_set_fmu_state_right_after_instantiation(inst, unzipped):
    """FMI 2.0 allows fmi2SetFMUstate in the instantiated state (fmusim's --initial-fmu-state-file restores a
    state there and starts stepping without initialising): a serialized state of a running instance, restored
    into a fresh instance, continues the run bit for bit, its model configured from the state's parameters."""
    assert inst.init(formulation=1, **START) == OK
    for _ in range(100):
        assert inst.step() == OK
    state = ctypes.c_void_p()
    assert inst.call("fmi2GetFMUstate", ctypes.byref(state)) == OK
    size = ctypes.c_size_t()
    assert inst.call("fmi2SerializedFMUstateSize", state, ctypes.byref(size)) == OK
    data = (ctypes.c_char * size.value)()
    assert inst.call("fmi2SerializeFMUstate", state, data, size.value) == OK
    fresh = Inst(unzipped, "fresh")
    try:
        s2 = ctypes.c_void_p()
        assert fresh.call("fmi2DeSerializeFMUstate", data, size.value, ctypes.byref(s2)) == OK
        assert fresh.call("fmi2SetFMUstate", s2) == OK
        fresh.t = inst.t
        fn = [inst.vr[f"blade[{j}].F_N"] for j in range(1, 11)]
        for _ in range(200):
            assert inst.step() == OK and fresh.step() == OK
            assert inst.f.getReal(fn) == fresh.f.getReal(fn)
        assert max(inst.f.getReal(fn)) > 10.0 and fresh.integer("formulation") == 1
        assert fresh.call("fmi2FreeFMUstate", ctypes.byref(s2)) == OK
    finally:
        fresh.free()
        inst.call("fmi2FreeFMUstate", ctypes.byref(state))


def test_garbage_serialized_state_is_refused(inst, flavour):
    assert inst.init(**START) == OK
    assert inst.step() == OK
    before = inst.real("blade[1].gap_LE")
    garbage = b"\x00not a state\xff" * 10
    state = ctypes.c_void_p()
    buf = (ctypes.c_char * len(garbage)).from_buffer_copy(garbage)
    s = inst.call("fmi2DeSerializeFMUstate", buf, len(garbage), ctypes.byref(state))
    if flavour == "native":
        assert s == ERROR and "not a state of this FMU" in inst.logged()
    else:  # DOCUMENTED_LIMIT: the state object is made; fmi2SetFMUstate refuses it (logs, keeps its state)
        assert s == OK
        assert inst.call("fmi2SetFMUstate", state) == OK
        assert "not a state of this FMU" in inst.said() and inst.real("blade[1].gap_LE") == before
        assert inst.step() == DISCARD
    assert inst.step() == OK  # and the instance goes on


def test_state_of_another_configuration_brings_its_configuration(unzipped, flavour):
    """A 2D instance's state given to a 3D instance: an FMU state holds the parameters too, so the instance
    becomes the 2D run and continues it bit for bit (native; the pythonfmu flavour rebuilds its model the same
    way)."""
    a, b = Inst(unzipped, "a"), Inst(unzipped, "b")
    try:
        assert a.init(formulation=1, **START) == OK and b.init(formulation=2, **START) == OK
        for _ in range(50):
            assert a.step() == OK and b.step() == OK
        state = ctypes.c_void_p()
        assert a.call("fmi2GetFMUstate", ctypes.byref(state)) == OK
        size = ctypes.c_size_t()
        assert a.call("fmi2SerializedFMUstateSize", state, ctypes.byref(size)) == OK
        data = (ctypes.c_char * size.value)()
        assert a.call("fmi2SerializeFMUstate", state, data, size.value) == OK
        s2 = ctypes.c_void_p()
        assert b.call("fmi2DeSerializeFMUstate", data, size.value, ctypes.byref(s2)) == OK
        assert b.call("fmi2SetFMUstate", s2) == OK
        assert b.f.getInteger([b.vr["formulation"]])[0] == 1
        fn = [a.vr[f"blade[{j}].F_N"] for j in range(1, 11)]
        for _ in range(100):
            assert a.step() == OK and b.step() == OK
            assert a.f.getReal(fn) == b.f.getReal(fn)
        a.call("fmi2FreeFMUstate", ctypes.byref(state))
        b.call("fmi2FreeFMUstate", ctypes.byref(s2))
    finally:
        a.free()
        b.free()


# ------------------------------------------------------------------------------------------ divergence
def test_divergence_is_caught_on_the_physical_scale(inst):
    """A penetration beyond max_penetration (here 0.2 mm; 3 mm by default) stops the run at the first
    substep that crosses it (this run, held at full imbalance, would reach 0.3 mm): the reported smallest
    gap is just past the limit, not metres, and no force is absurd."""
    assert inst.init(g0=0.2e-3, Omega=176.2, imbalance=0.022, max_penetration=0.2e-3) == OK
    statuses = []
    for _ in range(2000):
        s = inst.step()
        statuses.append(s)
        if s != OK:
            break
    assert statuses[-1] == DISCARD, "this run rubs beyond 0.2 mm: it must be stopped"
    gap = inst.real("gap_min")
    assert -0.25e-3 < gap < -0.2e-3
    assert max(inst.real(f"blade[{j}].F_N") for j in range(1, 11)) < 1.5e6 * 0.25e-3
    assert inst.integer("status") == 1 and "max_penetration" in inst.message()


def test_quasi_static_penetration_beyond_max_penetration_is_a_divergence(inst):
    """The physical scale of a transient holds in quasi_static mode: at g0 = 0 near the contact-stiffened critical
    (4.0 omega_ref) the 2D balanced solution penetrates 1.5 mm; with max_penetration = 0.3 mm that is a
    divergence (fmi2Discard, status 1, the run ends), not a solution reported with fmi2OK."""
    assert inst.init(mode=2, formulation=1, g0=0.0, Omega=4.0 * 53.4, imbalance=0.022, max_penetration=0.3e-3) \
        <= WARNING
    assert inst.step(0.1) == DISCARD
    assert inst.integer("status") == 1 and "deeper than max_penetration = 0.3 mm" in inst.message()
    assert _terminated(inst)
    assert inst.real("gap_min") < -0.3e-3  # the outputs are that solution's


def test_quasi_static_point_without_solution_after_an_unstable_one(inst):
    """The main job's FMU sweep at g0 = 0.33 mm (2D): at 3.70 omega_ref the balanced solution is unstable
    (status 3); at 3.87 Newton finds none: that step is fmi2Discard with status 1 (not the 3 the last good step
    left), and fmi2Terminated, which is what a sweep rolls back on."""
    g0, speeds = 1.6 * 0.00517474459231002 * (3 / 15) ** 2, np.linspace(2.6923, 4.2923, 20)
    assert inst.init(mode=2, formulation=1, g0=g0, Omega=speeds[0] * 53.4, imbalance=0.022) <= WARNING
    for sp in speeds[:14]:  # the sweep warm-starts each point from the last
        assert inst.set_real(Omega=sp * 53.4) == OK and inst.step(1.0) == OK
    assert inst.integer("status") == 3
    assert inst.set_real(Omega=speeds[14] * 53.4) == OK
    assert inst.step(1.0) == DISCARD
    assert inst.integer("status") == 1 and "no balanced static solution" in inst.message()
    assert _terminated(inst)


def test_quasi_static_reports_an_unstable_solution_in_status(inst):
    assert inst.init(mode=2, formulation=1, g0=0.2e-3, Omega=3.3 * 53.4, imbalance=0.022) <= WARNING
    assert inst.step(0.1) == OK
    assert inst.real("max_real_eig") > 0 and inst.integer("status") == 3  # 2D in contact: unstable (fact 5)
    assert inst.set_real(g0=0.02) == OK and inst.step(0.1) == OK  # no contact: stable
    assert inst.real("max_real_eig") < 0 and inst.integer("status") == 0


def test_errors_reach_the_logger_with_logging_off(inst, flavour):
    """loggingOn was false at fmi2Instantiate: the native FMU still logs errors (the standard leaves it to the
    FMU; a refusal without its reason helps nobody). pythonfmu forwards nothing then (DOCUMENTED_LIMIT);
    the 'message' output carries the cause in both."""
    inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
    inst.call("fmi2EnterInitializationMode")
    inst.set_real(Omega=-1.0)
    if flavour == "native":
        assert "Omega" in inst.logged()
    assert "Omega" in inst.message()


# --------------------------------------------------------------- found by benchmarks/fuzz_fmi.py (issue 17)
def _blade_outputs(i: Inst) -> list[float]:
    return i.f.getReal([i.vr[f"blade[{j}].{q}"] for j in range(1, 11) for q in ("F_N", "gap_LE", "gap_TE")])


@pytest.mark.parametrize("h", [1e12, 1e6])
def test_a_step_too_long_is_refused_at_once_with_the_longest_allowed(inst, flavour, h):
    """A communication step that needs more than MAX_SUBSTEPS substeps: 1e12 s overflowed the native int
    count into one unstable substep (fmi2OK, gap_min = -3e10 m); 1e6 s took hours in one call no master can
    cancel. Refused at once, the longest step named, the state left as it was."""
    import time

    from fmu_src.models.contact.variables import MAX_SUBSTEPS

    ref = Inst(inst.f.unzipDirectory, "ref")
    try:
        for i in (inst, ref):
            assert i.init(**START) == OK
            for _ in range(3):
                assert i.step() == OK
        t0 = time.perf_counter()
        s = inst.step(h)
        assert time.perf_counter() - t0 < 1.0
        assert s == (ERROR if flavour == "native" else DISCARD)  # pythonfmu: DOCUMENTED_LIMIT
        assert f"at most {MAX_SUBSTEPS} are taken in one step" in inst.said() and "h <= " in inst.said()
        assert not _terminated(inst) or flavour != "native"
        assert inst.step() == OK and ref.step() == OK
        assert _blade_outputs(inst) == _blade_outputs(ref)
    finally:
        ref.free()


def test_native_substep_cap_is_the_interfaces():
    from pathlib import Path

    from fmu_src.models.contact.variables import MAX_SUBSTEPS

    header = (Path(__file__).parents[2] / "fmu_src" / "fmi" / "c" / "fmu_model.h").read_text()
    assert f"#define MODEL_MAX_SUBSTEPS {MAX_SUBSTEPS}" in header


def test_the_step_that_crosses_the_limit_is_the_discarded_one(inst, flavour):
    """A step whose last substep ends beyond max_penetration returned fmi2OK (the kernel checked each substep's
    start only) and the next step was discarded: every fmi2OK step must end within the limit."""
    assert inst.init(**{**START, "max_penetration": 1e-5, "g0": -5e-7}) == OK
    for _ in range(200):
        s = inst.step()
        if s != OK:
            break
        assert inst.real("gap_min") > -1e-5, "an fmi2OK step ended beyond max_penetration"
    assert s == DISCARD and inst.real("gap_min") <= -1e-5 and inst.integer("status") == 1
    assert _terminated(inst)


def test_a_refused_tiny_step_leaves_the_instance_as_it_was(inst, flavour):
    """h = 1e-300 makes the central-difference matrix singular: refused, and the next step equals the same step
    without the refused one bit for bit (the two-step scheme used to be restarted before the refusal)."""
    ref = Inst(inst.f.unzipDirectory, "ref")
    try:
        for i in (inst, ref):
            assert i.init(**START) == OK
            for _ in range(3):
                assert i.step() == OK
        s = inst.step(1e-300)
        assert s != OK and "singular" in inst.said()
        assert inst.step() == OK and ref.step() == OK
        assert _blade_outputs(inst) == _blade_outputs(ref)
    finally:
        ref.free()


def test_calls_the_standard_does_not_allow_are_refused(unzipped, flavour):
    """FMI 2.0 co-simulation's calling sequence: no fmi2Get* before fmi2EnterInitializationMode, no
    fmi2Terminate in initialization mode, no input after a discarded step (stepFailed: roll back first).
    pythonfmu: an exception there would be fmi2Fatal, so the refusal is logged at the call with fmi2OK
    (DOCUMENTED_LIMIT), and fmi2Terminate leaves it in initialization mode."""
    refused = ERROR if flavour == "native" else OK
    i = Inst(unzipped)
    try:
        s = i.call("fmi2GetReal", (fmi2ValueReference * 1)(i.vr["gap_min"]), 1, (fmi2Real * 1)())
        told = i.logged() if flavour == "native" else i.message()  # native: no fmi2GetString yet either
        assert s == refused and "values are read from fmi2EnterInitializationMode on" in told
        i.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0)
        assert i.call("fmi2EnterInitializationMode") == OK
        assert i.call("fmi2Terminate") == refused and "fmi2Reset or fmi2FreeInstance" in i.said()
        assert i.set_real(**DIVERGES) == OK and i.call("fmi2ExitInitializationMode") == OK
        while (s := i.step()) == OK:
            pass
        assert s == DISCARD
        n = len(i.messages)
        s = i.set_real(Omega=100.0)
        assert s == (ERROR if flavour == "native" else OK)  # pythonfmu: logged at the call (DOCUMENTED_LIMIT)
        assert "roll back with fmi2SetFMUstate first" in (i.logged(n) if flavour == "native" else i.message())
        assert i.call("fmi2Terminate") == OK
    finally:
        i.free()


def test_a_wrong_guid_is_named_in_the_log(unzipped, flavour):
    """fmi2Instantiate's refusal of a foreign GUID reached fmpy's (non-formatting) logger as a raw format
    ("GUID '%s' is not this FMU's (%s)"): the message must carry both GUIDs."""
    if flavour != "native":
        pytest.skip("pythonfmu 0.7 does not check the GUID")
    md = read_model_description(unzipped)
    got = []

    def logger(_env, _name, status, _cat, message):
        got.append(message.decode("utf-8", "replace"))

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = fmpy.fmi2.fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
    cb.freeMemory = fmpy.fmi2.fmi2CallbackFreeMemoryTYPE(fmpy.free)
    f = FMU2Slave(guid="{not-this-one}", unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        f.instantiate(callbacks=cb)
    text = " ".join(got)
    assert "{not-this-one}" in text and md.guid in text and "%s" not in text, text


def test_a_state_of_another_native_fmu_is_refused(unzipped, flavour, tmp_path):
    """In-memory FMU states carried no identity: every FMU on the wrapper shares its magic number, and a state of
    the LP spool FMU given to the contact FMU was refused only because the sizes differed, after the wrapper had
    configured a model from the spool's values. It must be refused as another FMU's, nothing changed."""
    if flavour != "native":
        pytest.skip("the pythonfmu flavour's states are Python objects of its own class")
    from fmu_src.models.spool.builder import build_native_spool_fmu

    spool_dir = extract(str(build_native_spool_fmu(tmp_path, platforms=("linux64",))), str(tmp_path / "spool"))
    sp, c = Inst(spool_dir, "spool"), Inst(unzipped, "contact")
    try:
        assert sp.init() == OK and c.init(**START) == OK
        assert sp.step() == OK and c.step() == OK
        foreign = ctypes.c_void_p()
        assert sp.call("fmi2GetFMUstate", ctypes.byref(foreign)) == OK
        before = _blade_outputs(c)
        n = len(c.messages)
        assert c.call("fmi2SetFMUstate", foreign) == ERROR
        assert "another FMU's or build's" in c.logged(n)
        assert _blade_outputs(c) == before and c.step() == OK
        assert sp.call("fmi2FreeFMUstate", ctypes.byref(foreign)) == OK
    finally:
        sp.free()
        c.free()


# --------------------------------------------------------------- found in fmusim 0.0.39 and OMSimulator 3.0 (issue 17)
_STATE_BY_VALUE = """
import ctypes, sys
sys.path.insert(0, sys.argv[2])
from test_fmi2 import Inst, START, OK
i = Inst(sys.argv[1])
assert i.init(**START) == OK and i.step() == OK
state = ctypes.c_void_p()
assert i.call("fmi2GetFMUstate", ctypes.byref(state)) == OK
free = ctypes.CDLL(i.f.dll._name).fmi2FreeFMUstate  # a handle without fmpy's argtypes: the state itself goes in
free.restype = ctypes.c_int
print("status", free(ctypes.c_void_p(i.f.component), state))
print("step", i.step())
print("log", i.logged(level=1))
i.free()
"""


def test_a_state_freed_by_value_is_freed_with_a_warning_not_a_crash(native_fmu, tmp_path):
    """fmusim 0.0.39 passes the FMU state itself to fmi2FreeFMUstate where FMI 2.0 passes the address of the
    variable holding it; dereferencing it crashed the host (segfault with --initial-fmu-state-file and
    --final-fmu-state-file). The native FMU recognises the mistake (a state's first field is its own address),
    frees the state, logs a warning and returns OK (fmusim stops at any other status); the instance goes on.
    In a process of its own: a regression is a crash."""
    from pathlib import Path

    d = extract(native_fmu, str(tmp_path / "u"))
    r = subprocess.run([sys.executable, "-c", _STATE_BY_VALUE, d, str(Path(__file__).parent)], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0, r.stderr[-2000:]
    out = dict(line.split(" ", 1) for line in r.stdout.splitlines())
    assert out["status"] == str(OK) and out["step"] == str(OK)  # OK: fmusim ends its run at any other status
    assert "instead of a pointer to it" in out["log"]


def test_outputs_are_readable_in_initialization_mode(inst):
    """FMI 2.0 lets a master read outputs in initialization mode, and OMSimulator and libcosim pass them along
    their connections before the first step: they are the initial state's (here every gap is g0, no force),
    following the values set so far; they read 0 before."""
    assert inst.call("fmi2SetupExperiment", 0, 0.0, 0.0, 0, 0.0) == OK
    assert inst.call("fmi2EnterInitializationMode") == OK
    assert inst.set_real(g0=0.7e-3, Omega=176.2) == OK
    assert inst.real("gap_min") == 0.7e-3 and inst.real("blade[3].gap_tip") == 0.7e-3
    assert inst.set_real(g0=0.4e-3) == OK
    assert inst.real("gap_min") == 0.4e-3 and inst.real("blade[1].F_N") == 0.0
    assert inst.set_real(clearance_closure=0.1e-3) == OK  # the engine's closure: every gap 0.1 mm smaller
    assert inst.real("gap_min") == pytest.approx(0.3e-3, rel=1e-12)
    assert inst.real("clearance_effective") == pytest.approx(0.3e-3, rel=1e-12)
    assert inst.call("fmi2ExitInitializationMode") == OK
    assert inst.real("gap_min") == pytest.approx(0.3e-3, rel=1e-12)


def test_status_stays_diverged_whatever_is_refused_after(inst, flavour):
    """After a divergence the master's further calls are refused; the status output keeps saying 1 (diverged),
    not 2 (bad input): OMSimulator 3.0 steps on after fmi2Terminated, and a result file read for status == 1
    must still find the divergence."""
    if flavour == "pythonfmu":
        pytest.skip(DOCUMENTED_LIMIT)
    assert inst.init(**{**START, "max_penetration": 0.2e-3}) == OK
    while inst.step() == OK:
        assert inst.t < 2.0
    assert inst.integer("status") == 1
    assert inst.step() == ERROR and inst.set_real(Omega=170.0) == ERROR
    assert inst.integer("status") == 1 and "ended this simulation" in inst.message()
