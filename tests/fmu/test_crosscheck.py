"""The FMI cross-check kit next to each FMU (fmu_src/build/crosscheck.py): both flavours run it in two masters
(fmpy and OSP libcosim) and reproduce its reference outputs."""

from __future__ import annotations

import pytest

pytest.importorskip("fmpy")

from fmu_src.build import crosscheck as cc  # noqa: E402


@pytest.fixture(scope="module")
def kit(tmp_path_factory):
    d = tmp_path_factory.mktemp("kit")
    files = cc.write_kit(d)
    assert {p.name for p in files.values()} == {"RotorCasingContact_in.csv", "RotorCasingContact_ref.csv",
                                               "RotorCasingContact_ref.opt", "ReadMe.txt"}
    return d


def test_the_kit_is_a_run_up_with_rub(kit):
    ref = cc.read_csv(kit / "RotorCasingContact_ref.csv")
    inp = cc.read_csv(kit / "RotorCasingContact_in.csv")
    assert inp["Omega"][0] < 3.49 * 53.4 < inp["Omega"][-1]  # through the first critical speed
    assert ref["n_contact"].max() >= 2 and max(ref[f"blade[{j}].F_N"].max() for j in range(1, 11)) > 100.0
    assert ref["friction_torque"].min() < 0.0
    opt = dict(line.split(",") for line in (kit / "RotorCasingContact_ref.opt").read_text().splitlines())
    assert float(opt["StopTime"]) == pytest.approx(inp["time"][-1]) and float(opt["StepSize"]) == pytest.approx(1e-3)


@pytest.mark.parametrize("master", ["fmpy", "libcosim"])
def test_both_flavours_reproduce_the_kit(kit, any_fmu, master):
    if master == "libcosim":
        pytest.importorskip("libcosimpy", reason="libcosimpy: Linux x86_64, Python >= 3.11")
    run = cc.run_fmpy if master == "fmpy" else cc.run_libcosim
    diff = cc.compare(run(any_fmu, kit), kit)
    assert max(diff.values()) <= 1e-9, diff
