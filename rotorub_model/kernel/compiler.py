"""Finding a C compiler and building the kernel (and the native FMU) with it.

Order of preference (the first that works):

1. ``$ROTORUB_CC`` (a command line, e.g. ``"clang -march=native"`` is *not* advised: the
   build must stay portable and FMA-free);
2. ``$CC``, then ``cc``, ``gcc``, ``clang`` on the PATH (the system compiler);
3. the ``ziglang`` package (``python -m ziglang cc``): a complete clang-based C compiler
   and cross-compiler installed from PyPI, so a machine with only Python can build the
   kernel, and any machine can build Windows and macOS binaries of the native FMU.

Flags: C99, -O3 (2.5x faster than -O2 on the mat-vecs here), position independent, no
contraction to FMA and no fast-math (the kernel must give the same numbers on every
platform, see rotorub_kernel.h).
"""

from __future__ import annotations

import os
import platform
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..errors import RotorubError

CFLAGS = ["-std=c99", "-O3", "-ffp-contract=off", "-fno-fast-math", "-fvisibility=hidden", "-Wall"]

# FMI 2.0 platform folder -> zig target triple (cross builds of the native FMU)
ZIG_TARGETS = {
    "linux64": "x86_64-linux-gnu.2.17",
    "win64": "x86_64-windows-gnu",
    "darwin64": "x86_64-macos",
    "aarch64-darwin": "aarch64-macos",
    "aarch64-linux": "aarch64-linux-gnu.2.17",
}
SHARED_SUFFIX = {"linux": ".so", "win": ".dll", "darwin": ".dylib"}


class CompilerError(RotorubError):
    """No C compiler could be found, or the build failed; the message says what to install."""


NO_COMPILER = (
    "no C compiler found to build the rotorub kernel. Install one of: the ziglang package "
    "(`pip install ziglang`, a C compiler from PyPI, works everywhere), or a system compiler "
    "(Debian/Ubuntu: `apt install gcc`; Fedora: `dnf install gcc`; macOS: `xcode-select --install`; "
    "Windows: LLVM clang or MinGW-w64), or set ROTORUB_CC to a compiler command"
)


@dataclass(frozen=True)
class Compiler:
    command: tuple[str, ...]
    kind: str  # "system" or "zig"

    @property
    def name(self) -> str:
        return " ".join(self.command)


def _works(cmd: list[str]) -> bool:
    with tempfile.TemporaryDirectory(prefix="rotorub_cc_") as tmp:
        src = Path(tmp) / "probe.c"
        src.write_text("#include <math.h>\ndouble rr_probe(double x) { return sqrt(x); }\n")
        out = Path(tmp) / ("probe" + host_suffix())
        try:
            r = subprocess.run([*cmd, "-shared", "-fPIC", "-o", str(out), str(src), "-lm"], capture_output=True,
                               timeout=600)
        except (OSError, subprocess.TimeoutExpired):
            return False
        return r.returncode == 0 and out.exists()


def zig_command() -> list[str] | None:
    """``python -m ziglang cc`` if the ziglang package is importable."""
    try:
        import ziglang  # noqa: F401
    except ImportError:
        return None
    return [sys.executable, "-m", "ziglang", "cc"]


def find_compiler(allow_system: bool = True) -> Compiler:
    """The first working compiler of the preference order; raises CompilerError if none."""
    candidates: list[tuple[list[str], str]] = []
    for var in ("ROTORUB_CC", "CC"):
        if os.environ.get(var):
            candidates.append((shlex.split(os.environ[var]), "system"))
    if allow_system:
        for name in ("cc", "gcc", "clang"):
            path = shutil.which(name)
            if path:
                candidates.append(([path], "system"))
    zig = zig_command()
    if zig:
        candidates.append((zig, "zig"))
    seen = set()
    for cmd, kind in candidates:
        key = tuple(cmd)
        if key in seen:
            continue
        seen.add(key)
        if _works(cmd):
            return Compiler(key, "zig" if cmd == zig else kind)
    raise CompilerError(NO_COMPILER)


def host_os() -> str:
    return "win" if sys.platform.startswith("win") else "darwin" if sys.platform == "darwin" else "linux"


def host_suffix() -> str:
    return SHARED_SUFFIX[host_os()]


def host_platform_tag() -> str:
    """``<machine>-<os>`` of this interpreter, e.g. x86_64-linux (names a cached binary)."""
    machine = platform.machine().lower()
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(machine, machine)
    return f"{machine}-{host_os()}"


def compile_shared(sources: list[Path], out: Path, compiler: Compiler | None = None, target: str | None = None,
                   defines: dict[str, str] | None = None, include: list[Path] | None = None) -> Path:
    """Compile ``sources`` into the shared library ``out`` (atomically: a reader never sees a half file).

    ``target``: an FMI platform folder of :data:`ZIG_TARGETS` for a cross build (needs ziglang).
    """
    if target is not None:
        zig = zig_command()
        if zig is None:
            raise CompilerError(f"building for {target} needs the ziglang package (`pip install ziglang`)")
        compiler = Compiler(tuple(zig), "zig")
        triple = ["-target", ZIG_TARGETS[target]]
    else:
        compiler = compiler or find_compiler()
        triple = []
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    defs = [f"-D{k}={v}" for k, v in (defines or {}).items()]
    incs = [f"-I{p}" for p in (include or [])]
    win = (target or host_os()).startswith("win")
    with tempfile.TemporaryDirectory(prefix="rotorub_cc_", dir=out.parent) as work:
        # in a folder of its own (a Windows build also leaves an import library and debug data behind),
        # then moved in place atomically: a reader never sees a half-written library
        tmp = Path(work) / out.name
        cmd = [*compiler.command, *triple, *CFLAGS, "-shared", *([] if win else ["-fPIC"]), "-DRR_BUILD_SHARED",
               *defs, *incs, "-o", str(tmp), *map(str, sources), *([] if win else ["-lm"])]
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=work)
        if r.returncode != 0 or not tmp.exists():
            raise CompilerError(f"compiling {', '.join(p.name for p in sources)} with {compiler.name} failed "
                                f"(exit {r.returncode}):\n{r.stderr.strip()[-4000:]}")
        os.replace(tmp, out)
    return out
