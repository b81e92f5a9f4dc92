"""Processes that used an FMU exit cleanly (benchmarks/bench_exit.py, a small N here; 200 + 200 in the README).

The cause of the aborts seen before (pythonfmu 0.7.0's linux64 binary writes into a block it freed, at
process exit) is removed at build time by patching one instruction (fmu_src/fmi/pythonfmu.py); the first test
checks the patch is in the built FMU, the others run fresh processes of both kinds for both flavours.
"""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytest.importorskip("fmpy")

ROOT = Path(__file__).resolve().parents[2]


def test_the_pythonfmu_binary_is_patched(contact_fmu):
    from fmu_src.fmi.pythonfmu import ON_UNLOAD_BYTES as _ON_UNLOAD_BYTES
    from fmu_src.fmi.pythonfmu import ON_UNLOAD_OFFSET as _ON_UNLOAD_OFFSET

    with zipfile.ZipFile(contact_fmu) as z:
        so = z.read("binaries/linux64/RotorCasingContact.so")
    o = _ON_UNLOAD_OFFSET
    assert so[o:o + 4] == _ON_UNLOAD_BYTES[:4] and so[o + 4] == 0xC3, "onLibraryUnload must return at once"


@pytest.mark.parametrize("flavour", ["pythonfmu", "native"])
def test_fresh_processes_exit_cleanly(flavour, request):
    fmu = request.getfixturevalue("contact_fmu" if flavour == "pythonfmu" else "native_fmu")
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "bench_exit.py"), "--fmu", str(fmu), "--n", "6",
                        "--steps", "100", "--sim-steps", "100"], capture_output=True, text=True, timeout=600)
    assert "simulate: 0/6 abnormal exits" in r.stdout and "slaves: 0/6 abnormal exits" in r.stdout, \
        r.stdout + r.stderr
    assert r.returncode == 0
