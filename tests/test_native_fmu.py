"""The native FMU as a product: its binaries for every platform, its sources, what its binary links.

* every platform's binary (linux64 built and run here; win64, darwin64 and aarch64-darwin cross-compiled
  with ziglang) exports each FMI 2.0 co-simulation function, for the right architecture, and nothing of
  the kernel;
* deleting the binaries and rebuilding from ``sources/`` with a standard route (fmpy's
  ``build_platform_binary``, CMake underneath; and the CMakeLists.txt the FMU carries) gives an FMU that
  computes the same numbers, bit for bit.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("fmpy")

from fmu_src.build.binaries import exported_symbols, missing_fmi_functions  # noqa: E402
from fmu_src.harness.fmi_run import Slave  # noqa: E402

ARCH = {"linux64": "x86_64", "win64": "x86_64", "darwin64": "x86_64", "aarch64-darwin": "aarch64"}
FN = [f"blade[{j}].F_N" for j in range(1, 11)] + ["friction_torque", "disk_displacement.x"]


@pytest.fixture(scope="module")
def all_platforms(tmp_path_factory):
    pytest.importorskip("ziglang", reason="cross-compiling the FMU needs ziglang (a dependency of rotorub)")
    from fmu_src.build.native_fmu import build_native_fmu

    out = build_native_fmu(tmp_path_factory.mktemp("native_all"))
    assert set(out["platforms"]) == set(ARCH), out
    d = tmp_path_factory.mktemp("native_all_unzipped")
    with zipfile.ZipFile(out["fmu"]) as z:
        z.extractall(d)
    return d


@pytest.mark.parametrize("platform", list(ARCH))
def test_each_platform_binary_exports_the_fmi_functions(all_platforms, platform):
    binary = next((all_platforms / "binaries" / platform).iterdir())
    assert len(list((all_platforms / "binaries" / platform).iterdir())) == 1  # no import library or debug data
    [(arch, names)] = exported_symbols(binary)
    assert arch == ARCH[platform]
    assert missing_fmi_functions(binary) == {arch: []}
    assert not [n for n in names if n.startswith("rr_")], "kernel functions must not leak out of the FMU"


def test_sources_are_listed_and_complete(all_platforms):
    from fmpy import read_model_description

    md = read_model_description(str(all_platforms))
    files = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    assert sorted(files) == ["contact_model.c", "fmi2_cs.c", "model_data.c", "rotorub_kernel.c"]
    for f in [*files, "fmu_model.h", "rotorub_kernel.h", "fmi2Functions.h", "fmi2FunctionTypes.h",
              "fmi2TypesPlatform.h", "CMakeLists.txt"]:
        assert (all_platforms / "sources" / f).is_file(), f


def _scenario(fmu_dir: Path) -> np.ndarray:
    with Slave(fmu_dir, g0=0.2e-3, Omega=176.2, imbalance=0.022, formulation="2D") as s:
        rows = []
        for _ in range(300):
            s.step(None, 1e-3)
            rows.append(s.get_reals(FN))
    return np.array(rows)


def test_rebuilt_from_sources_with_fmpy_gives_the_same_numbers(native_fmu, tmp_path, monkeypatch):
    from fmpy.build import build_platform_binary

    # fmpy's helper runs cmake: the cmake package (a dependency of fmpy) puts it next to this Python
    monkeypatch.setenv("PATH", str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
    if shutil.which("cmake") is None:
        pytest.skip("fmpy's helper needs cmake")
    orig, rebuilt = tmp_path / "orig", tmp_path / "rebuilt"
    for d in (orig, rebuilt):
        with zipfile.ZipFile(native_fmu) as z:
            z.extractall(d)
    shutil.rmtree(rebuilt / "binaries")
    (tmp_path / "build").mkdir()
    build_platform_binary(rebuilt, build_dir=tmp_path / "build")
    assert (rebuilt / "binaries" / "linux64" / "RotorCasingContact.so").exists()
    a, b = _scenario(orig), _scenario(rebuilt)
    assert a[:, :10].max() > 10.0
    assert np.array_equal(a, b)


def test_rebuilt_with_the_fmus_own_cmakelists(native_fmu, tmp_path):
    cmake = shutil.which("cmake") or str(Path(sys.executable).parent / "cmake")
    d = tmp_path / "fmu"
    with zipfile.ZipFile(native_fmu) as z:
        z.extractall(d)
    build = tmp_path / "build"
    for args in (["-S", str(d / "sources"), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"],
                 ["--build", str(build), "--config", "Release"]):
        r = subprocess.run([cmake, *args], capture_output=True, text=True)
        assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    shutil.copy2(build / "RotorCasingContact.so", d / "binaries" / "linux64" / "RotorCasingContact.so")
    ldd = subprocess.run(["ldd", str(d / "binaries" / "linux64" / "RotorCasingContact.so")], capture_output=True,
                         text=True).stdout
    assert "libm.so" in ldd and "python" not in ldd
    ref = tmp_path / "ref"
    with zipfile.ZipFile(native_fmu) as z:
        z.extractall(ref)
    assert np.array_equal(_scenario(d), _scenario(ref))
