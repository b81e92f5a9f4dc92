"""fmusim, the Modelica Association's reference FMI importer (Reference-FMUs v0.0.39), as a host of our FMUs.

Nobody here wrote fmusim: a run through it checks the FMUs as a system engineer's tool reads them (their model
description, their status semantics), not as our own masters do. It is built once from the sources in
``../shared/hosts/fmusim-0.0.39/`` (beside the repository; ``ROTORUB_HOSTS`` names another folder holding
``fmusim-0.0.39/``) with Debian's sundials, minizip, libxml2 and zlib, into the kernel's cache (``hosts/``, keyed
by the sources' hash); ``ROTORUB_FMUSIM`` names a ready executable instead.

:func:`run` gives fmusim what a user would: ``--start-value`` per parameter, an input CSV (fmusim interpolates a
continuous input linearly between rows and reads it at each communication point: the row's value there, to an
ulp), ``--output-interval`` the communication step; it reads fmusim's output CSV back (an FMI 3.0 array is one
column of space-separated values: ``name[k]`` is its element k). A pythonfmu FMU gets what docs/FMU-hosts.md says a
native host must give it (this Python's libpython preloaded, PYTHONHOME, PYTHONPATH).
"""

from __future__ import annotations

import csv
import hashlib
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fmi.crosscheck import write_csv

VERSION = "0.0.39"
_ELEMENT = re.compile(r"^(.*)\[(\d+)\]$")
PACKAGES = ("gcc", "libsundials-dev", "libminizip-dev", "libxml2-dev", "zlib1g-dev")


def sources() -> Path:
    """The folder of fmusim's sources (with its build.sh)."""
    root = os.environ.get("ROTORUB_HOSTS")
    base = Path(root) if root else Path(__file__).resolve().parents[3] / "shared" / "hosts"
    return base / f"fmusim-{VERSION}"


def _cache() -> Path:
    from rotorub_model.kernel import cache_dir  # the one cache of the project (ROTORUB_CACHE_DIR, XDG, ~/.cache)

    return cache_dir() / "hosts"


def available() -> str | None:
    """None when fmusim can be run here (built, or buildable); otherwise why not, in one line."""
    if os.environ.get("ROTORUB_FMUSIM"):
        return None if Path(os.environ["ROTORUB_FMUSIM"]).is_file() else \
            f"ROTORUB_FMUSIM={os.environ['ROTORUB_FMUSIM']} is not a file"
    src = sources()
    if not (src / "build.sh").is_file():
        return f"fmusim's sources not found at {src} (set ROTORUB_HOSTS to the folder holding fmusim-{VERSION}/)"
    if shutil.which("gcc") is None:
        return "no gcc to build fmusim (apt-get install " + " ".join(PACKAGES) + ")"
    headers = ("/usr/include/libxml2/libxml/parser.h", "/usr/include/minizip/unzip.h", "/usr/include/cvode/cvode.h")
    missing = [h for h in headers if not Path(h).exists()]
    if missing:
        return f"fmusim needs Debian's development packages (missing {', '.join(missing)}): apt-get install " + \
            " ".join(PACKAGES)
    return None


def executable() -> Path:
    """fmusim, built once (atomically: concurrent test processes may ask at the same time)."""
    if os.environ.get("ROTORUB_FMUSIM"):
        return Path(os.environ["ROTORUB_FMUSIM"])
    why = available()
    if why:
        raise RuntimeError(f"fmusim: {why}")
    src = sources()
    h = hashlib.sha256()
    for p in sorted(src.rglob("*")):
        if p.is_file():
            h.update(p.relative_to(src).as_posix().encode())
            h.update(p.read_bytes())
    dest = _cache() / f"fmusim-{VERSION}-{h.hexdigest()[:12]}" / "fmusim"
    if dest.is_file():
        return dest
    dest.parent.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=dest.parent.parent) as tmp:
        r = subprocess.run(["bash", str(src / "build.sh"), tmp], capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            raise RuntimeError(f"fmusim: build failed ({src / 'build.sh'}): {r.stderr.strip()[-600:]}")
        dest.parent.mkdir(exist_ok=True)
        os.replace(Path(tmp) / "fmusim", dest)  # a rename: a concurrent build replaces it with the same file
    return dest


@dataclass
class Run:
    """What fmusim did: its exit code, its log, and the outputs it wrote (``time`` and one array per name)."""

    exit_code: int
    log: str
    result: dict[str, np.ndarray]


def _value(text: str) -> float:
    t = text.strip().lower()
    return {"true": 1.0, "false": 0.0}[t] if t in ("true", "false") else float(t)


def read_output(path: Path, outputs: list[str] | None = None) -> dict[str, np.ndarray]:
    """fmusim's output CSV, with each array column split into its elements (``name[k]``, 1-based)."""
    with path.open(newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {"time": np.zeros(0)}
    head = rows[0]
    arrays = {m.group(1) for m in map(_ELEMENT.match, outputs or []) if m}
    cols: dict[str, list[float]] = {}
    for row in rows[1:]:
        for name, cell in zip(head, row):
            parts = cell.split()
            if name in arrays or len(parts) > 1:
                for k, x in enumerate(parts, start=1):
                    cols.setdefault(f"{name}[{k}]", []).append(_value(x))
            else:
                cols.setdefault(name, []).append(_value(parts[0]) if parts else np.nan)
    out = {k: np.asarray(v, dtype=float) for k, v in cols.items()}
    if outputs is not None:
        missing = [o for o in outputs if o not in out]
        if missing:
            raise KeyError(f"fmusim's output has no column(s) {', '.join(missing)}")
        out = {"time": out["time"], **{o: out[o] for o in outputs}}
    return out


def _environment(fmu: str | Path) -> dict[str, str] | None:
    """A pythonfmu FMU (needsExecutionTool) runs the host's CPython inside fmusim: this Python's libpython preloaded,
    its home and packages named (docs/FMU-hosts.md, "What a native host needs"); a native FMU: fmusim as it is."""
    import sys
    import sysconfig
    import zipfile

    with zipfile.ZipFile(fmu) as z:
        if b'needsExecutionTool="true"' not in z.read("modelDescription.xml"):
            return None
    lib = Path(sysconfig.get_config_var("LIBDIR") or "") / (sysconfig.get_config_var("LDLIBRARY") or "")
    packages = Path(np.__file__).resolve().parents[1]  # where this Python finds numpy (the FMU's slave needs it)
    return {**os.environ, "LD_PRELOAD": str(lib), "PYTHONHOME": sys.base_prefix, "PYTHONPATH": str(packages)}


def run(fmu: str | Path, start_values: dict[str, float | int | str], inputs: dict[str, np.ndarray] | None,
        outputs: list[str], step: float, stop: float, start: float = 0.0, *, state_in: Path | None = None,
        state_out: Path | None = None, early_return: bool = False, timeout: float = 600.0) -> Run:
    """Run ``fmu`` in fmusim (co-simulation) from ``start`` to ``stop`` with communication step ``step``;
    ``inputs``: a ``time`` column and one column per input variable (None: no input file); ``outputs``: the
    variables to record (``name[k]``: element k of an FMI 3.0 array, recorded as the whole array)."""
    exe = executable()
    recorded = list(dict.fromkeys((_ELEMENT.match(o).group(1) if _ELEMENT.match(o) else o) for o in outputs))
    with tempfile.TemporaryDirectory() as tmp:
        tmp_p = Path(tmp)
        out_csv = tmp_p / "out.csv"
        log = tmp_p / "log.txt"
        args = [str(exe), "--interface-type", "cs", "--start-time", repr(float(start)), "--stop-time",
                repr(float(stop)), "--output-interval", repr(float(step)), "--output-file", str(out_csv),
                "--log-file", str(log), "--logging-on", "--log-level", "warning"]
        for name, v in start_values.items():
            args += ["--start-value", name, v if isinstance(v, str) else repr(v) if isinstance(v, float) else str(v)]
        for name in recorded:
            args += ["--output-variable", name]
        if inputs is not None:
            in_csv = tmp_p / "in.csv"
            write_csv(in_csv, inputs)
            args += ["--input-file", str(in_csv)]
        if state_in is not None:
            args += ["--initial-fmu-state-file", str(state_in)]
        if state_out is not None:
            args += ["--final-fmu-state-file", str(state_out)]
        if early_return:
            args += ["--early-return-allowed"]
        args.append(str(fmu))
        try:
            r = subprocess.run(args, capture_output=True, text=True, timeout=timeout, env=_environment(fmu))
        except subprocess.TimeoutExpired:
            return Run(-9, f"fmusim did not end within {timeout:g} s (killed)", {"time": np.zeros(0)})
        text = (log.read_text(errors="replace") if log.exists() else "") + r.stdout + r.stderr
        result = read_output(out_csv, outputs) if out_csv.exists() and out_csv.stat().st_size else \
            {"time": np.zeros(0)}
        return Run(r.returncode, text, result)
