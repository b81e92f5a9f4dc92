"""CasingLoad.fmu (fmu_src/models/casing_load/): the fan case's distortion during a manoeuvre against the closed form of
its schedule, in FMI 2.0 and FMI 3.0 built from the same model.c; its kit; its ranges against the contact FMU's
inputs; its FMU state; a refused parameter."""

from __future__ import annotations

import math

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="the casing-load FMU is built with fmpy's headers and run with fmpy")

from fmpy.validation import validate_fmu  # noqa: E402

from fmu_src.masters import crosscheck as runs  # noqa: E402
from fmu_src.masters.fmi2 import FMUError, Slave  # noqa: E402
from fmu_src.models.casing_load import crosscheck as kit  # noqa: E402
from fmu_src.models.casing_load import variables as lv  # noqa: E402
from fmu_src.models.casing_load.builder import CasingLoadError, build_casing_load_fmu  # noqa: E402

OUTPUTS = kit.OUTPUTS


@pytest.fixture(scope="module")
def fmu2(tmp_path_factory):
    return build_casing_load_fmu(tmp_path_factory.mktemp("casing_load2"), platforms=("linux64",))


@pytest.fixture(scope="module")
def fmu3(tmp_path_factory):
    return build_casing_load_fmu(tmp_path_factory.mktemp("casing_load3"), platforms=("linux64",), fmi="3.0")


def test_both_fmi_versions_validate(fmu2, fmu3):
    assert validate_fmu(str(fmu2)) == []
    assert validate_fmu(str(fmu3)) == []


@pytest.mark.parametrize("version", ["2.0", "3.0"])
def test_the_fmu_reproduces_its_kit_to_round_off(version, fmu2, fmu3, tmp_path):
    """The default pull-up (2.5 g, 0.5 s up, 2 s held, 0.5 s down) at 1 ms steps: every output the closed form of
    the schedule to a few ulps (a wrong edge, a hold one step long or short, a sign would be 1e-3 to 1)."""
    kit.write_kit(tmp_path)
    run = runs.run_fmpy(fmu2, tmp_path) if version == "2.0" else runs.run_fmi3(fmu3, tmp_path)
    diff = runs.compare(run, tmp_path)
    assert set(diff) == set(OUTPUTS)
    assert max(diff.values()) <= 2e-15, diff
    ref = kit.reference()
    assert ref["load_factor"].max() == lv.DEFAULTS["load_factor_peak"] and ref["load_factor"][0] == 1.0
    assert np.ptp(ref["casing_lobe2.amplitude"]) == pytest.approx(1.5 * lv.DEFAULTS["ovalization_per_g"])


def test_the_kit_has_no_input_and_the_readme_says_so(tmp_path):
    files = kit.write_kit(tmp_path)
    assert files["in"].read_text().splitlines()[0] == "time"
    assert files["ref"].read_text().splitlines()[0] == ",".join(("time", *OUTPUTS))
    assert "no input" in files["readme"].read_text()


def test_a_push_over_with_a_step_at_uneven_steps(fmu2, fmu3):
    """Another manoeuvre at uneven communication steps, in both versions: a push-over to -1 g whose rise is a step,
    the offset 30 degrees off the vertical. The outputs are the closed form at the steps' sum, FMI 3.0 bit for bit
    FMI 2.0's; the ovalization and the offset reverse with n - 1 (a linear carcass)."""
    from fmu_src.masters.fmi3 import OK, Slave3, fmi3_available

    p = {"load_factor_peak": -1.0, "t_start": 0.3, "t_rise": 0.0, "t_hold": 0.45, "t_fall": 0.6,
         "ovalization_per_g": 2e-4, "ovalization_phase": 0.3, "offset_per_g": 1e-4, "offset_angle": math.radians(120)}
    steps = [0.013, 0.25, 0.04, 0.1, 0.007, 0.3, 0.2, 0.09, 0.5]
    times = np.array([math.fsum(steps[:k + 1]) for k in range(len(steps))])  # the exact sums, rounded once
    ref = kit.closed_form(times, **p)
    seen = []
    with Slave(fmu2, **p) as s:
        assert s.get("load_factor") == 1.0 and s.get("casing_lobe2.amplitude") == 0.0  # at t = 0: level flight
        t = 0.0
        for k, h in enumerate(steps):
            s.step(t, h)
            t += h
            got = {v: s.get(v) for v in OUTPUTS}
            seen.append(got)
            for v in OUTPUTS:  # to a few ulps of the column's largest value
                assert abs(got[v] - ref[v][k]) <= 1e-15 * np.abs(ref[v]).max(), (k, v, got[v], ref[v][k])
    assert min(r["load_factor"] for r in seen) == -1.0  # the step reached the peak, the fall left it
    assert seen[1]["load_factor"] == 1.0 and seen[2]["casing_lobe2.amplitude"] == pytest.approx(-2.0 * 2e-4, rel=1e-15)
    assert seen[2]["casing_offset.y"] == pytest.approx(-2.0 * 1e-4 * math.sin(math.radians(120)), rel=1e-15)
    if fmi3_available():
        pytest.skip(fmi3_available())
    with Slave3(fmu3) as s3:
        assert s3.init(**p) == OK
        for k, h in enumerate(steps):
            assert s3.step(h)[0] == OK
            for v in OUTPUTS:
                assert s3.get(v) == seen[k][v], (k, v)


def test_level_flight_distorts_nothing(fmu2):
    """load_factor_peak = 1 (the manoeuvre scenario's reference): the schedule runs, the casing stays round."""
    with Slave(fmu2, load_factor_peak=1.0) as s:
        for k in range(40):
            s.step(k * 0.1, 0.1)
            assert s.get("load_factor") == 1.0
            assert s.get("casing_lobe2.amplitude") == 0.0 and s.get("casing_offset.y") == 0.0
        assert s.get("schedule") == 0.0 and s.get("casing_lobe2.phase") == lv.DEFAULTS["ovalization_phase"]


def test_every_output_stays_inside_the_contact_fmus_inputs():
    """At the extremes of its declared ranges (|n - 1| <= 9, 1 mm per g) the ovalization and each offset component
    stay inside the contact FMU's declared input ranges, and the phase range is the contact's: a master connecting
    the two never meets a refused set."""
    from fmu_src.models.contact import variables as contact

    lo, hi = lv.LOAD_FACTOR_RANGE
    dn = max(abs(lo - 1.0), abs(hi - 1.0))
    assert dn * max(map(abs, lv.PER_G_RANGE)) <= contact.LOBE_AMPLITUDE_RANGE[1]
    assert -dn * max(map(abs, lv.PER_G_RANGE)) >= contact.LOBE_AMPLITUDE_RANGE[0]
    assert dn * lv.OFFSET_PER_G_RANGE[1] <= min(-contact.OFFSET_RANGE[0], contact.OFFSET_RANGE[1])
    assert lv.ANGLE_RANGE == contact.LOBE_PHASE_RANGE


def test_a_rolled_back_step_gives_the_same_outputs(fmu2):
    """FMU state: the time (and its compensation) is the whole state; a step redone from a saved state repeats."""
    with Slave(fmu2) as s:
        for k in range(1200):
            s.step(k * 1e-3, 1e-3)
        state = s.fmu.getFMUstate()
        s.step(1.2, 0.05)
        first = [s.get(v) for v in OUTPUTS]
        s.fmu.setFMUstate(state)
        s.step(1.2, 0.05)
        assert [s.get(v) for v in OUTPUTS] == first
        s.fmu.freeFMUstate(state)


def test_a_parameter_out_of_range_is_refused_in_one_line(fmu2, tmp_path):
    with pytest.raises(CasingLoadError, match=r"^casing load FMU: ovalization_per_g = 0.01 out of range; accepted "
                                              r"range \[-0.001, 0.001\]$"):
        build_casing_load_fmu(tmp_path, platforms=("linux64",), ovalization_per_g=0.01)
    with pytest.raises(CasingLoadError, match="unknown parameter 'amplitude'"):
        build_casing_load_fmu(tmp_path, platforms=("linux64",), amplitude=1e-4)
    assert not list(tmp_path.iterdir())  # nothing half-written
    with pytest.raises(FMUError):  # the wrapper refuses it too, before any step
        Slave(fmu2, load_factor_peak=20.0)
