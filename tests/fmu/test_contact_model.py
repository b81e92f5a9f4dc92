"""Both flavours of RotorCasingContact.fmu (pythonfmu and native C) against the library.

Every comparison runs the same arithmetic on both sides (the pythonfmu FMU carries a copy of
the library, the native one the same kernel and the same order of operations), so the
tolerances are round-off, not modelling tolerances. The FMI behaviour a system simulator
relies on (status codes, refusals, rollback) is tests/fmu/test_fmi2.py's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="the FMU tests drive the FMU with fmpy (pip install -e '.[fmu]')")
pytest.importorskip("pythonfmu", reason="building the FMU needs pythonfmu (pip install -e '.[fmu]')")

from fmu_src.masters.fmi2 import FMUError, Slave, simulate  # noqa: E402
from rotorub_model.analyses.stability import stability_of  # noqa: E402
from rotorub_model.analyses.static import solve_static  # noqa: E402
from rotorub_model.analyses.transient import critical_time_step, run_transient  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402

NB = 10
FN = [f"blade[{j}].F_N" for j in range(1, NB + 1)]
LE = [f"blade[{j}].gap_LE" for j in range(1, NB + 1)]
FR = [f"blade[{j}].contact_fraction" for j in range(1, NB + 1)]


@pytest.fixture(scope="module")
def fmu(any_fmu):
    return any_fmu


@pytest.fixture(scope="module")
def unzipped(fmu, tmp_path_factory):
    from fmpy import extract

    return extract(fmu, str(tmp_path_factory.mktemp("unzipped")))


def test_fmpy_validate_reports_no_problem(fmu):
    from fmpy.validation import validate_fmu

    assert validate_fmu(fmu) == []


def test_model_description_declares_units_and_structured_names(unzipped):
    from fmpy import read_model_description

    md = read_model_description(unzipped)
    v = {x.name: x for x in md.modelVariables}
    assert v["Omega"].causality == "input" and v["Omega"].unit == "rad/s"
    assert v["imbalance"].unit == "kg.m"
    assert v["blade[3].F_N"].causality == "output" and v["blade[3].F_N"].unit == "N"
    assert v["g0"].variability == "tunable"
    assert all(x.description for x in md.modelVariables)
    assert {u.name for u in md.unitDefinitions} >= {"rad/s", "N", "m", "N.m", "kg.m"}
    outs = [x for x in md.modelVariables if x.causality == "output"]
    assert len(md.initialUnknowns) == len(outs)


def test_transient_through_fmpy_equals_library_to_1e_9(fmu, ref_model):
    """3D, imbalance ramped over 1 s by the master, constant speed, h = 1 ms."""
    p = ref_model.params
    omega, g0, me, t_end = 3.3 * p.normalisation.omega_ref, 0.2e-3, p.imbalance.me, 1.5
    sig = np.array([(0.0, omega, 0.0), (1.0, omega, me), (t_end + 1.0, omega, me)],
                   dtype=[("time", float), ("Omega", float), ("imbalance", float)])
    outs = FN + LE + ["friction_torque", "casing_force.x", "casing_force.y", "status", "n_contact"]
    r = simulate(fmu, stop_time=t_end, output_interval=1e-3, input=sig, start_values={"g0": g0, "formulation": "3D"},
                 output=outs)
    lib = run_transient(ref_model, make_contact(ref_model, "3D", g0=g0), omega, t_end=t_end, t_ramp=1.0, me=me,
                        record_dt=1e-3, hold=1e-3)
    assert not lib.penetration_limit_hit and np.all(r["status"] == 0)
    F_fmu = np.array([r[n] for n in FN]).T[1:]  # row 0 is the initial state
    F_lib = lib.outputs["F_N"]
    assert F_fmu.shape == F_lib.shape == (1500, NB)
    scale = np.abs(F_lib).max()
    assert scale > 50.0, "the scenario must actually rub"
    assert r["n_contact"].max() >= 2
    assert np.abs(F_fmu - F_lib).max() <= 1e-9 * scale
    gap = np.array([r[n] for n in LE]).T[1:]
    assert np.abs(gap - lib.outputs["gap"][:, :, 0]).max() <= 1e-9 * np.abs(lib.outputs["gap"]).max()
    tq = lib.outputs["friction_torque"]
    assert np.abs(r["friction_torque"][1:] - tq).max() <= 1e-9 * np.abs(tq).max()
    Fc = lib.outputs["casing_force_fixed"]
    assert np.abs(r["casing_force.x"][1:] - Fc[:, 0]).max() <= 1e-9 * np.abs(Fc).max()


def test_run_down_to_rest_friction_follows_the_sliding(fmu, ref_model):
    """A run-down from 3.3 omega_ref to rest with an interference fit (g0 = -0.1 mm): once the spin
    stops, the ringing blades slide both ways over the casing and the friction force follows
    (F_T takes both signs, never above mu F_N); the FMU equals the library to 1e-9 all along."""
    p = ref_model.params
    w0, g0, me, t_end = 3.3 * p.normalisation.omega_ref, -0.1e-3, p.imbalance.me, 1.5
    sig = np.array([(0.0, w0, 0.0), (0.3, w0, me), (0.5, w0, me), (0.8, 0.0, me), (t_end + 1.0, 0.0, me)],
                   dtype=[("time", float), ("Omega", float), ("imbalance", float)])
    FT = [f"blade[{j}].F_T" for j in range(1, NB + 1)]
    r = simulate(fmu, stop_time=t_end, output_interval=1e-3, input=sig, start_values={"g0": g0, "formulation": "3D"},
                 output=FN + FT + ["status"])
    lib = run_transient(ref_model, make_contact(ref_model, "3D", g0=g0),
                        lambda t: w0 * min(max((0.8 - t) / 0.3, 0.0), 1.0), t_end=t_end, t_ramp=0.3, me=me,
                        record_dt=1e-3, hold=1e-3)
    assert not lib.penetration_limit_hit and np.all(r["status"] == 0)
    F_N, F_T = np.array([r[n] for n in FN]).T[1:], np.array([r[n] for n in FT]).T[1:]
    assert np.abs(F_N - lib.outputs["F_N"]).max() <= 1e-9 * np.abs(lib.outputs["F_N"]).max()
    assert np.abs(F_T - lib.outputs["F_T"]).max() <= 1e-9 * np.abs(lib.outputs["F_T"]).max()
    mu = p.contact.mu
    assert np.all(np.abs(F_T) <= mu * F_N * (1 + 1e-12) + 1e-12)
    spinning, at_rest = lib.t < 0.5, lib.t > 0.85
    # tip speed >> slip_velocity: Coulomb against the spin (summed over LE and TE: equal to rounding)
    np.testing.assert_allclose(F_T[spinning], mu * F_N[spinning], rtol=1e-12, atol=1e-12 * F_N.max())
    assert F_N[at_rest].max() > 50.0
    assert F_T[at_rest].min() < -0.5 and F_T[at_rest].max() > 0.5  # both ways once the spin has stopped


def test_quasi_static_mode_equals_static_solver(fmu, ref_model):
    """A speed sweep through contact: each step the balanced solution, warm-started from the last."""
    p = ref_model.params
    w_ref, g0, me = p.normalisation.omega_ref, 0.5e-3, p.imbalance.me
    speeds = np.linspace(2.9, 3.7, 17) * w_ref
    h = 0.1
    with Slave(fmu, mode="quasi_static", formulation="2D", g0=g0, Omega=speeds[0], imbalance=me) as s:
        got = []
        for k, w in enumerate(speeds):
            s.set(Omega=float(w))
            s.step(k * h, h)
            got.append((s.get_reals(FN), s.get("max_real_eig"), s.get("n_contact")))
    c = make_contact(ref_model, "2D", g0=g0)
    q = solve_static(ref_model, c, speeds[0], me=me).q  # what the FMU solved at initialization
    n_unstable = 0
    for (F, re, n), w in zip(got, speeds):
        st = solve_static(ref_model, c, float(w), me=me, q0=q)
        assert st.converged
        q = st.q
        sb = stability_of(ref_model, c, float(w), q)
        F_ref = c.outputs(q, float(w))["F_N"]
        assert np.abs(F - F_ref).max() <= 1e-9 * max(np.abs(F_ref).max(), 1.0)
        assert re == pytest.approx(sb.max_real, rel=1e-9, abs=1e-12)
        assert n == st.n_contact
        n_unstable += sb.max_real > 0
    assert max(g[2] for g in got) >= 2, "the sweep must cross contact"
    assert n_unstable > 0, "2D contact solutions at these speeds are unstable (paper fact 5)"


def _run(s: Slave, n: int, h: float = 1e-3) -> np.ndarray:
    rows = []
    for _ in range(n):
        s.step(None, h)
        rows.append(s.get_reals(FN + LE))
    return np.array(rows)


def test_rollback_reproduces_the_run_exactly(fmu, unzipped, ref_model):
    omega = 3.3 * ref_model.params.normalisation.omega_ref
    with Slave(fmu, unzip_dir=unzipped, g0=0.2e-3, Omega=omega, imbalance=ref_model.params.imbalance.me) as s:
        _run(s, 150)
        state = s.get_state()
        blob = s.serialize(state)
        first = _run(s, 100)
        assert first[:, :NB].max() > 10.0  # in contact: the state matters
        s.set(g0=0.05)  # a tunable change after the snapshot is rolled back too
        _run(s, 10)
        s.set_state(state)
        assert s.get("g0") == 0.2e-3
        again = _run(s, 100)
        s.set_state(s.deserialize(blob))
        from_bytes = _run(s, 100)
        s.free_state(state)
    assert np.array_equal(first, again)
    assert np.array_equal(first, from_bytes)


def test_substeps_follow_the_communication_step(fmu, unzipped, ref_model):
    """Variable step sizes: h = 1 ms and two steps of 0.5 ms use the same internal step, so the
    states agree exactly at the common points; a step that is not a multiple restarts cleanly."""
    omega = 3.3 * ref_model.params.normalisation.omega_ref
    kw = dict(unzip_dir=unzipped, g0=0.2e-3, Omega=omega, imbalance=ref_model.params.imbalance.me)
    with Slave(fmu, **kw) as a, Slave(fmu, instance_name="b", **kw) as b:
        ra = _run(a, 200, 1e-3)
        rb = _run(b, 400, 0.5e-3)[1::2]
        assert a.get("dt_internal") == b.get("dt_internal") == 0.5e-3
        assert np.array_equal(ra, rb)
        b.step(None, 0.37e-3)
        assert b.get("n_substeps") == 1 and b.get("dt_internal") == pytest.approx(0.37e-3)
        # the rule: n = ceil(h / min(dt_max, half the stability limit at Omega rounded up to a whole rad/s))
        cap = min(1e-3, 0.5 * critical_time_step(ref_model, make_contact(ref_model, "3D", g0=0.2e-3),
                                                 float(math.ceil(omega))))
        n = math.ceil(2.1e-3 / cap)
        assert 2 < n < 10
        b.step(None, 2.1e-3)
        assert b.get("n_substeps") == n and b.get("dt_internal") == pytest.approx(2.1e-3 / n)
        assert b.get("status") == 0


def test_g0_is_tunable_between_steps(fmu, unzipped, ref_model):
    omega = 3.3 * ref_model.params.normalisation.omega_ref
    with Slave(fmu, unzip_dir=unzipped, g0=0.2e-3, Omega=omega, imbalance=ref_model.params.imbalance.me) as s:
        F = _run(s, 300)[:, :NB]
        assert F[-1].max() > 10.0
        s.set(g0=0.05)
        s.step(None, 1e-3)
        assert s.get_reals(FN).max() == 0.0
        assert s.get("gap_min") > 0.04


def test_reset_returns_to_a_fresh_instance(fmu, unzipped, ref_model):
    omega = 3.3 * ref_model.params.normalisation.omega_ref
    me = ref_model.params.imbalance.me
    with Slave(fmu, unzip_dir=unzipped, g0=0.2e-3, Omega=omega, imbalance=me) as s:
        first = _run(s, 50)
        s.reset()
        s.fmu.setupExperiment(startTime=0.0)
        s.fmu.enterInitializationMode()
        s.set(g0=0.2e-3, Omega=omega, imbalance=me)
        s.fmu.exitInitializationMode()
        s.time = 0.0
        assert np.array_equal(_run(s, 50), first)


BAD_START = [  # (start values, a word the refusal names): refused at the set (native) or the first step
    ({"mode": 3}, "mode"),
    ({"formulation": 0}, "formulation"),
    ({"dt_max": 0.0}, "dt_max"),
    ({"k_r": -1.0}, "k_r"),
    ({"theta": 1.5707963267948966}, "theta"),
    ({"g0": float("nan")}, "g0"),
    ({"g0": -2e-3, "max_penetration": 1e-3}, "max_penetration"),  # each in range, together a divergence at t = 0
    ({"param_file": "/nonexistent/params.toml"}, "params.toml"),  # pythonfmu only: the native FMU has no param_file
]


@pytest.mark.parametrize("start,word", BAD_START)
def test_bad_parameter_is_an_error_naming_it_and_the_next_instance_works(fmu, unzipped, start, word):
    if "param_file" in start and "param_file" not in {v.name for v in fmpy.read_model_description(unzipped)
                                                      .modelVariables}:
        pytest.skip("the native FMU has no param_file (tests/fmu/test_fmi2.py checks it is not declared)")
    with pytest.raises(FMUError) as err:
        with Slave(fmu, unzip_dir=unzipped, instance_name="bad", **start) as s:
            s.step(0.0, 1e-3)
    assert word in str(err.value)
    with Slave(fmu, unzip_dir=unzipped, Omega=100.0) as s:  # same process, new instance
        s.step(0.0, 1e-3)
        assert s.get("status") == 0


@pytest.mark.parametrize("omega", [float("nan"), -1.0, float("inf"), 1e4])
def test_bad_spin_speed_is_refused_and_the_instance_goes_on(fmu, unzipped, omega):
    """Outside [0, the model's validity limit]: refused (the native FMU at fmi2SetReal, the pythonfmu
    one at the next fmi2DoStep), the state unchanged, and the same instance goes on."""
    with Slave(fmu, unzip_dir=unzipped, g0=0.2e-3, Omega=150.0, imbalance=0.02) as s:
        before = _run(s, 5)[-1]
        with pytest.raises(FMUError) as err:
            s.set(Omega=omega)
            s.step(None, 1e-3)
        assert "Omega" in str(err.value) and "accepted range" in str(err.value)
        assert s.get("status") == 2 and "Omega" in s.get("message")
        assert np.array_equal(s.get_reals(FN + LE), before)  # state unchanged
        s.set(Omega=150.0)
        s.step(None, 1e-3)
        assert s.get("status") == 0 and s.get("message") == ""


def test_bad_parameter_file_content_names_the_field(contact_fmu, tmp_path):
    """pythonfmu flavour only: the native FMU reads no parameter file (its model is built in)."""
    from rotorub_model.structure.params import REFERENCE_FILE

    bad = tmp_path / "bad.toml"
    bad.write_text(REFERENCE_FILE.read_text().replace("count = 10 ", "count = 1  "))
    with pytest.raises(FMUError) as err:
        simulate(contact_fmu, stop_time=0.002, output_interval=1e-3, start_values={"param_file": str(bad)})
    assert "blades.count" in str(err.value)


def test_divergence_ends_the_run_and_a_rollback_goes_on(fmu, unzipped, ref_model):
    """A 2.5 mm interference at the section-6 speed with the reference imbalance: the blades go deeper than
    max_penetration (3 mm) at about 1.47 s. That step is fmi2Discard with the reason, the FMU asks to end the
    run (fmi2Terminated) and refuses any further step; a rollback to a state saved before clears the flag
    (it belongs to the state), and the same instance goes on with a safe clearance."""
    p = ref_model.params
    omega, me = 3.3 * p.normalisation.omega_ref, p.imbalance.me
    with Slave(fmu, unzip_dir=unzipped, g0=-2.5e-3, Omega=omega, imbalance=me, formulation="3D") as s:
        _run(s, 1000)
        good = s.get_state()
        assert not s.terminated()
        with pytest.raises(FMUError) as err:
            _run(s, 1000)
        t_fail = s.time
        assert 1.2 < t_fail < 1.9, t_fail
        assert "diverged" in str(err.value) and "max_penetration = 3 mm" in str(err.value)
        assert s.get("status") == 1 and "diverged" in s.get("message")
        assert s.terminated()
        assert t_fail <= s.last_successful_time() <= t_fail + 1e-3
        assert min(s.get(f"blade[{j}].gap_tip") for j in range(1, NB + 1)) < -3e-3  # the state just past it
        with pytest.raises(FMUError) as again:  # no step from a diverged state ...
            s.step(None, 1e-3)
        assert "ended this simulation" in str(again.value)
        s.set_state(good)  # ... until rolled back to before the divergence
        # pythonfmu 0.7's binary keeps reporting fmi2Terminated once any step was discarded (contact/FMU.md)
        native = "native" in s.model_description.generationTool
        assert s.terminated() is not native
        s.set(g0=1e-3)
        _run(s, 600)
        assert s.get("status") == 0 and s.terminated() is not native
        assert math.isfinite(s.get("gap_min")) and s.get("gap_min") > -3e-3


NUMPY_ONLY_HOST = r'''
import importlib.abc, json, sys

class Block(importlib.abc.MetaPathFinder):
    """What a bare host lacks: any import of these fails, as if they were not installed."""
    BLOCKED = ("scipy", "numba", "llvmlite", "matplotlib", "rotorub_model", "tqdm", "dask")

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in self.BLOCKED:
            raise ModuleNotFoundError(f"No module named '{name}'", name=name.split(".")[0])
        return None

sys.meta_path.insert(0, Block())
from fmpy import simulate_fmu

out = {}
for mode in ("transient", "quasi_static"):
    r = simulate_fmu(sys.argv[1], stop_time=0.02, output_interval=1e-3,
                     start_values={"g0": 0.2e-3, "Omega": 176.2, "imbalance": 0.022, "mode": 1 + (mode != "transient")})
    out[mode] = [float(r["blade[1].F_N"][-1]), int(r["status"][-1]), len(r)]
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
unzip = extract(sys.argv[1])
md = read_model_description(unzip)
vr = {v.name: v.valueReference for v in md.modelVariables}
f = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="p")
f.instantiate()
f.setupExperiment(startTime=0.0)
f.enterInitializationMode()
f.setString([vr["param_file"]], [sys.argv[2]])
f.exitInitializationMode()
try:
    f.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
    refused = False
except Exception:
    refused = True
out["param_file"] = [f.getString([vr["message"]])[0].decode(), f.getInteger([vr["status"]])[0], refused]
f.terminate()
f.freeInstance()
print(json.dumps(out))
'''


def test_a_python_with_numpy_only_runs_the_fmu(contact_fmu, ref_model, tmp_path):
    """No scipy, numba, matplotlib, rotorub in the host: both modes run on the built-in model; a
    param_file, which needs scipy to assemble a model, is refused with a message that says so."""
    import json
    import subprocess
    import sys

    from rotorub_model.structure.params import REFERENCE_FILE

    script = tmp_path / "host.py"
    script.write_text(NUMPY_ONLY_HOST)
    r = subprocess.run([sys.executable, str(script), contact_fmu, str(REFERENCE_FILE)], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert out["transient"][1] == 0 and out["transient"][2] == 21
    assert out["quasi_static"][1] in (0, 3) and out["quasi_static"][0] > 0  # 3D, 0.2 mm: blade 1 touches (3: unstable)
    msg, status, refused = out["param_file"]
    assert refused and status == 2 and "needs scipy" in msg and "pip install scipy" in msg, msg


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_every_speed_band_of_the_validity_range_steps(fmu, unzipped, formulation):
    """The internal step comes from an eigen-solve per whole rad/s band: every band from 0 to the validity
    limit (640.8 rad/s) gives a step (the native FMU once refused 71 rad/s: its eigen-solver stopped at the
    classic hqr's 30 sweeps), with the contacts closed (an interference fit) as the limit assumes."""
    with Slave(fmu, unzip_dir=unzipped, g0=-0.1e-3, Omega=0.0, imbalance=0.0, formulation=formulation) as s:
        for w in range(0, 641):
            s.set(Omega=float(w))
            s.step(None, 1e-4)
            assert s.get("status") == 0 and s.get("dt_internal") > 0.0


DANGLING_LOGGER = r'''
import gc, sys
import fmpy
from fmu_src.masters.fmi2 import simulate
fmu = sys.argv[1]
simulate(fmu, stop_time=0.01, output_interval=1e-3)
gc.collect()
# fmpy's default callbacks log through its native proxy: it must not point at a freed thunk of ours
r = fmpy.simulate_fmu(fmu, start_values={"g0": 0.2e-3, "Omega": 176.2, "imbalance": 0.022, "max_penetration": 0.2e-3},
                      stop_time=5.0, output_interval=1e-3, output=["gap_min", "status"])
print("ended at", r["time"][-1])
'''


def test_simulate_leaves_no_dangling_logger_in_fmpy(native_fmu, tmp_path):
    """fmpy.simulate_fmu(logger=f) leaves fmpy's process-wide log proxy pointing at f's ctypes thunk, freed
    when the run ends; the next FMU logging through fmpy's default callbacks (the native FMU logs every
    refusal) then jumped into freed memory: a segfault of the whole suite, found by a helper with gdb and
    valgrind. fmu_src.masters.fmi2.simulate drives an instance with callbacks of its own instead. In a
    subprocess: the failure is a crash."""
    import subprocess
    import sys

    script = tmp_path / "dangling.py"
    script.write_text(DANGLING_LOGGER)
    r = subprocess.run([sys.executable, str(script), str(native_fmu)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "ended at" in r.stdout, (r.returncode, r.stderr[-2000:])


# ------------------------------------------------------------------ the second normal law, the casing out of round
def test_the_bilinear_law_through_the_fmu_equals_the_library(fmu, ref_model):
    """law = bilinear as an FMU parameter (issue 24.5): the same run as the library with the same law, to round-off,
    and different from the penalty law's (the stiffer layer beyond the knee carries the blades)."""
    p = ref_model.params
    omega, g0, me, t_end = 3.3 * p.normalisation.omega_ref, -0.4e-3, p.imbalance.me, 0.3
    law = {"law": "bilinear", "knee": 0.2e-3, "stiffness_ratio": 3.0}
    r = simulate(fmu, stop_time=t_end, output_interval=1e-3,
                 start_values={"g0": g0, "formulation": "3D", "Omega": omega, "imbalance": me, **law}, output=FN)
    from rotorub_model.structure.model import build_model

    bil = build_model(p.replace(contact=law))
    lib = run_transient(bil, make_contact(bil, "3D", g0=g0), omega, t_end=t_end, t_ramp=0.0, me=me, record_dt=1e-3,
                        hold=1e-3)
    pen = run_transient(ref_model, make_contact(ref_model, "3D", g0=g0), omega, t_end=t_end, t_ramp=0.0, me=me,
                        record_dt=1e-3, hold=1e-3)
    F = np.array([r[n] for n in FN]).T[1:]
    scale = np.abs(lib.outputs["F_N"]).max()
    assert np.abs(F - lib.outputs["F_N"]).max() <= 1e-9 * scale
    assert np.abs(lib.outputs["F_N"] - pen.outputs["F_N"]).max() > 0.1 * scale


def test_an_oval_casing_through_the_fmu_equals_the_library(fmu, ref_model):
    """casing_lobe2.amplitude/phase as inputs (issue 27.1), set half-way through a run: the library's run with the same
    distortion set between two runs (its final state carried over), to round-off; and the lobe shows in the forces
    (blades opposite each other see the same gap: the force pattern has a 2-per-revolution part)."""
    from rotorub_model.contact.liner import Liner

    p = ref_model.params
    omega, g0, me, t1, t_end = 3.3 * p.normalisation.omega_ref, 0.2e-3, p.imbalance.me, 0.2, 0.5
    a, psi = 0.3e-3, 0.4
    sig = np.array([(0.0, omega, me, 0.0), (t1 - 1e-9, omega, me, 0.0), (t1, omega, me, a), (t_end + 1, omega, me, a)],
                   dtype=[("time", float), ("Omega", float), ("imbalance", float), ("casing_lobe2.amplitude", float)])
    r = simulate(fmu, stop_time=t_end, output_interval=1e-3, input=sig,
                 start_values={"g0": g0, "formulation": "3D", "casing_lobe2.phase": psi}, output=FN + ["gap_min"])
    c = make_contact(ref_model, "3D", g0=g0)
    casing = Liner(c, wears=False)
    first = run_transient(ref_model, c, omega, t_end=t1, t_ramp=0.0, me=me, record_dt=1e-3, hold=1e-3, liner=casing)
    casing.set_distortion({2: (a, psi)})
    second = run_transient(ref_model, c, omega, t_end=t_end - t1, t_ramp=0.0, me=me, record_dt=1e-3, hold=1e-3,
                           liner=casing, start=first.final_state)
    lib = np.vstack([first.outputs["F_N"], second.outputs["F_N"]])
    F = np.array([r[n] for n in FN]).T[1:]
    assert F.shape == lib.shape and np.abs(lib).max() > 50.0
    assert np.abs(F - lib).max() <= 1e-9 * np.abs(lib).max()
    assert np.abs(second.outputs["F_N"][-100:] - lib[:100].mean(0)).max() > 1.0, "the lobe changes the rub"
