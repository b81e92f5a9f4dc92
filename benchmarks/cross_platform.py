"""The native FMU's binaries for other platforms, run here, against the linux64 one: are the numbers the same?

    .venv/bin/python benchmarks/cross_platform.py [--steps N]

Builds RotorCasingContact.fmu for linux64, aarch64-linux and win64 (ziglang), builds the C host
(fmu_src/masters/hosts/fmu_host.c) for each platform, and runs the same scenario in each: a 3D rub at the
section-6 speed from rest with the reference imbalance, every blade's normal and friction force, the casing
force, the friction torque, the disk displacement, the smallest gap, the blades in contact, N steps of 1 ms.
aarch64-linux runs under qemu-aarch64 (Debian: apt install qemu-user libc6-arm64-cross), win64 under wine
(Debian: apt install wine64); a platform whose emulator is missing is reported as not run.

With ``--chroot DIR`` (root; repeatable) the linux64 binaries also run inside an older Linux's root file system,
with its own C library: the C host built for glibc 2.17 as the FMU is, both copied into DIR and run there with
nothing of this machine's. A Debian 11 root (glibc 2.31: Ubuntu 20.04's, newer than RHEL 8's 2.28) comes from
Debian's own tool: ``apt install debootstrap; debootstrap --variant=minbase bullseye DIR
http://deb.debian.org/debian``.

Prints, per platform, the number of values that differ from linux64, the first step where one does, and the
largest difference relative to each column's largest value. Before the kernel had its own elementary
functions (rotorub_model/kernel/rr_math.h) the win64 DLL differed in 40 % of the values (first at step 21 by
1 ulp, at most 4.4e-12 of a column's maximum); the README quotes what this script prints today.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from fmu_src.masters import native_host  # noqa: E402
from fmu_src.models.contact.builder import build_native_fmu  # noqa: E402

PLATFORMS = ("linux64", "aarch64-linux", "win64")


def scenario_args(md_vr: dict[str, int], steps: int) -> list[str]:
    args = ["-n", str(steps), "-s", "0.001", "-I", f"{md_vr['formulation']}=2", "-p", f"{md_vr['g0']}=0.0002",
            "-u", f"{md_vr['Omega']}=176.22", "-u", f"{md_vr['imbalance']}=0.022"]
    reals = [n for n in md_vr if n.startswith("blade[") and n.rsplit(".", 1)[1] in ("F_N", "F_T", "gap_tip")]
    reals += ["casing_force.x", "casing_force.y", "friction_torque", "disk_displacement.x", "disk_displacement.y",
              "gap_min"]
    for n in reals:
        args += ["-o", str(md_vr[n])]
    return args + ["-i", str(md_vr["n_contact"]), "-i", str(md_vr["status"])]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=5000)
    ap.add_argument("--chroot", action="append", default=[], help="an older Linux's root file system to run the "
                    "linux64 binaries in as well (root needed)")
    ns = ap.parse_args(argv)
    from fmpy import read_model_description

    with tempfile.TemporaryDirectory(prefix="rotorub_xp_") as tmp:
        tmp = Path(tmp)
        fmu = build_native_fmu(tmp / "fmu", platforms=PLATFORMS)["fmu"]
        unz = tmp / "unzipped"
        with zipfile.ZipFile(fmu) as z:
            z.extractall(unz)
        md_vr = {v.name: v.valueReference for v in read_model_description(str(unz)).modelVariables}
        args = ["-d", str(unz), *scenario_args(md_vr, ns.steps)]
        rows, seconds = {}, {}
        for plat in PLATFORMS:
            prefix, why = native_host.runner(plat)
            if prefix is None:
                print(f"{plat:14s} not run: {why}")
                continue
            exe = native_host.compile_host(tmp / plat / ("fmu_host.exe" if plat == "win64" else "fmu_host"),
                                           None if plat == "linux64" else plat)
            t0 = time.perf_counter()
            r = native_host.run(exe, plat, args, timeout=3600)
            seconds[plat] = time.perf_counter() - t0
            if r.returncode != 0:
                print(f"{plat:14s} failed (exit {r.returncode}): {r.stderr.strip()[-500:]}")
                continue
            header, data = native_host.read_csv(r.stdout)
            outs = [k for k, h in enumerate(header) if h[:1] in "ri"]  # the outputs (not time, status, inputs)
            rows[plat] = data[:, outs]
        for root in ns.chroot:
            label, data = _run_in_chroot(Path(root), unz, tmp, scenario_args(md_vr, ns.steps))
            if data is not None:
                rows[label], seconds[label] = data
    ref = rows.get("linux64")
    if ref is None:
        print("linux64 could not be run here: nothing to compare with")
        return 1
    values = ref
    print(f"scenario: 3D rub, {ns.steps} steps of 1 ms, {values.shape[1]} outputs per step "
          f"({values.size} values); max |F_N| {np.abs(values).max():.4g}")
    worst = 0
    for plat in [*PLATFORMS[1:], *[k for k in rows if k not in PLATFORMS]]:
        if plat not in rows:
            continue
        got = rows[plat]
        if got.shape != values.shape:
            print(f"{plat:14s} {got.shape[0]} rows instead of {values.shape[0]}")
            worst = 1
            continue
        diff = got != values
        n = int(diff.sum())
        scale = np.maximum(np.abs(values).max(axis=0), 1e-300)
        rel = float((np.abs(got - values) / scale).max())
        first = int(np.argmax(diff.any(axis=1))) if n else None
        print(f"{plat:14s} {n} of {values.size} values differ ({100 * n / values.size:.2g} %)"
              + (f", first at step {first}, largest {rel:.3g} of a column's maximum" if n else ": bit for bit")
              + f"  [{seconds[plat]:.1f} s{' under its emulator' if plat in PLATFORMS else ''}]")
        worst = max(worst, int(n > 0))
    return worst


def _run_in_chroot(root: Path, unzipped: Path, tmp: Path, scenario: list[str]):
    """(label, (outputs, seconds)) of the scenario run inside ``root`` by the C host built for glibc 2.17."""
    label = f"linux64 in {root}"
    if not (root / "usr" / "bin" / "env").exists():
        print(f"{label}: not run: not a root file system (no usr/bin/env)")
        return label, None
    libc = subprocess.run(["chroot", str(root), "/usr/bin/env", "-i", "ldd", "--version"], capture_output=True,
                          text=True)
    label += f" ({libc.stdout.splitlines()[0].split()[-1]})" if libc.returncode == 0 and libc.stdout else ""
    place = root / "rotorub_xp"
    shutil.rmtree(place, ignore_errors=True)
    native_host.compile_host(place / "fmu_host", "linux64")  # ziglang, glibc 2.17: what the FMU is built for
    shutil.copytree(unzipped, place / "fmu")
    t0 = time.perf_counter()
    r = subprocess.run(["chroot", str(root), "/usr/bin/env", "-i", "/rotorub_xp/fmu_host", "-d", "/rotorub_xp/fmu",
                        *scenario], capture_output=True, text=True, timeout=3600)
    seconds = time.perf_counter() - t0
    shutil.rmtree(place, ignore_errors=True)
    if r.returncode != 0:
        print(f"{label}: failed (exit {r.returncode}): {r.stderr.strip()[-500:]}")
        return label, None
    header, data = native_host.read_csv(r.stdout)
    return label, (data[:, [k for k, h in enumerate(header) if h[:1] in "ri"]], seconds)


if __name__ == "__main__":
    sys.exit(main())
