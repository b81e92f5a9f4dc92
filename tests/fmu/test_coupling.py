"""Engine coupling: the LP spool FMU (native C and pythonfmu), the SSP of the coupled system, the masters.

The engine system is the native spool with the native contact FMU (no Python anywhere); the pythonfmu
spool, the example of a slave in Python, is run with the pythonfmu contact FMU. Both pairs are built once
from the current sources (conftest's contact FMUs, fmu_src.models.spool.builder's spool builds) and every physics
test runs on both.
The coupled scenario (fmu_src.systems.coupling.scenario_settings(quick=True)): the spool runs up
from 2.8 to 4.2 x omega_ref (half-cosine, 0.5 s -> 4.5 s) through the first critical
speed (3.49 x omega_ref) with the reference imbalance 22 kg mm, 3D contact, h = 1 ms,
once with the rub disabled (g0 = 1 m) and once with g0 = 1 mm.
"""

from __future__ import annotations

import io
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
pytest.importorskip("fmpy")
pytest.importorskip("lxml")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from fmu_src.masters.fmi2 import FMUError  # noqa: E402
from fmu_src.models.spool.builder import build_native_spool_fmu  # noqa: E402
from fmu_src.systems.coupling import (  # noqa: E402
    CONNECTIONS,
    EngineError,
    FmuInstance,
    build_spool_fmu,
    run_coupled,
    scenario_settings,
    ssp_contents,
    validate_ssp,
    write_ssp,
)

CFG = scenario_settings(quick=True)
SP = CFG["spool_params"]
J_REF, CW_REF = 55.5, 0.05  # the spool FMU's defaults (fmu_src/models/spool/variables.py)


def schedule(t, w0=SP["Omega0"], w1=SP["Omega1"], t1=SP["t_ramp_start"], T=SP["t_ramp"]):
    """Half-cosine speed schedule and its derivative, written independently of the slave."""
    t = np.asarray(t, dtype=float)
    x = np.clip((t - t1) / T, 0.0, 1.0)
    w = w0 + (w1 - w0) * (1.0 - np.cos(np.pi * x)) / 2.0
    wd = np.where((x > 0) & (x < 1), (w1 - w0) * np.pi / (2.0 * T) * np.sin(np.pi * x), 0.0)
    return w, wd


def integrate_spool(t_eval, tau_ext, J=J_REF, cw=CW_REF):
    """Independent solution of J dOmega/dt = tau_drive(t) - c_w Omega^2 + tau_ext (tau_ext constant), tau_drive
    the schedule's feed-forward torque, by scipy's DOP853 in pieces split at the schedule's acceleration kinks."""
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        w, wd = schedule(t)
        return [(J * float(wd) + cw * float(w) ** 2 - cw * y[0] ** 2 + tau_ext) / J]

    kinks = [SP["t_ramp_start"], SP["t_ramp_start"] + SP["t_ramp"]]
    edges = [t_eval[0]] + [k for k in kinks if t_eval[0] < k < t_eval[-1]] + [t_eval[-1]]
    out = np.empty_like(t_eval)
    y0 = float(schedule(t_eval[0])[0])
    for a, b in zip(edges[:-1], edges[1:]):
        m = (t_eval >= a) & (t_eval <= b)
        sol = solve_ivp(rhs, (a, b), [y0], method="DOP853", t_eval=t_eval[m], rtol=1e-13, atol=1e-10)
        assert sol.success
        out[m] = sol.y[0]
        y0 = float(sol.y[0, -1])
    return out


@pytest.fixture(scope="module")
def spools(tmp_path_factory):
    d = tmp_path_factory.mktemp("engine_fmus")
    return {"native": build_native_spool_fmu(d / "native", platforms=("linux64",)), "pythonfmu": build_spool_fmu(d)}


@pytest.fixture(scope="module", params=["native", "pythonfmu"])
def fmus(request, spools):
    """A spool flavour with the contact FMU of the same flavour."""
    contact = request.getfixturevalue("native_fmu" if request.param == "native" else "contact_fmu")
    return {"contact": Path(contact), "spool": spools[request.param], "flavour": request.param}


@pytest.fixture(scope="module")
def runs(fmus):
    common = {"t_end": CFG["t_end"], "h": CFG["h"], "imbalance": CFG["imbalance"], "formulation": CFG["formulation"],
              "spool_params": SP}
    ref = run_coupled(fmus["contact"], fmus["spool"], g0=CFG["g0_no_rub"], **common)
    rub = run_coupled(fmus["contact"], fmus["spool"], g0=CFG["g0_rub"], **common)
    return ref, rub


# ------------------------------------------------------------------------------------------ (a) FMI validity
def test_both_fmus_pass_fmpy_validation(fmus):
    for name in ("contact", "spool"):
        assert validate_fmu(str(fmus[name])) == [], name
    with zipfile.ZipFile(fmus["spool"]) as z:
        md = z.read("modelDescription.xml").decode()
        names = z.namelist()
    assert "<InitialUnknowns>" in md and "<UnitDefinitions>" in md
    assert 'canGetAndSetFMUstate="true"' in md and 'canSerializeFMUstate="true"' in md
    if fmus["flavour"] == "pythonfmu":  # the script travels under a hashed module name (one sys.modules)
        assert any(n.startswith("resources/lpspool_") and n.endswith(".py") for n in names)
    else:  # C, with its sources, no Python
        assert "binaries/linux64/LPSpool.so" in names and "sources/model.c" in names


def test_both_spool_flavours_have_one_interface_and_the_same_numbers(spools):
    """Same variables, value references, units, ranges and start values; under a braking torque the same
    speeds to round-off (the schedule's cosine is rr_math.h's in C, Python's in the slave)."""
    from fmpy import read_model_description

    mds = {f: read_model_description(str(p)) for f, p in spools.items()}
    rows = {f: [(v.name, v.valueReference, v.causality, v.unit, v.min, v.max, v.start) for v in md.modelVariables]
            for f, md in mds.items()}
    assert rows["native"] == rows["pythonfmu"]
    w = {}
    for f, path in spools.items():
        s = FmuInstance(path, f"same_{f}")
        try:
            s.initialize(0.0, 5.0, **SP)
            out = []
            for k in range(5000):
                s.set(friction_torque=-400.0 if 1.0 <= k * 1e-3 < 3.0 else 0.0)
                s.fmu.doStep(k * 1e-3, 1e-3)
                out.append([s.get(n) for n in ("Omega", "Omega_schedule", "drive_torque", "windage_torque")])
            w[f] = np.array(out)
        finally:
            s.close()
    assert w["native"][-1, 0] < w["native"][-1, 1] - 1.0  # the torque did act
    np.testing.assert_allclose(w["native"], w["pythonfmu"], rtol=1e-12, atol=1e-12)


def test_a_stopping_spool_ends_the_run_and_a_rollback_goes_on(fmus):
    """A braking torque that would stop the spool: that step is refused (fmi2Discard, status 1) with the reason,
    the FMU asks to end the run (fmi2Terminated) and refuses another step; a rollback to a state saved before
    lets the run go on with a smaller torque."""
    from fmpy.fmi2 import fmi2Terminated

    s = FmuInstance(fmus["spool"], "stops")
    try:
        s.initialize(0.0, 1.0, **{**SP, "Omega0": 5.0, "Omega1": 5.0})
        state = s.fmu.getFMUstate()
        s.set(friction_torque=-2000.0)  # 36 rad/s^2 down from 5 rad/s: stopped before 0.14 s
        with pytest.raises(FMICallException, match="discard"):
            for k in range(1000):
                s.fmu.doStep(k * 1e-3, 1e-3)
        assert 0.1 < k * 1e-3 < 0.2 and s.get("status") == 1 and "would stop" in s.get("message")
        assert s.fmu.getBooleanStatus(fmi2Terminated)
        with pytest.raises(FMICallException):
            s.fmu.doStep(k * 1e-3, 1e-3)
        assert "ended this simulation" in s.get("message")
        s.fmu.setFMUstate(state)
        s.set(friction_torque=-10.0)
        for k in range(200):
            s.fmu.doStep(k * 1e-3, 1e-3)
        assert s.get("status") == 0 and 0.0 < s.get("Omega") < 5.0
        s.fmu.freeFMUstate(state)
    finally:
        s.close()


# ------------------------------------------------------------------------------------------ (b) no rub
def test_without_rub_the_spool_follows_its_drive_schedule(runs):
    ref, _ = runs
    assert ref.meta["steps_done"] == round(CFG["t_end"] / CFG["h"])
    assert np.all(ref.friction_torque == 0.0) and np.all(ref.n_contact == 0) and np.all(ref.F_N == 0.0)
    w, wd = schedule(ref.t)
    # closed form: the drive torque schedule is J dOmega_s/dt + c_w Omega_s^2, so Omega = Omega_s
    np.testing.assert_allclose(ref.omega, w, rtol=1e-12, atol=0)
    np.testing.assert_allclose(ref.drive_torque, J_REF * wd + CW_REF * w**2, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(ref.windage_torque, CW_REF * w**2, rtol=1e-12, atol=0)
    # and an independent integration of J dOmega/dt = tau_drive(t) - c_w Omega^2 from Omega0
    w_ivp = integrate_spool(ref.t, 0.0)
    assert np.max(np.abs(ref.omega - w_ivp) / w_ivp) < 1e-9
    assert ref.omega[0] == SP["Omega0"] and ref.omega[-1] == pytest.approx(SP["Omega1"], rel=1e-12)


def test_spool_alone_matches_an_independent_integration_with_a_braking_torque(fmus):
    """RK4 on e = Omega - Omega_s, 1 substep per 1 ms: its error is far below 1e-9 relative."""
    h, n, tau = 1e-3, 3000, -400.0
    s = FmuInstance(fmus["spool"], "spool_alone")
    try:
        s.initialize(0.0, n * h, **SP)
        s.set(friction_torque=tau)
        w = np.empty(n + 1)
        w[0] = s.get("Omega")
        for k in range(n):
            s.fmu.doStep(k * h, h)
            w[k + 1] = s.get("Omega")
    finally:
        s.close()
    t = np.arange(n + 1) * h
    w_ivp = integrate_spool(t, tau)
    assert np.max(np.abs(w - w_ivp) / w_ivp) < 1e-9
    assert w_ivp[-1] < schedule(t[-1])[0] - 10.0  # the braking torque did matter


# ------------------------------------------------------------------------------------------ (c) with rub
def test_with_rub_the_friction_torque_slows_the_spool_by_the_balance(runs):
    """Angular momentum: J (Omega_rub(T) - Omega_ref(T)) = sum_k tau_f(t_k) h - int c_w (Omega_rub^2 -
    Omega_ref^2) dt (the drive torque is the same schedule in both runs). The friction sum is exact (the spool
    held tau_f(t_k) over [t_k, t_k + h], Jacobi exchange); the windage integral is a trapezoid rule on the
    recorded outputs, error ~ h^2/12 int |w''| dt with w = c_w (Omega_rub^2 - Omega_ref^2), a small smooth term;
    the spool's RK4 error is O(dt^4). Measured: ~4e-9 of the friction impulse; tolerance 1e-6."""
    ref, rub = runs
    s = rub.summary(reference=ref)
    assert s["max_contact_force_N"] > 100.0 and s["max_n_contact"] >= 1
    assert s["friction_impulse_N_m_s"] < -10.0  # the rub brakes the spool
    assert s["min_spool_speed_dip_rad_s"] > 0.5
    assert np.all(rub.omega <= ref.omega + 1e-9)  # braking only: never faster than the rub-free spool
    mb = s["momentum_balance"]
    assert mb["drive_impulse_difference_N_m_s"] == 0.0
    assert mb["relative_residual"] < 1e-6, mb
    eb = s["energy_balance"]  # J/2 (Omega^2) against the work of the torques, all trapezoid: O(h^2) too
    assert eb["relative_residual"] < 1e-6, eb
    assert eb["friction_work_J"] < 0
    # the rub starts while the spool passes the first critical speed (3.49 x omega_ref), not before
    first = int(np.argmax(rub.n_contact > 0))
    assert 0.9 * 3.49 * 53.4 < rub.omega[first] < 1.15 * 3.49 * 53.4
    # the speed is the rub-free one until the first contact (one step of exchange delay)
    assert np.array_equal(rub.omega[: first + 1], ref.omega[: first + 1])
    assert np.all(rub.contact_status == 0) and np.all(rub.spool_status == 0)


def test_result_files(runs, tmp_path):
    ref, rub = runs
    rub.save(tmp_path, reference=ref, stem="runup")
    png = tmp_path / "runup.png"
    assert png.stat().st_size > 20_000
    npz = rub.save_npz(tmp_path / "rub.npz")
    back = type(rub).load_npz(npz)
    assert np.array_equal(back.omega, rub.omega) and np.array_equal(back.F_N, rub.F_N)
    assert back.meta["g0"] == rub.meta["g0"] and back.summary(ref)["min_spool_speed_dip_rad_s"] > 0


# ------------------------------------------------------------------------------------------ (d) SSP
def test_ssp_validates_and_names_both_fmus_and_connections(fmus, tmp_path):
    ssp = write_ssp(tmp_path / "engine.ssp", fmus["contact"], fmus["spool"], g0=1e-3, imbalance=0.022,
                    spool_params=SP, t_end=CFG["t_end"], h=CFG["h"])
    assert validate_ssp(ssp) == []
    c = ssp_contents(ssp)
    assert c["components"] == {"contact": "resources/RotorCasingContact.fmu", "spool": "resources/LPSpool.fmu"}
    assert set(c["connections"]) == set(CONNECTIONS) == {("spool", "Omega", "contact", "Omega"),
                                                         ("contact", "friction_torque", "spool", "friction_torque")}
    with zipfile.ZipFile(ssp) as z:
        assert z.read("resources/LPSpool.fmu") == fmus["spool"].read_bytes()
        assert z.read("resources/RotorCasingContact.fmu") == fmus["contact"].read_bytes()
        ssv = z.read("resources/spool.ssv").decode()
    assert 'name="t_ramp"' in ssv and 'value="4.0"' in ssv


def _rewrite(ssp, out, name, fn):
    with zipfile.ZipFile(ssp) as zin, zipfile.ZipFile(out, "w") as zout:
        for n in zin.namelist():
            data = zin.read(n)
            zout.writestr(n, fn(data) if n == name else data)
    return out


def test_ssp_validation_rejects_broken_packages(fmus, tmp_path):
    ssp = write_ssp(tmp_path / "ok.ssp", fmus["contact"], fmus["spool"])
    bad_kind = _rewrite(ssp, tmp_path / "k.ssp", "SystemStructure.ssd",
                        lambda b: b.replace(b'kind="output"', b'kind="sideways"', 1))
    assert any("sideways" in p for p in validate_ssp(bad_kind))  # schema: kind is an enumeration
    no_conn = _rewrite(ssp, tmp_path / "c.ssp", "SystemStructure.ssd",
                       lambda b: b.replace(b'endConnector="friction_torque"', b'endConnector="torque"'))
    assert any("torque is not declared" in p for p in validate_ssp(no_conn))
    bad_ssv = _rewrite(ssp, tmp_path / "v.ssp", "resources/spool.ssv",
                       lambda b: b.replace(b'value="55.5"', b'value="heavy"'))
    assert any("spool.ssv" in p for p in validate_ssp(bad_ssv))  # xs:double
    bad_par = _rewrite(ssp, tmp_path / "p.ssp", "resources/spool.ssv",
                       lambda b: b.replace(b'name="c_w"', b'name="c_windage"'))
    assert any("c_windage" in p for p in validate_ssp(bad_par))
    assert validate_ssp(io.BytesIO(b"not a zip")) != []


# ------------------------------------------------------------------------------------------ (e) rollback
def test_spool_rollback_reproduces_a_run_exactly(fmus):
    h = 1e-3

    def tau(k):
        return -300.0 * math.sin(0.01 * k) ** 2

    s = FmuInstance(fmus["spool"], "rollback")
    try:
        s.initialize(0.0, 1.0, **SP)
        for k in range(100):
            s.set(friction_torque=tau(k))
            s.fmu.doStep(k * h, h)
        state = s.fmu.getFMUstate()
        serial = s.fmu.serializeFMUstate(state)

        def leg():
            out = []
            for k in range(100, 300):
                s.set(friction_torque=tau(k))
                s.fmu.doStep(k * h, h)
                out.append([s.get(n) for n in ("Omega", "drive_torque", "windage_torque")])
            return np.array(out)

        first = leg()
        s.fmu.setFMUstate(state)
        second = leg()
        s.fmu.setFMUstate(s.fmu.deSerializeFMUstate(serial))
        third = leg()
        s.fmu.freeFMUstate(state)
    finally:
        s.close()
    assert np.array_equal(first, second) and np.array_equal(first, third)
    assert first[-1, 0] < schedule(0.3)[0]  # the torque did act


# ------------------------------------------------------------------------------------------ (f) bad input
def test_bad_input_is_reported_through_fmpy_and_a_new_instance_works(fmus):
    """A parameter or an input outside its declared range: the native spool refuses it at the fmi2SetReal
    (fmi2Error, the message names it and the range); the pythonfmu one logs it there and refuses the next
    step (its documented limit). The state is kept and the instance, or a new one, goes on."""
    native = fmus["flavour"] == "native"
    refused = r"J = -1(\.0)? .*out of range; accepted range \[0\.001, 100000(\.0)?\]"
    with pytest.raises(EngineError, match=refused):
        run_coupled(fmus["contact"], fmus["spool"], t_end=0.01, spool_params={"J": -1.0})
    s = FmuInstance(fmus["spool"], "nan_torque")
    try:
        s.initialize(0.0, 1.0)
        s.fmu.doStep(0.0, 1e-3)
        w = s.get("Omega")
        if native:
            with pytest.raises(FMUError, match="friction_torque = nan is not finite"):
                s.set(friction_torque=float("nan"))
        else:
            s.set(friction_torque=float("nan"))
            with pytest.raises(FMICallException, match="discard"):
                s.fmu.doStep(1e-3, 1e-3)
        assert any("friction_torque = nan" in m and "accepted range" in m for m in s.log.problems())
        assert s.get("Omega") == w and s.get("status") == 2
        s.set(friction_torque=0.0)
        s.fmu.doStep(1e-3, 1e-3)
        assert s.get("status") == 0
    finally:
        s.close()
    # a brand-new coupled run in the same process works
    r = run_coupled(fmus["contact"], fmus["spool"], t_end=0.05, g0=0.05, spool_params=SP)
    assert r.meta["steps_done"] == 50 and np.array_equal(r.omega, schedule(r.t)[0])


def _rub_ssp(fmus, tmp_path, t_end):
    sp = {**SP, "Omega0": 183.0, "Omega1": 190.0, "t_ramp_start": 0.1, "t_ramp": 1.0}  # at the critical: rub
    ssp = write_ssp(tmp_path / "engine.ssp", fmus["contact"], fmus["spool"], g0=CFG["g0_rub"],
                    imbalance=CFG["imbalance"], spool_params=sp, t_end=t_end, h=CFG["h"])
    assert validate_ssp(ssp) == []
    ref = run_coupled(fmus["contact"], fmus["spool"], t_end=t_end, h=CFG["h"], g0=CFG["g0_rub"],
                      imbalance=CFG["imbalance"], spool_params=sp)
    assert ref.friction_torque.min() < -1.0, "the scenario must rub for the comparison to say something"
    return ssp, ref


def test_ssp_runs_in_libcosim_and_gives_the_fmpy_master_loops_spool_speed(fmus, tmp_path):
    """The package as written, loaded by a second co-simulation engine (OSP libcosim, from_ssp_file): with rub,
    its spool speed and friction torque are the fmpy loop's (both masters exchange at the communication points
    and hold the inputs over the step)."""
    pytest.importorskip("libcosimpy", reason="libcosimpy: Linux x86_64, Python >= 3.11")
    from fmu_src.systems.ssp import run_ssp_libcosim

    ssp, ref = _rub_ssp(fmus, tmp_path, 1.2)
    lc = run_ssp_libcosim(ssp, 1.2, CFG["h"])
    np.testing.assert_allclose(lc["spool.Omega"], ref.omega[1:], rtol=1e-9)
    np.testing.assert_allclose(lc["contact.friction_torque"], ref.friction_torque[1:], rtol=1e-9,
                               atol=1e-9 * np.abs(ref.friction_torque).max())


def test_ssp_runs_in_a_process_with_no_python(fmus, tmp_path):
    """The package as written, run by a C master (fmu_src/masters/hosts/engine_host.c) in an environment without
    Python: the native pair gives the fmpy loop's spool speed and friction torque bit for bit (same exchange,
    same FMUs). The pythonfmu pair cannot even load there: its binaries need libpython, which is the point."""
    import sys

    if sys.platform != "linux":
        pytest.skip("the C master is run here on Linux")
    from fmu_src.systems.ssp import run_ssp_native

    ssp, ref = _rub_ssp(fmus, tmp_path, 1.2)
    if fmus["flavour"] == "pythonfmu":
        with pytest.raises(EngineError, match="undefined symbol"):
            run_ssp_native(ssp, 1.2)
        return
    nat = run_ssp_native(ssp, 1.2)
    assert np.array_equal(nat["t"], ref.t[1:])
    assert np.array_equal(nat["spool.Omega"], ref.omega[1:])
    assert np.array_equal(nat["contact.friction_torque"], ref.friction_torque[1:])


def test_ssd_carries_omsimulators_system_annotation_and_a_proper_name(fmus, tmp_path):
    """OMSimulator 3.0 aborts on an SSD whose system lacks its org.openmodelica annotation (the master: a
    fixed-step co-simulation); the system is named for what it is (it was named after a loop variable)."""
    from xml.etree import ElementTree as ET

    from fmu_src.systems.ssp import NS, OMS_NS

    ssp = write_ssp(tmp_path / "engine.ssp", fmus["contact"], fmus["spool"], h=2e-3)
    assert validate_ssp(ssp) == []
    with zipfile.ZipFile(ssp) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    system = root.find("ssd:System", NS)
    assert root.get("name") == system.get("name") == "RotorRubEngine"
    ann = system.find("ssd:Annotations/ssc:Annotation", NS)
    assert ann.get("type") == "org.openmodelica"
    master = ann.find(f"{{{OMS_NS}}}Annotations/{{{OMS_NS}}}SimulationInformation/{{{OMS_NS}}}FixedStepMaster")
    assert master is not None and master.get("description") == "oms-ma" and float(master.get("stepSize")) == 2e-3
