"""The contact model as an FMI 3.0 co-simulation FMU (issue 20): the FMI 2.0 native FMU's model and kernel behind
fmi3_cs.c, driven by fmpy's FMU3Slave.

* the model description passes fmpy's FMI 3.0 validation, with the FMI 2.0 interface's units, ranges and nominal
  values, the per-blade outputs as arrays of n_blades (a structural parameter) and two event indicators;
* the cross-check kit's run-up equals the FMI 2.0 native FMU's (same steps, no early return) to 1e-12; with
  early return the first contact is reported within one internal substep after a bisection of the FMI 2.0 FMU's
  communication step with rollbacks finds it;
* the divergence rule, FMU states and their serialisation;
* every misuse refused with fmi3Error and a logged message, the instance left as it was.

Skips (does not fail) where fmpy has no FMI 3.0 support or no C compiler is there to build the FMU.
"""

from __future__ import annotations

import ctypes
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")

from fmu_src.masters import fmi3 as fmi3_run  # noqa: E402

_why = fmi3_run.fmi3_available()
if _why:
    pytest.skip(_why, allow_module_level=True)

from fmpy.fmi3 import fmi3Float64, fmi3Int32, fmi3Int64, fmi3UInt64, fmi3ValueReference  # noqa: E402

from fmu_src.fmi.crosscheck import read_csv  # noqa: E402
from fmu_src.masters import crosscheck as runs  # noqa: E402
from fmu_src.masters.fmi3 import ERROR, OK, WARNING, Slave3  # noqa: E402
from fmu_src.models.contact import crosscheck  # noqa: E402
from fmu_src.models.contact import variables as interface  # noqa: E402

START = {"g0": 0.2e-3, "Omega": 176.2, "imbalance": 0.022}
DIVERGES = {**START, "max_penetration": 0.2e-3}  # rubs beyond 0.2 mm at about 0.08 s


def _compiler_or_skip() -> None:
    from rotorub_model.kernel.compiler import CompilerError, find_compiler, zig_command

    if zig_command():
        return
    try:
        find_compiler()
    except CompilerError as exc:
        pytest.skip(f"no C compiler to build the FMU: {exc}")


@pytest.fixture(scope="module")
def built3(tmp_path_factory):
    """`rotorub build-fmu --native --fmi3` (linux64): the FMU and its cross-check kit."""
    _compiler_or_skip()
    from fmu_src.models.contact.builder import build_with_kit as build

    out = build(tmp_path_factory.mktemp("fmi3"), native=True, fmi3=True, platforms=("linux64",))
    return out


@pytest.fixture(scope="module")
def fmu3(built3):
    return built3["fmu"]


@pytest.fixture(scope="module")
def unzipped3(fmu3, tmp_path_factory):
    d = tmp_path_factory.mktemp("fmi3_unzipped")
    with zipfile.ZipFile(fmu3) as z:
        z.extractall(d)
    return d


@pytest.fixture
def inst(unzipped3):
    i = Slave3(None, unzipped=str(unzipped3))
    yield i
    i.free()


def _vals(ctype, values):
    return (ctype * len(values))(*values), len(values)


def _vrs(*vrs):
    return (fmi3ValueReference * len(vrs))(*vrs), len(vrs)


# ------------------------------------------------------------------------------------------ model description
def test_fmpy_validation_is_clean(fmu3):
    from fmpy.validation import validate_fmu

    assert validate_fmu(fmu3) == []


def test_variables_are_the_fmi2_interface_with_arrays(unzipped3):
    from fmpy import read_model_description

    md = read_model_description(str(unzipped3))
    assert md.fmiVersion == "3.0"
    cs = md.coSimulation
    assert cs.mightReturnEarlyFromDoStep and not cs.hasEventMode and not cs.providesIntermediateUpdate
    xml = (unzipped3 / "modelDescription.xml").read_text()
    assert 'canGetAndSetFMUState="true"' in xml and 'canSerializeFMUState="true"' in xml
    v3 = {v.name: v for v in md.modelVariables}
    from fmu_src.fmi.variables import declared, scalars
    from rotorub_model.structure.params import reference_parameters

    d = interface.Defaults.from_parameters(reference_parameters())
    v2 = scalars(declared(interface.variables(d), ("fmi2", "native")))  # the native FMI 2.0 FMU's
    nb = v3["n_blades"]
    assert (nb.type, nb.causality, nb.variability, int(nb.start)) == ("UInt64", "structuralParameter", "fixed", 10)
    for quantity in ("F_N", "F_T", "gap_LE", "gap_TE", "gap_tip", "contact_fraction"):
        a = v3[f"blade.{quantity}"]
        assert a.type == "Float64" and a.causality == "output"
        assert [dim.variable for dim in a.dimensions] == [nb] and a.shape == (10,)
        assert a.valueReference == next(v.vr for v in v2 if v.name == f"blade[1].{quantity}")
    assert v3["wear.harmonic"].shape == (interface.WEAR_HARMONICS,)
    types = {"Real": "Float64", "Integer": "Int32", "Enumeration": "Enumeration", "String": "String"}
    scalars = [v for v in v2 if not v.name.startswith(("blade[", "wear.harmonic["))]
    assert len(v3) == len(scalars) + 7 + 3  # the 7 arrays, time, n_blades, penetration_margin
    for v in scalars:  # same name, value reference, type, units, range, nominal and start as FMI 2.0
        w = v3[v.name]
        assert (w.valueReference, w.type, w.causality) == (v.vr, types[v.type], v.causality), v.name
        assert (w.unit, w.displayUnit) == (v.unit, v.display_unit), v.name
        for key in ("min", "max", "nominal"):
            want = getattr(v, key)
            assert (getattr(w, key) is None) == (want is None), (v.name, key)
            if want is not None:
                assert float(getattr(w, key)) == float(want), (v.name, key)
        if v.settable and v.type != "String":
            assert float(w.start) == float(v.start), v.name
    assert v3["formulation"].declaredType.name == "Formulation"
    assert [v3[n].variability for n in ("time", "penetration_margin")] == ["continuous", "continuous"]
    assert [e.variable.name for e in md.eventIndicators] == ["gap_min", "penetration_margin"]
    # transient: no input feedthrough; the outputs follow the state, i.e. time (not dependencies="": fmi4c crashes)
    assert md.outputs and all([d.name for d in u.dependencies] == ["time"] for u in md.outputs)


def test_sources_binaries_and_the_same_model(unzipped3, native_fmu):
    from fmu_src.fmi.binaries import missing_fmi_functions, newest_glibc
    from rotorub_model import kernel

    src = unzipped3 / "sources"
    bd = (src / "buildDescription.xml").read_text()
    kernel_c = [p.name for p in kernel.SOURCES]  # however many files the kernel is split into
    for f in ("fmi3_cs.c", "fmu_core.c", "model.c", "model_data.c", *kernel_c):
        assert f'<SourceFile name="{f}"/>' in bd and (src / f).is_file()
        assert f in (src / "CMakeLists.txt").read_text()
    so = unzipped3 / "binaries" / "x86_64-linux" / "RotorCasingContact.so"
    assert missing_fmi_functions(so, "3.0") == {"x86_64": []}
    assert newest_glibc(so) <= (2, 17)
    with zipfile.ZipFile(native_fmu) as z:  # one model: the FMI 2.0 FMU's files, byte for byte
        for f in ("model.c", "model.h", "variables.h", "fmu_core.c", "fmu_model.h", *kernel_c):
            assert z.read(f"sources/{f}") == (src / f).read_bytes(), f


# ------------------------------------------------------------------------------------------ numbers
def test_kit_run_up_equals_the_fmi2_fmu(built3, fmu3, native_fmu, tmp_path):
    """The cross-check kit's run-up (through the first critical with rub), same steps, no early return: the
    FMI 3.0 FMU's outputs are the FMI 2.0 native FMU's (run through the FMI 2.0 kit) to 1e-12, and its kit, in
    FMI 3.0 columns, the reference's to the kit's bound."""
    kit = Path(built3["fmu"]).parent
    r3 = runs.run_fmi3(fmu3, kit)
    crosscheck.write_kit(tmp_path)
    r2 = runs.run_fmpy(native_fmu, tmp_path)
    col = crosscheck.columns3()
    assert r3["n_contact"].max() >= 1 and r3["gap_min"].min() < 0.0  # it rubs
    diff = max(float(np.abs(r3[col.get(c, c)] - r2[c]).max()) for c in crosscheck.OUTPUTS)
    assert diff <= 1e-12, diff
    ref = read_csv(kit / f"{crosscheck.NAME}_ref.csv")
    assert "blade.F_N[1]" in ref and "blade[1].F_N" not in ref
    assert max(runs.compare(r3, kit).values()) <= 1e-9


def test_a_run_with_early_returns_continues_as_without_to_round_off(unzipped3):
    """After an early return the master steps on to its communication point: the remainder is the same internal
    substep up to the rounding of the master's subtraction (here 0.0005000000000000004 for 0.0005), and where it
    differs in the last bits the two-step scheme restarts at the same velocity. So the run departs from the run
    without early return by round-off only: measured 1.3e-12 of the largest force over 2 s (bound: 1e-11)."""
    with Slave3(None, unzipped=str(unzipped3), early_return=True) as i, \
            Slave3(None, unzipped=str(unzipped3), name="plain") as plain:
        assert i.init(**START) == OK and plain.init(**START) == OK
        early_returns, worst = 0, 0.0
        for _ in range(2000):
            t = i.t
            s, _, early, last = i.step(1e-3)
            if early:
                early_returns += 1
                s, _, early, _ = i.step(t + 1e-3 - last, last)
            assert s == OK and not early and plain.step(1e-3)[0] == OK
            fa, fb = i.get("blade.F_N"), plain.get("blade.F_N")
            worst = max(worst, float(np.abs(fa - fb).max()) / max(float(np.abs(fb).max()), 1.0))
        assert early_returns >= 1 and np.abs(fb).max() > 100.0
        assert worst <= 1e-11, worst


@pytest.mark.parametrize("h", [1e-3, 1e-2])
def test_first_contact_within_one_substep_of_a_bisection_on_the_fmi2_fmu(fmu3, native_fmu, h):
    """Early return at the first contact: lastSuccessfulTime is the end of the first internal substep whose state
    is in contact, so a master's bisection of the FMI 2.0 FMU's communication step (rollbacks, to 1e-9 s) finds
    the crossing within that substep: 0 <= t_fmi3 - t_bisection <= dt_internal."""
    a = fmi3_run.first_event_fmi3(fmu3, h, 1.0, **START)
    b = fmi3_run.first_event_fmi2_bisection(native_fmu, h, 1.0, tol=1e-9, **START)
    assert a["gap_min"] < 0.0 and a["n_contact"] >= 1
    assert a["t_step"] == pytest.approx(b["t_step"], abs=1e-12) and a["t"] < a["t_step"] + h  # early, same step
    assert 0.0 <= a["t"] - b["t"] <= a["dt_internal"] + 1e-12, (a, b)


def test_early_return_protocol(unzipped3):
    """earlyReturn, lastSuccessfulTime and the next communication point after an early return; a step from
    anywhere else is refused; without early return allowed the same run never returns early."""
    with Slave3(None, unzipped=str(unzipped3), early_return=True) as i, \
            Slave3(None, unzipped=str(unzipped3), name="plain") as plain:
        assert i.init(**START) == OK and plain.init(**START) == OK
        t, early = 0.0, False
        while not early:
            t = i.t
            s, term, early, last = i.step(1e-3)
            assert s == OK and not term
            assert plain.step(1e-3)[:3] == (OK, False, False)
        assert t < last < t + 1e-3 and i.get("time") == last and i.get("gap_min") < 0.0
        assert i.get("n_substeps") == 1 and last == pytest.approx(t + i.get("dt_internal"), abs=1e-15)
        n = len(i.messages)
        assert i.step(1e-3, t + 1e-3)[0] == ERROR and "does not match the FMU's time" in i.logged(n)
        s, _, early, last2 = i.step(t + 1e-3 - last, last)  # on to the communication point
        assert s == OK and not early and last2 == pytest.approx(t + 1e-3, abs=1e-15)


# ------------------------------------------------------------------------------------------ divergence, states
def test_divergence_ends_the_run_with_ok_and_terminate_simulation_and_rolls_back(inst):
    """FMI 3.0's way to end a run (issue 24.7: fmi3Discard lost fmpy's whole result): the diverging step returns
    fmi3OK with terminateSimulation = true and lastSuccessfulTime the time the model reached (no early return: it was
    not allowed), its outputs that state's, the reason logged (a warning) and in 'message'; a further step is
    refused; a rollback goes on."""
    assert inst.init(**DIVERGES) == OK
    state = ctypes.c_void_p()
    for k in range(2000):
        if k % 50 == 0:
            assert inst.call("fmi3GetFMUState", ctypes.byref(state)) == OK
            t_saved = inst.t
        t0 = inst.t
        s, term, early, last = inst.step()
        assert s == OK
        if term:
            break
    assert term and not early and t0 < last <= t0 + 1e-3 and inst.get("time") == last
    assert inst.get("status") == 1 and "max_penetration" in inst.get("message")
    assert inst.get("penetration_margin") < 0.0  # the divergence's event indicator crossed 0
    assert "terminateSimulation = true" in inst.logged(level=WARNING)
    n = len(inst.messages)
    assert inst.step(1e-3, last)[0] == ERROR and "ended this simulation" in inst.logged(n)
    assert inst.set(Omega=100.0) == ERROR and "roll back with fmi3SetFMUState first" in inst.logged(n)
    assert inst.call("fmi3SetFMUState", state) == OK
    inst.t = t_saved
    assert inst.set(g0=5e-3) == OK
    for _ in range(100):
        s, term, _, _ = inst.step()
        assert s == OK and not term
    assert inst.call("fmi3FreeFMUState", ctypes.byref(state)) == OK


def test_divergence_with_early_return_allowed_returns_early_at_the_time_reached(unzipped3):
    """Early return allowed: the diverging step returns early (FMI 3.0 names terminateSimulation among its
    reasons), lastSuccessfulTime the substep the divergence was found at, before the communication point (steps of
    10 ms: 19 substeps each, the divergence found in the 6th)."""
    with Slave3(None, unzipped=str(unzipped3), early_return=True) as i:
        assert i.init(**DIVERGES) == OK
        point, term = 0.0, False
        while not term and point < 1.0:
            point += 1e-2
            while i.t < point and not term:  # on to the communication point after each early return
                t0 = i.t
                s, term, early, last = i.step(point - t0, t0)
                assert s == OK
        assert term and early and t0 < last < point and i.t == last and i.get("status") == 1


def fmusim3_loop(unzipped, start: dict, stop: float = 5.0, h: float = 1e-3, mode: int | None = None) -> dict:
    """The co-simulation loop of fmusim 0.0.39's FMI3CSSimulation.c, as written: every call through its CALL macro
    (any status above OK ends the run, keeping the rows recorded so far), a row after initialisation and after each
    step (at lastSuccessfulTime on an early return, else at the communication point), the run ended on
    terminateSimulation after that step's row. Returns the rows' times and statuses and the status it ended with."""
    rows, status = [], OK
    with Slave3(None, unzipped=str(unzipped), name="fmusim") as s:
        def call(st: int) -> bool:
            nonlocal status
            status = st
            return st > OK

        values = {**start, **({"mode": mode} if mode else {})}
        if not (call(s.call("fmi3EnterInitializationMode", False, 0.0, 0.0, True, stop)) or call(s.set(**values))
                or call(s.call("fmi3ExitInitializationMode"))):
            rows.append((0.0, int(s.get("status"))))
            t = 0.0
            while t < stop - 1e-12:
                st, term, early, last = s.step(h, t)
                if call(st):
                    break
                t = last if early else t + h
                rows.append((t, int(s.get("status"))))
                if term:
                    break
    return {"rows": rows, "status": status}


@pytest.mark.parametrize("master", ["fmpy.simulate_fmu", "fmpy simulate", "fmusim loop"])
def test_a_diverging_run_keeps_its_rows_in_every_master(fmu3, unzipped3, master, tmp_path):
    """Issue 24.7: simulate_fmu(fmu3, start_values={"g0": -2.9e-3}) raised FMICallException (fmi3DoStep failed
    with status 2 (discard)) and `fmpy simulate` exited 1 with no file: fmpy's FMI 3.0 loop raises on a Discard.
    The diverging step now ends the run as FMI 3.0 says (fmi3OK, terminateSimulation): every master keeps the rows
    so far and the diverged step's, whose status is 1, as the FMI 2.0 FMU gives them."""
    start = {"g0": -2.9e-3}  # an interference: the blades go past max_penetration within a few steps
    if master == "fmpy.simulate_fmu":
        r = fmpy.simulate_fmu(fmu3, start_values=start, stop_time=2.0, output_interval=1e-3,
                              output=["status", "gap_min"])
        times, status = r["time"], r["status"]
        assert r["gap_min"][-1] < -3e-3  # the diverged state's
    elif master == "fmpy simulate":
        import subprocess
        import sys

        out = tmp_path / "result.csv"
        cli = "import sys; from fmpy.cli import main; sys.argv[0] = 'fmpy'; sys.exit(main())"  # the fmpy command
        proc = subprocess.run([sys.executable, "-c", cli, "simulate", str(fmu3), "--start-values", "g0", "-0.0029",
                               "--stop-time", "2", "--output-interval", "1e-3", "--output-variables", "status",
                               "--output-file", str(out)], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 0, proc.stderr[-2000:]
        rows = np.genfromtxt(out, delimiter=",", names=True)
        times, status = rows["time"], rows["status"]
    else:
        r = fmusim3_loop(unzipped3, start, stop=2.0)
        assert r["status"] == OK
        times, status = np.array([t for t, _ in r["rows"]]), np.array([st for _, st in r["rows"]])
    assert 2 <= len(times) and times[-1] < 1.0 and status[-1] == 1 and (status[:-1] != 1).all()


def test_a_quasi_static_divergence_at_initialisation_gives_every_master_a_row(unzipped3, fmu3):
    """Issue 24.7: no balanced solution (or one deeper than max_penetration) at the initial inputs made
    fmi3ExitInitializationMode return a Warning, and fmusim, which stops at any status above OK, wrote an empty
    result. It is OK now, with status = 1 and the reason in 'message': fmusim's loop has the initial row (status 1)
    and the first step's, which ends the run; fmpy the same."""
    start = {"g0": 0.0, "max_penetration": 1e-5, **{k: START[k] for k in ("Omega", "imbalance")}}
    r = fmusim3_loop(unzipped3, start, mode=2)
    assert r["status"] == OK and r["rows"][0] == (0.0, 1) and len(r["rows"]) == 2 and r["rows"][-1][1] == 1
    with Slave3(None, unzipped=str(unzipped3)) as i:
        assert i.init(**start, mode=2) == OK
        assert i.get("status") == 1 and "penetrates the casing" in i.get("message")
        assert "penetrates the casing" in i.logged(level=WARNING)  # logged as a warning, logging off or on
        assert i.get("gap_min") < -1e-5  # the outputs of that too-deep solution
    res = fmpy.simulate_fmu(fmu3, start_values={**start, "mode": 2}, stop_time=1.0, output_interval=1e-3,
                            output=["status"])
    assert len(res) == 2 and (res["status"] == 1).all()


def test_serialized_state_continues_bit_for_bit_in_a_fresh_instance(inst):
    assert inst.init(formulation=1, **START) == OK
    for _ in range(100):
        assert inst.step()[0] == OK
    state = inst.f.getFMUState()
    data = inst.f.serializeFMUState(state)
    inst.f.freeFMUState(state)
    with Slave3(None, unzipped=inst.unzipped, name="fresh") as b:
        s2 = b.f.deserializeFMUState(data)
        b.f.setFMUState(s2)  # right after instantiation: the state brings its model (2D)
        b.t = inst.t
        assert b.get("formulation") == 1
        for _ in range(100):
            assert inst.step()[0] == OK and b.step()[0] == OK
            assert np.array_equal(inst.get("blade.F_N"), b.get("blade.F_N"))
        assert inst.get("blade.F_N").max() > 10.0
        b.f.freeFMUState(s2)


# ------------------------------------------------------------------------------------------ misuse: fmi3Error
def _same_after(inst, probe):
    """The values a refusal must leave as they were."""
    return {n: inst.get(n) for n in probe}


PROBE = ("Omega", "imbalance", "g0", "mu", "formulation", "n_sectors", "status")


@pytest.mark.parametrize("name, value", [
    ("Omega", -1.0), ("Omega", 1e4), ("Omega", float("nan")), ("imbalance", float("inf")), ("g0", -0.02),
    ("mu", -0.1), ("theta", math.pi / 2), ("formulation", 3), ("mode", 0), ("n_sectors", 2)])
def test_out_of_range_value_is_refused(inst, name, value):
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == OK
    before = _same_after(inst, [p for p in PROBE if p != "status"])
    n = len(inst.messages)
    assert inst.set(**{name: value}) == ERROR
    said = inst.logged(n)
    assert name in said and "accepted range" in said, said
    assert _same_after(inst, before) == before
    assert inst.call("fmi3ExitInitializationMode") == OK and inst.step()[0] == OK  # goes on with the old value


@pytest.mark.parametrize("fn, name, ctype, value, says", [
    ("fmi3SetInt32", "Omega", fmi3Int32, 100, "Omega (value reference 0) is of type Float64: use fmi3GetFloat64"),
    ("fmi3SetFloat64", "n_sectors", fmi3Float64, 100.0, "n_sectors (value reference"),
    ("fmi3SetInt32", "formulation", fmi3Int32, 1, "is of type Enumeration: use fmi3GetInt64/fmi3SetInt64"),
    ("fmi3SetFloat32", "Omega", ctypes.c_float, 100.0, "is of type Float64, not Float32"),
    ("fmi3SetBoolean", "g0", ctypes.c_bool, True, "this FMU has no Boolean variable"),
    ("fmi3SetUInt64", "Omega", fmi3UInt64, 100, "is of type Float64")])
def test_wrong_type_is_refused(inst, fn, name, ctype, value, says):
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == OK
    before = _same_after(inst, PROBE)
    n = len(inst.messages)
    vrs, nvr = _vrs(inst.vr[name])
    vals, nv = _vals(ctype, [value])
    assert inst.call(fn, vrs, nvr, vals, nv) == ERROR
    assert says in inst.logged(n), inst.logged(n)
    before["status"] = 2  # the status output says: bad input
    assert _same_after(inst, PROBE) == before


def test_wrong_getter_and_unknown_value_reference_are_refused(inst):
    assert inst.init(**START) == OK
    n = len(inst.messages)
    vrs, nvr = _vrs(inst.vr["n_contact"])
    out = (fmi3Float64 * 1)()
    assert inst.call("fmi3GetFloat64", vrs, nvr, out, 1) == ERROR
    assert "n_contact" in inst.logged(n) and "Int32" in inst.logged(n)
    vrs, nvr = _vrs(4)  # the gap the pythonfmu flavour's param_file keeps in FMI 2.0
    assert inst.call("fmi3GetFloat64", vrs, nvr, out, 1) == ERROR and "unknown value reference 4" in inst.logged(n)
    assert inst.step()[0] == OK


def test_array_size_must_match_nvalues(inst):
    """nValues is the number of elements of the value references given: an array of 10 read with 5 (or 11), two
    scalars set with one value: refused, nothing read or stored."""
    assert inst.init(**START) == OK
    for _ in range(40):
        inst.step()
    n = len(inst.messages)
    fn_vr = inst.vr["blade.F_N"]
    for count in (5, 11, 1):
        vrs, nvr = _vrs(fn_vr)
        out = (fmi3Float64 * count)(*([-7.0] * count))
        assert inst.call("fmi3GetFloat64", vrs, nvr, out, count) == ERROR
        assert f"nValues = {count}" in inst.logged(n) and "10 element(s)" in inst.logged(n)
        assert list(out) == [-7.0] * count  # nothing written
    vrs, nvr = _vrs(fn_vr, inst.vr["gap_min"])
    out = (fmi3Float64 * 11)()
    assert inst.call("fmi3GetFloat64", vrs, nvr, out, 11) == OK and list(out)[:10] == list(inst.get("blade.F_N"))
    vrs, nvr = _vrs(inst.vr["Omega"], inst.vr["imbalance"])
    vals, _ = _vals(fmi3Float64, [150.0, 0.01])
    assert inst.call("fmi3SetFloat64", vrs, nvr, vals, 1) == ERROR and "nValues = 1" in inst.logged(n)
    assert inst.get("Omega") == START["Omega"]  # all or nothing: the first value was not stored either
    assert inst.step()[0] == OK


def test_calls_in_the_wrong_state_are_refused(inst):
    n = len(inst.messages)
    assert inst.step()[0] == ERROR and "the instance is in instantiated" in inst.logged(n)
    assert inst.call("fmi3Terminate") == ERROR
    assert inst.call("fmi3EnterEventMode") == ERROR and "hasEventMode = false" in inst.logged(n)
    assert inst.set(n_blades=10) == ERROR and "configuration mode" in inst.logged(n)
    assert inst.call("fmi3EnterConfigurationMode") == OK
    assert inst.set(n_blades=10) == OK  # its one value
    assert inst.set(n_blades=24) == ERROR and "rebuild" in inst.logged(n) and "[10, 10]" in inst.logged(n)
    assert inst.set(Omega=100.0) == ERROR and "only structural parameters" in inst.logged(n)
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == ERROR
    assert inst.call("fmi3ExitConfigurationMode") == OK
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == OK
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == ERROR
    assert inst.call("fmi3Terminate") == ERROR and "fmi3Reset or fmi3FreeInstance" in inst.logged(n)
    assert inst.set(**START) == OK and inst.call("fmi3ExitInitializationMode") == OK
    assert inst.set(k_r=2e6) == ERROR and "fixed parameter" in inst.logged(n)
    assert inst.set(**{"blade.F_N": [1.0] * 10}) == ERROR and "is an output" in inst.logged(n)
    assert inst.set(time=1.0) == ERROR and "independent variable" in inst.logged(n)
    assert inst.step(1e12)[0] == ERROR and "at most 10000000 are taken in one step" in inst.logged(n)
    assert inst.step()[0] == OK  # every refusal left the instance as it was
    assert inst.call("fmi3Terminate") == OK
    assert inst.step(1e-3, inst.t)[0] == ERROR and "terminated" in inst.logged(n)


def test_instantiation_refusals_are_logged(unzipped3):
    from fmpy import read_model_description
    from fmpy.fmi3 import FMU3Slave

    md = read_model_description(str(unzipped3))
    got: list[str] = []

    def log(_env, _status, _cat, msg):
        got.append(msg.decode())

    f = FMU3Slave(guid=md.guid, unzipDirectory=str(unzipped3), modelIdentifier="RotorCasingContact",
                  instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        f.instantiate(eventModeUsed=True, logMessage=log)
    assert "no event mode" in got[-1]
    f = FMU3Slave(guid="{not-this-one}", unzipDirectory=str(unzipped3), modelIdentifier="RotorCasingContact",
                  instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        f.instantiate(logMessage=log)
    assert "{not-this-one}" in got[-1] and md.guid in got[-1]


def test_enumeration_through_int64_and_messages_shortest_decimals(inst):
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == OK
    vrs, nvr = _vrs(inst.vr["formulation"])
    vals, nv = _vals(fmi3Int64, [1])
    assert inst.call("fmi3SetInt64", vrs, nvr, vals, nv) == OK and inst.get("formulation") == 1
    n = len(inst.messages)
    assert inst.set(Omega=700.0) == ERROR and "accepted range [0, 640.8]" in inst.logged(n)
    assert inst.get("message") == inst.logged(n)  # the cause is in the 'message' output too
    assert inst.call("fmi3ExitInitializationMode") <= WARNING


# ------------------------------------------------------------------------------------------ the product
ARCH3 = {"x86_64-linux": "x86_64", "aarch64-linux": "aarch64", "x86_64-windows": "x86_64",
         "x86_64-darwin": "x86_64", "aarch64-darwin": "aarch64"}


def test_every_platform_of_the_fmi2_fmu_in_fmi3_folders(tmp_path):
    """The FMI 2.0 native FMU's platforms and baseline: each binary, in its FMI 3.0 folder, exports the whole FMI
    3.0 API for its architecture and nothing of the kernel; the Linux ones need glibc 2.17 and no libm."""
    pytest.importorskip("ziglang", reason="cross-compiling the FMU needs ziglang (a dependency of rotorub)")
    from fmu_src.fmi.binaries import elf_version_needs, exported_symbols, missing_fmi_functions, newest_glibc
    from fmu_src.models.contact.builder import build_native_fmu

    out = build_native_fmu(tmp_path / "all", fmi="3.0")
    assert set(out["platforms"]) == {"linux64", "aarch64-linux", "win64", "darwin64", "aarch64-darwin"}
    with zipfile.ZipFile(out["fmu"]) as z:
        z.extractall(tmp_path / "unz")
    for folder, arch in ARCH3.items():
        [binary] = list((tmp_path / "unz" / "binaries" / folder).iterdir())
        [(got, names)] = exported_symbols(binary)
        assert got == arch and missing_fmi_functions(binary, "3.0") == {arch: []}, folder
        assert not [n for n in names if n.startswith(("rr_", "core_", "model_"))], folder
        if folder.endswith("linux"):
            assert set(elf_version_needs(binary)) == {"libc.so.6"} and newest_glibc(binary) <= (2, 17), folder


def test_rebuilt_with_the_fmus_own_cmakelists_gives_the_same_numbers(fmu3, tmp_path):
    import shutil
    import subprocess
    import sys

    cmake = shutil.which("cmake") or str(Path(sys.executable).parent / "cmake")
    if not Path(cmake).exists() and not shutil.which(cmake):
        pytest.skip("no cmake")
    d, ref = tmp_path / "fmu", tmp_path / "ref"
    for x in (d, ref):
        with zipfile.ZipFile(fmu3) as z:
            z.extractall(x)
    build = tmp_path / "build"
    for args in (["-S", str(d / "sources"), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"],
                 ["--build", str(build), "--config", "Release"]):
        r = subprocess.run([cmake, *args], capture_output=True, text=True)
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    shutil.copy2(build / "RotorCasingContact.so", d / "binaries" / "x86_64-linux" / "RotorCasingContact.so")

    def run(folder: Path) -> np.ndarray:
        with Slave3(None, unzipped=str(folder), early_return=True) as s:
            assert s.init(**START) == OK
            rows = []
            for _ in range(300):
                assert s.step(1e-3)[0] == OK
                rows.append(s.get("blade.F_N"))
        return np.array(rows)

    a, b = run(ref), run(d)
    assert a.max() > 10.0 and np.array_equal(a, b)


# ------------------------------------------------------------------------------------------ found in fmusim 0.0.39
_STATE_BY_VALUE = """
import ctypes, sys
from fmu_src.masters.fmi3 import Slave3
i = Slave3(None, unzipped=sys.argv[1])
assert i.init(g0=0.2e-3, Omega=176.2, imbalance=0.022) == 0 and i.step()[0] == 0
state = i.f.getFMUState()
free = ctypes.CDLL(i.f.dll._name).fmi3FreeFMUState  # without fmpy's argtypes: the state itself goes in
free.restype = ctypes.c_int
print("status", free(ctypes.c_void_p(i.f.component), state))
print("step", i.step()[0])
print("log", " | ".join(m for s, m in i.messages if s >= 1))
i.free()
"""


def test_a_state_freed_by_value_is_freed_with_a_warning_not_a_crash(unzipped3):
    """fmusim 0.0.39 hands fmi3FreeFMUState the state itself, not the address of the variable holding it (a crash
    of the host before): freed, with a logged warning and OK (fmusim stops at any other status), and the instance
    goes on. In a process of its own."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-c", _STATE_BY_VALUE, str(unzipped3)], capture_output=True, text=True,
                       timeout=60, cwd=str(Path(__file__).resolve().parents[2]))
    assert r.returncode == 0, r.stderr[-2000:]
    out = dict(line.split(" ", 1) for line in r.stdout.splitlines())
    assert out["status"] == str(OK) and out["step"] == str(OK)  # OK: fmusim ends its run at any other status
    assert "instead of a pointer to it" in out["log"]


def test_outputs_are_readable_in_initialization_mode(inst):
    """The initial state's outputs in initialization mode, following the values set so far (FMI 3.0 allows
    reading them there; they read 0 before)."""
    assert inst.call("fmi3EnterInitializationMode", False, 0.0, 0.0, False, 0.0) == OK
    assert inst.set(g0=0.7e-3) == OK
    assert inst.get("gap_min") == 0.7e-3 and np.all(inst.get("blade.gap_tip") == 0.7e-3)
    assert inst.call("fmi3ExitInitializationMode") == OK
