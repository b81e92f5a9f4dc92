"""The FMI cross-check kit next to each FMU (fmu_src/models/contact/crosscheck.py, the files
fmu_src/fmi/crosscheck.py): it holds every input of the FMU, and both flavours run it in two masters (fmpy and OSP
libcosim: fmu_src/masters/crosscheck.py) and reproduce its reference outputs."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("fmpy")

from fmu_src.fmi.crosscheck import read_csv  # noqa: E402
from fmu_src.masters import crosscheck as runs  # noqa: E402
from fmu_src.models.contact import crosscheck as cc  # noqa: E402


@pytest.fixture(scope="module")
def kit(tmp_path_factory):
    d = tmp_path_factory.mktemp("kit")
    files = cc.write_kit(d)
    assert {p.name for p in files.values()} == {"RotorCasingContact_in.csv", "RotorCasingContact_ref.csv",
                                               "RotorCasingContact_ref.opt", "ReadMe.txt"}
    return d


def test_the_kit_is_a_run_up_with_rub(kit):
    ref = read_csv(kit / "RotorCasingContact_ref.csv")
    inp = read_csv(kit / "RotorCasingContact_in.csv")
    assert inp["Omega"][0] < 3.49 * 53.4 < inp["Omega"][-1]  # through the first critical speed
    # the ovalization half-way changes the rub: the blades' forces differ from a run with a round casing
    assert np.ptp(ref["gap_min"][inp["time"] > cc.RUN["oval_at"]]) > 0
    assert ref["n_contact"].max() >= 2 and max(ref[f"blade[{j}].F_N"].max() for j in range(1, 11)) > 100.0
    assert ref["friction_torque"].min() < 0.0
    opt = dict(line.split(",") for line in (kit / "RotorCasingContact_ref.opt").read_text().splitlines())
    assert float(opt["StopTime"]) == pytest.approx(inp["time"][-1]) and float(opt["StepSize"]) == pytest.approx(1e-3)


def test_the_kit_holds_every_input_of_the_fmu(kit, native_fmu, capfd):
    """Issue 24.7: the kit's _in.csv had 2 of the 5 inputs, and fmpy warned of the three missing with the kit. Every
    input of the FMU is a column now, every one moving (issue 33.4; lobe 2 steps to the oval half-way), and fmpy's
    simulate_fmu takes the file without a warning."""
    from fmpy import read_model_description, simulate_fmu

    inputs = {v.name for v in read_model_description(native_fmu).modelVariables if v.causality == "input"}
    inp = read_csv(kit / "RotorCasingContact_in.csv")
    lobes = {f"casing_lobe{n}.{q}" for n in (2, 3, 4) for q in ("amplitude", "phase")}
    assert set(inp) - {"time"} == inputs == {"Omega", "imbalance", "clearance_closure", "casing_offset.x",
                                             "casing_offset.y", *lobes}
    # issue 33.4: every input moves (six of nine stayed at 0, so a host that mis-wired them passed), each first
    # at its own time: two inputs swapped give another run
    first_change = {c: int(np.flatnonzero(np.diff(inp[c]) != 0)[0]) for c in inputs if c != "Omega"}
    assert len(set(first_change.values())) == len(first_change), first_change
    assert np.ptp(inp["Omega"]) > 0
    oval = inp["casing_lobe2.amplitude"]
    assert oval[0] == 0 and oval[-1] == cc.RUN["oval"] > 0
    rows = np.genfromtxt(kit / "RotorCasingContact_in.csv", delimiter=",", names=True, deletechars="")[:50]
    capfd.readouterr()
    r = simulate_fmu(native_fmu, stop_time=0.049, output_interval=1e-3, input=rows, output=["friction_torque"])
    assert len(r) == 50 and "missing input" not in capfd.readouterr().out  # fmpy prints it for a missing column


@pytest.mark.parametrize("master", ["fmpy", "libcosim"])
def test_both_flavours_reproduce_the_kit(kit, any_fmu, master):
    if master == "libcosim":
        pytest.importorskip("libcosimpy", reason="libcosimpy: Linux x86_64, Python >= 3.11")
    run = runs.run_fmpy if master == "fmpy" else runs.run_libcosim
    diff = runs.compare(run(any_fmu, kit), kit)
    assert max(diff.values()) <= 1e-9, diff


@pytest.mark.parametrize("model", ["spool native", "spool pythonfmu", "clearance native"])
def test_the_engine_fmus_reproduce_their_kits(model, tmp_path):
    """Every model folder has its kit (crosscheck.py): the spool's run-up with a braking torque against scipy's
    DOP853, the clearance closure against the closed form of its thermal lag; run through fmpy as any master would,
    every input from _in.csv."""
    name, flavour = model.split()
    if flavour == "pythonfmu":
        pytest.importorskip("pythonfmu")
    if name == "spool":
        from fmu_src.models.spool import crosscheck as kit_of
        from fmu_src.models.spool.builder import build_native_spool_fmu, build_spool_fmu

        fmu = build_spool_fmu(tmp_path) if flavour == "pythonfmu" else build_native_spool_fmu(
            tmp_path, platforms=("linux64",))
    else:
        from fmu_src.models.clearance import crosscheck as kit_of
        from fmu_src.models.clearance.builder import build_clearance_fmu

        fmu = build_clearance_fmu(tmp_path, platforms=("linux64",))
    kit_of.write_kit(tmp_path)
    diff = runs.compare(runs.run_fmpy(fmu, tmp_path), tmp_path)
    assert max(diff.values()) <= 1e-9, diff
    ref = read_csv(next(tmp_path.glob("*_ref.csv")))
    assert np.ptp(ref[kit_of.OUTPUTS[0]]) > 0.0  # it moves
