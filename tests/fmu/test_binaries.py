"""The native FMU as a product: its binaries for every platform, its sources, what its binary links.

* every platform's binary (linux64, aarch64-linux, win64, darwin64 and aarch64-darwin, all built with ziglang)
  exports each FMI 2.0 co-simulation function, for the right architecture, and nothing of the kernel;
* the Linux binaries need nothing newer than glibc 2.17 (the manylinux2014 baseline: RHEL 7 and later) and no
  libm, read from their ELF version needs;
* the aarch64-linux binary (under qemu-aarch64) and the win64 one (under wine) compute the linux64 numbers bit
  for bit, where those emulators are installed;
* deleting the binaries and rebuilding from ``sources/`` with a standard route (fmpy's
  ``build_platform_binary``, CMake underneath; and the CMakeLists.txt the FMU carries) gives an FMU that
  loads in a process with nothing but the C runtime and computes the same numbers, bit for bit.
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

from fmu_src.fmi.binaries import elf_version_needs, exported_symbols, missing_fmi_functions, newest_glibc  # noqa: E402
from fmu_src.masters import native_host  # noqa: E402
from fmu_src.masters.fmi2 import Slave  # noqa: E402

ARCH = {"linux64": "x86_64", "aarch64-linux": "aarch64", "win64": "x86_64", "darwin64": "x86_64",
        "aarch64-darwin": "aarch64"}
FN = [f"blade[{j}].F_N" for j in range(1, 11)] + ["friction_torque", "disk_displacement.x"]


@pytest.fixture(scope="module")
def all_platforms(tmp_path_factory):
    pytest.importorskip("ziglang", reason="cross-compiling the FMU needs ziglang (a dependency of rotorub)")
    from fmu_src.models.contact.builder import build_native_fmu

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

    from rotorub_model import kernel

    md = read_model_description(str(all_platforms))
    files = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    kernel_c = [p.name for p in kernel.SOURCES]  # however many files the kernel is split into
    assert sorted(files) == sorted(["model.c", "fmi2_cs.c", "fmu_core.c", "model_data.c", *kernel_c])
    for f in [*files, "fmu_model.h", "fmu_core.h", "model.h", "variables.h", *(p.name for p in kernel.HEADERS),
              "fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h", "CMakeLists.txt"]:
        assert (all_platforms / "sources" / f).is_file(), f


@pytest.mark.parametrize("platform", ["linux64", "aarch64-linux"])
def test_linux_binaries_load_on_glibc_2_17_and_need_no_libm(all_platforms, platform):
    binary = all_platforms / "binaries" / platform / "RotorCasingContact.so"
    needs = elf_version_needs(binary)
    assert set(needs) == {"libc.so.6"}, needs  # no libm (rr_math.h), no libpython
    assert newest_glibc(binary) <= (2, 17), needs


# 3D rub at the section-6 speed from rest with the reference imbalance: F_N of every blade, friction torque,
# casing force, disk displacement, smallest gap; n_contact and status (value references of variables.py)
HOST_ARGS = ["-n", "2000", "-s", "0.001", "-I", "2=2", "-p", "5=0.0002", "-u", "0=176.2", "-u", "1=0.022",
             *[a for j in range(10) for a in ("-o", str(13 + 6 * j))], "-o", "74", "-o", "75", "-o", "77", "-o", "78",
             "-o", "80", "-i", "73", "-i", "82"]


@pytest.fixture(scope="module")
def linux64_rows(all_platforms, tmp_path_factory):
    host = native_host.compile_host(tmp_path_factory.mktemp("host_here") / "fmu_host")
    r = native_host.run(host, "linux64", ["-d", str(all_platforms), *HOST_ARGS])
    assert r.returncode == 0, r.stderr[-2000:]
    header, rows = native_host.read_csv(r.stdout)
    assert rows.shape == (2001, len(header)) and rows[:, 2:12].max() > 50.0  # it rubs
    return rows


@pytest.mark.parametrize("platform", ["aarch64-linux", "win64"])
def test_aarch64_and_win64_binaries_compute_the_linux64_numbers(all_platforms, linux64_rows, tmp_path, platform):
    """The kernel's arithmetic is IEEE 754 in a fixed order and its elementary functions its own (rr_math.h):
    the aarch64 build (qemu-aarch64) and the Windows build (wine), each driven by the C host built for that
    platform, give the linux64 outputs bit for bit (before rr_math.h the win64 DLL differed in 40 % of them)."""
    prefix, why = native_host.runner(platform)
    if prefix is None:
        pytest.skip(why)
    host = native_host.compile_host(tmp_path / ("fmu_host.exe" if platform == "win64" else "fmu_host"), platform)
    r = native_host.run(host, platform, ["-d", str(all_platforms), *HOST_ARGS])
    assert r.returncode == 0, r.stderr[-2000:]
    _, rows = native_host.read_csv(r.stdout)
    assert rows.shape == linux64_rows.shape
    assert np.array_equal(rows, linux64_rows)


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
    so = rebuilt / "binaries" / "linux64" / "RotorCasingContact.so"
    assert so.exists()
    assert set(elf_version_needs(so)) == {"libc.so.6"}  # fmpy's recipe links no libm: none is needed
    a, b = _scenario(orig), _scenario(rebuilt)
    assert a[:, :10].max() > 10.0
    assert np.array_equal(a, b)
    # and in a process that has nothing but the C runtime (a Python process has libm loaded already, which
    # hid the 'undefined symbol: sincos' of the binaries before rr_math.h)
    host = native_host.compile_host(tmp_path / "fmu_host")
    runs = [native_host.run(host, "linux64", ["-d", str(d), *HOST_ARGS[:-4]]) for d in (orig, rebuilt)]
    assert all(r.returncode == 0 for r in runs), runs[1].stderr[-2000:]
    assert runs[0].stdout == runs[1].stdout


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
    assert "python" not in ldd
    ref = tmp_path / "ref"
    with zipfile.ZipFile(native_fmu) as z:
        z.extractall(ref)
    assert np.array_equal(_scenario(d), _scenario(ref))
