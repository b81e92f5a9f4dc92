"""Compiling a native FMU's staged sources for every platform: which compiler, which baseline, in
parallel, from a cache, and saying what it is doing.

* Linux binaries (linux64, aarch64-linux) are built with ziglang for glibc 2.17, the manylinux2014
  baseline: they load on RHEL 7/8/9, SLES 12/15, Ubuntu 16.04 and later, whatever machine built them.
  Without ziglang the system compiler builds this machine's platform only, for its own glibc (a
  warning says so).
* win64, darwin64 and aarch64-darwin are cross-compiled with ziglang.
* Each binary is cached under the user cache (``fmu-binaries/<key>``), the key a hash of the
  compiler, target, flags and every staged file: a rebuild of unchanged sources is a copy.
* Platforms compile in parallel (one process per core) and a line is printed when each starts and
  ends, plus one every 8 s while any is running: a first build with ziglang also compiles the
  target's C library (about 15 s for Linux, a minute for Windows), which otherwise looks like a hang.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path


class NativeBuildError(Exception):
    pass


@dataclass(frozen=True)
class Platform:
    folder: str  # FMI 2.0 binaries/ folder (the name every command takes)
    suffix: str
    zig_target: str
    machine: str  # what binaries.exported_symbols reports
    fmi3_folder: str  # FMI 3.0 binaries/ folder (the standard's platform tuple)


PLATFORMS = {p.folder: p for p in (
    Platform("linux64", ".so", "x86_64-linux-gnu.2.17", "x86_64", "x86_64-linux"),
    Platform("aarch64-linux", ".so", "aarch64-linux-gnu.2.17", "aarch64", "aarch64-linux"),
    Platform("win64", ".dll", "x86_64-windows-gnu", "x86_64", "x86_64-windows"),
    Platform("darwin64", ".dylib", "x86_64-macos", "x86_64", "x86_64-darwin"),
    Platform("aarch64-darwin", ".dylib", "aarch64-macos", "aarch64", "aarch64-darwin"),
)}
ALL_PLATFORMS = tuple(PLATFORMS)
GLIBC_BASELINE = (2, 17)
HEARTBEAT_S = 8.0  # below the 10 s a user waits without a word


def host_platform() -> str:
    from rotorub_model.kernel.compiler import host_platform_tag

    return {"x86_64-linux": "linux64", "x86_64-win": "win64", "x86_64-darwin": "darwin64",
            "aarch64-darwin": "aarch64-darwin", "aarch64-linux": "aarch64-linux"}[host_platform_tag()]


def say(msg: str) -> None:
    """One whole line on stderr (the parallel compilations' threads never run into each other's lines)."""
    from rotorub_model.progress import say as line

    line(msg, "build-fmu")


@contextmanager
def progress(what: str, label: str, how: str = ""):
    """Say when a compilation starts and ends, and every HEARTBEAT_S seconds while it runs (a first ziglang
    build of a target also compiles that target's C library, which otherwise looks like a hang)."""
    t0 = time.perf_counter()
    stop = threading.Event()

    def beat() -> None:
        while not stop.wait(HEARTBEAT_S):
            say(f"{what}: {label}: still compiling ({time.perf_counter() - t0:.0f} s; a first ziglang build of a "
                "target also compiles its C library, about a minute for Windows)")

    say(f"{what}: {label}: compiling{' ' + how if how else ''}")
    thread = threading.Thread(target=beat, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
    say(f"{what}: {label}: done in {time.perf_counter() - t0:.1f} s")


def _compiler_identity(command: tuple[str, ...], kind: str) -> str:
    if kind == "zig":
        from importlib.metadata import version

        return f"ziglang {version('ziglang')}"
    r = subprocess.run([*command, "--version"], capture_output=True, text=True)
    return " ".join(command) + " " + (r.stdout.splitlines() or [""])[0]


def _cache_dir() -> Path:
    from rotorub_model import kernel

    return kernel.cache_dir() / "fmu-binaries"


def compile_platforms(sources: Path, c_files: tuple[str, ...], identifier: str, dest: Path,
                      platforms: tuple[str, ...] | None, what: str = "native FMU", fmi: str = "2.0") -> list[str]:
    """Compile ``sources/c_files`` into ``dest/<platform folder>/<identifier><suffix>`` for each platform;
    returns the platforms built (by their FMI 2.0 names). ``platforms=None``: every platform when ziglang
    is installed, else this machine's only. ``fmi``: whose folder names ("2.0": linux64; "3.0": x86_64-linux)."""
    from rotorub_model.kernel.compiler import CFLAGS, Compiler, find_compiler, zig_command

    zig = zig_command()
    host = host_platform()
    if platforms is None:
        platforms = (host, *(p for p in ALL_PLATFORMS if p != host)) if zig else (host,)
    unknown = [p for p in platforms if p not in PLATFORMS]
    if unknown:
        raise NativeBuildError(f"platform '{unknown[0]}': unknown; accepted: {', '.join(PLATFORMS)}")
    jobs = []
    for plat in platforms:
        if zig:
            compiler = Compiler(tuple(zig), "zig")
            triple = ["-target", PLATFORMS[plat].zig_target]
        elif plat == host:
            compiler, triple = find_compiler(), []
            if plat.endswith("linux"):
                say(f"warning: ziglang is not installed: {plat} is built with {compiler.name} for this machine's "
                    f"glibc, not the {'.'.join(map(str, GLIBC_BASELINE))} baseline (pip install ziglang)")
        else:
            raise NativeBuildError(f"building for {plat} needs the ziglang package (pip install ziglang)")
        win = plat == "win64"
        flags = [*triple, *CFLAGS, "-shared", "-DRR_API=", *([] if win else ["-fPIC"])]
        libs = [] if win else ["-lm"]
        key = hashlib.sha256("\0".join([_compiler_identity(compiler.command, compiler.kind), *flags, *libs,
                                        identifier]).encode())
        for f in sorted(sources.iterdir()):
            if f.is_file():
                key.update(f.name.encode() + b"\0" + f.read_bytes())
        jobs.append((plat, compiler, flags, libs, key.hexdigest()[:32]))

    def one(job) -> str:
        plat, compiler, flags, libs, key = job
        name = f"{identifier}{PLATFORMS[plat].suffix}"
        out = dest / (PLATFORMS[plat].fmi3_folder if fmi == "3.0" else plat) / name
        out.parent.mkdir(parents=True, exist_ok=True)
        cached = _cache_dir() / key / name
        if cached.exists():
            shutil.copy2(cached, out)
            say(f"{what}: {plat}: from the cache ({cached.parent.name[:12]})")
            return plat
        how = f"with {compiler.name}" + (f" for {PLATFORMS[plat].zig_target}" if compiler.kind == "zig" else "")
        with progress(what, plat, how), tempfile.TemporaryDirectory(prefix="rotorub_cc_") as work:
            # in a folder of its own: a Windows build also leaves an import library and debug data behind
            target = Path(work) / name
            cmd = [*compiler.command, *flags, f"-I{sources}", "-o", str(target), *(str(sources / s) for s in c_files),
                   *libs]
            r = subprocess.run(cmd, capture_output=True, text=True, cwd=work)
            if r.returncode != 0 or not target.exists():
                raise NativeBuildError(f"{what} for {plat}: {compiler.name} failed:\n{r.stderr.strip()[-4000:]}")
            cached.parent.mkdir(parents=True, exist_ok=True)
            tmp = cached.with_suffix(cached.suffix + f".{os.getpid()}.{threading.get_ident()}.tmp")
            shutil.copy2(target, tmp)
            os.replace(tmp, cached)  # another build may be writing the same key: whole files only
            shutil.copy2(target, out)
        return plat

    with ThreadPoolExecutor(max_workers=max(1, min(len(jobs), os.cpu_count() or 1))) as pool:
        return list(pool.map(one, jobs))
