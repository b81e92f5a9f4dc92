"""The README's main-job command from a fresh clone with cold caches, timed (issue 25.3: <= 3 min on 2 cores).

    python benchmarks/bench_main_job.py [--repo .] [--keep DIR] [--warm]

What it does: ``git clone`` of the repository's HEAD into a temporary folder, then the README's main-job command
(the first code block after "**Main job**", run as written by bash in the clone) with every cache it can empty
pointed at fresh empty folders:

* ``ROTORUB_CACHE_DIR`` (the compiled kernel, the FMU binaries, the C hosts) and ``XDG_CACHE_HOME`` (pip's cache and
  anything else that follows the XDG rule);
* zig's caches (``ZIG_GLOBAL_CACHE_DIR``, ``ZIG_LOCAL_CACHE_DIR``): a cold ziglang compiles each target's C library
  first, the largest single cost of a first FMU build;
* matplotlib's (``MPLCONFIGDIR``: its font list is built on first use).

Every line the command prints is time-stamped as it arrives; the script prints the wall time, the time to the end
of the install (the first line of ``rotorub``), the longest silence between two lines (the issue's 10 s rule), each
stage's time from the main job's own "done in" lines, and the load average before and after (a second worker only
helps where a core is free: on a busy machine the same run takes longer).

What it cannot make cold: the operating system's page cache (the Python installation, the wheels' files), the
local wheel source pip is given (``PIP_FIND_LINKS``: a machine that downloads its wheels adds the download), the
CPU's state. ``--warm`` runs the command a second time in the same clone (caches filled) for the warm figure.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path


def readme_command(readme: Path) -> str:
    """The main-job command of the README: the first fenced block after the '**Main job**' paragraph."""
    text = readme.read_text()
    tail = text.split("**Main job**", 1)[1]
    block = re.search(r"```\n(.*?)\n```", tail, re.S)
    if block is None:
        raise SystemExit("bench_main_job: no code block after '**Main job**' in the README")
    return block.group(1).strip()


def run_timed(command: str, cwd: Path, env: dict) -> tuple[float, list[tuple[float, str, str]], int]:
    """Run ``command`` with bash; every line of stdout and stderr time-stamped as it arrives (progress bars'
    carriage returns count as lines: they are what a user sees move)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(["bash", "-c", command], cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    lines: list[tuple[float, str, str]] = []
    lock = threading.Lock()

    def pump(stream, name: str) -> None:
        buf = b""
        while True:
            chunk = stream.read1(4096) if hasattr(stream, "read1") else stream.read(4096)
            if not chunk:
                break
            buf += chunk
            parts = re.split(rb"[\r\n]", buf)
            buf = parts.pop()
            now = time.perf_counter() - t0
            with lock:
                lines.extend((now, name, p.decode("utf-8", "replace")) for p in parts if p.strip())
        if buf.strip():
            with lock:
                lines.append((time.perf_counter() - t0, name, buf.decode("utf-8", "replace")))

    threads = [threading.Thread(target=pump, args=(proc.stdout, "out")),
               threading.Thread(target=pump, args=(proc.stderr, "err"))]
    for th in threads:
        th.start()
    code = proc.wait()
    for th in threads:
        th.join()
    return time.perf_counter() - t0, sorted(lines, key=lambda x: x[0]), code  # stable: each stream's order kept


def report(wall: float, lines: list[tuple[float, str, str]], code: int, label: str) -> None:
    print(f"\n== {label}: exit {code}, wall {wall:.1f} s ({wall / 60:.2f} min)")
    first = next((t for t, _, s in lines if s.startswith("[rotorub]") or s.startswith("[reproduce]")), None)
    if first is not None:
        print(f"   install (venv + pip) until rotorub's first line: {first:.1f} s; the main job itself: "
              f"{wall - first:.1f} s")
    stamps = [0.0, *(t for t, _, _ in lines), wall]
    gaps = sorted(((b - a, a) for a, b in zip(stamps, stamps[1:])), reverse=True)[:3]
    print("   longest silences: " + ", ".join(f"{g:.1f} s at {a:.0f} s" for g, a in gaps))
    if gaps:
        a = gaps[0][1]
        before = [s for t, _, s in lines if t <= a][-1:] or ["(start)"]
        print(f"   (the longest follows: {before[0][:110]!r})")
    print("   stages (their own 'done in'):")
    for _, _, s in lines:
        m = re.match(r"\[(rotorub|reproduce|build-fmu)\] (.*): done in ([0-9.]+) s", s)
        if m and (m.group(1) != "build-fmu" or float(m.group(3)) > 2):
            print(f"     {float(m.group(3)):6.1f} s  {m.group(2)[:100]}")
    tail = [s for _, n, s in lines if n == "out"][-12:]
    print("   last lines on stdout:\n     " + "\n     ".join(tail))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repo", default=str(Path(__file__).resolve().parents[1]), help="repository to clone (HEAD)")
    ap.add_argument("--keep", default=None, help="clone into this folder and keep it (default: a temporary one)")
    ap.add_argument("--warm", action="store_true", help="then run the command again in the same clone, caches warm")
    ns = ap.parse_args(argv)
    root = Path(ns.keep) if ns.keep else Path(tempfile.mkdtemp(prefix="rotorub_bench_main_"))
    if ns.keep and root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    clone = root / "rotorub"
    subprocess.run(["git", "clone", "-q", ns.repo, str(clone)], check=True)
    command = readme_command(clone / "README.md")
    caches = {k: root / "caches" / k.lower() for k in ("ROTORUB_CACHE_DIR", "XDG_CACHE_HOME", "ZIG_GLOBAL_CACHE_DIR",
                                                          "ZIG_LOCAL_CACHE_DIR", "MPLCONFIGDIR")}
    for p in caches.values():
        p.mkdir(parents=True)
    env = {**os.environ, **{k: str(v) for k, v in caches.items()}}
    env.pop("VIRTUAL_ENV", None)
    print(f"bench_main_job: {clone} (HEAD {subprocess.run(['git', '-C', str(clone), 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True).stdout.strip()})")  # noqa: E501
    print(f"  command: {command}")
    print(f"  cold caches: {', '.join(caches)} -> empty folders under {root / 'caches'}")
    print(f"  load average before: {os.getloadavg()[0]:.2f}; cores: {os.cpu_count()}")
    wall, lines, code = run_timed(command, clone, env)
    report(wall, lines, code, "cold")
    print(f"  load average after: {os.getloadavg()[0]:.2f}")
    if ns.warm and code == 0:
        wall2, lines2, code2 = run_timed(command, clone, env)
        report(wall2, lines2, code2, "warm (the same clone and caches, again)")
    if not ns.keep:
        shutil.rmtree(root, ignore_errors=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
