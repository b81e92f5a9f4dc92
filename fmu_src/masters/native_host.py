"""The C hosts (fmu_src/masters/hosts/): compiled for a platform, run where it can run, their CSV read back.

A host compiled for another platform runs here under an emulator when one is installed: ``qemu-aarch64``
(Debian's qemu-user, with the aarch64 C library of libc6-arm64-cross in /usr/aarch64-linux-gnu) for
aarch64-linux, ``wine`` for win64. That is how the native FMU's aarch64 and Windows binaries are run here
and compared with the linux64 one (tests/fmu/test_binaries.py, benchmarks/cross_platform.py).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

HOST_DIR = Path(__file__).resolve().parent / "hosts"
AARCH64_SYSROOT = Path("/usr/aarch64-linux-gnu")


def compile_host(out: str | Path, platform: str | None = None, source: str = "fmu_host.c") -> Path:
    """Compile a host (fmu_host.c or engine_host.c) into ``out``: with the system compiler for this machine
    (``platform=None``), with ziglang for an FMI platform folder (linux64, aarch64-linux, win64)."""
    from rotorub_model.kernel.compiler import ZIG_TARGETS, find_compiler, zig_command

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if platform is None:
        cc = list(find_compiler().command)
    else:
        zig = zig_command()
        if zig is None:
            raise RuntimeError(f"compiling a host for {platform} needs ziglang (pip install ziglang)")
        cc = [*zig, "-target", ZIG_TARGETS[platform]]
    win = platform == "win64"
    cmd = [*cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(out), str(HOST_DIR / source),
           *([] if win else ["-ldl"])]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=out.parent)
    if r.returncode != 0:
        raise RuntimeError(f"compiling {source} for {platform or 'this machine'} failed:\n{r.stderr[-3000:]}")
    for junk in out.parent.glob(out.stem + ".pdb"):  # a Windows build's debug data
        junk.unlink()
    return out


def cached_host(source: str = "fmu_host.c") -> Path:
    """This machine's build of a host, compiled once into the user cache (named by a hash of its sources)."""
    import hashlib

    from rotorub_model import kernel

    h = hashlib.sha256()
    for f in (HOST_DIR / source, HOST_DIR / "fmi2_host.h"):
        h.update(f.read_bytes())
    exe = kernel.cache_dir() / "hosts" / f"{Path(source).stem}-{h.hexdigest()[:16]}"
    if not exe.exists():
        tmp = compile_host(exe.with_name(exe.name + f".{os.getpid()}.tmp"), None, source)
        os.replace(tmp, exe)
    return exe


def runner(platform: str) -> tuple[list[str] | None, str]:
    """(command prefix that runs a binary of ``platform`` here, or None; why not)."""
    import platform as _p

    here = {"x86_64": "linux64", "aarch64": "aarch64-linux"}.get(_p.machine(), "")
    if platform == here:
        return [], ""
    if platform == "aarch64-linux":
        qemu = shutil.which("qemu-aarch64") or shutil.which("qemu-aarch64-static")
        if qemu is None:
            return None, "qemu-aarch64 is not installed (Debian: apt install qemu-user libc6-arm64-cross)"
        if not (AARCH64_SYSROOT / "lib" / "ld-linux-aarch64.so.1").exists():
            return None, f"no aarch64 C library in {AARCH64_SYSROOT} (Debian: apt install libc6-arm64-cross)"
        return [qemu, "-L", str(AARCH64_SYSROOT)], ""
    if platform == "win64":
        wine = shutil.which("wine") or shutil.which("wine64")
        if wine is None:
            return None, "wine is not installed (Debian: apt install wine64)"
        return [wine], ""
    return None, f"no way to run {platform} binaries on this machine"


def run(exe: Path, platform: str, args: list[str], timeout: float = 600) -> subprocess.CompletedProcess:
    """Run a host binary of ``platform`` (through its emulator) with ``args``; the environment has no Python."""
    prefix, why = runner(platform)
    if prefix is None:
        raise RuntimeError(why)
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp"), "WINEDEBUG": "-all"}
    if platform == "win64":
        env["WINEPREFIX"] = os.environ.get("WINEPREFIX", str(Path(env["HOME"]) / ".wine-rotorub"))
    return subprocess.run([*prefix, str(exe), *args], capture_output=True, text=True, timeout=timeout, env=env)


def read_csv(text: str) -> tuple[list[str], np.ndarray]:
    """(header, rows) of a host's CSV (Windows line ends accepted; an unreadable value is NaN)."""
    lines = [ln.rstrip("\r") for ln in text.strip().splitlines()]
    header = lines[0].split(",") if lines else []
    rows = np.array([[float(x) if x else np.nan for x in ln.split(",")] for ln in lines[1:]])
    return header, rows
