"""The LP spool FMU (fmu_src/pythonfmu/spool_slave.py, built with pythonfmu) and the contact FMU for the engine system.

The spool: J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque, with a drive torque
schedule that makes the rub-free spool follow a half-cosine run-up Omega0 -> Omega1 exactly
(see the slave's docstring). The script is staged under a hashed module name, ``lpspool_<hash>``,
because every pythonfmu FMU in a process shares one ``sys.modules``.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import tempfile
from pathlib import Path

from .system import SPOOL_ID, EngineError

HERE = Path(__file__).resolve().parent.parent  # fmu_src/
SPOOL_SCRIPT = HERE / "pythonfmu" / "spool_slave.py"


def spool_defaults() -> dict:
    """The spool FMU's default parameter values (module defaults of fmu_src/pythonfmu/spool_slave.py)."""
    from ..pythonfmu import spool_slave

    return dict(spool_slave.DEFAULTS)


def build_spool_fmu(dest: str | Path = "fmus", **defaults) -> Path:
    """Build ``dest/LPSpool.fmu``; keyword arguments override the parameters' start values
    (J, c_w, Omega0, Omega1, t_ramp_start, t_ramp, dt_max). Needs pythonfmu."""
    try:
        from pythonfmu import FmuBuilder
        from pythonfmu import __version__ as pythonfmu_version
    except ImportError:
        raise EngineError("pythonfmu is not installed: pip install 'rotorub[fmu]'") from None
    values = spool_defaults()
    unknown = sorted(set(defaults) - set(values))
    if unknown:
        raise EngineError(f"build_spool_fmu: unknown parameter(s) {', '.join(unknown)}; known: {', '.join(values)}")
    for k, v in defaults.items():
        v = float(v)
        if not math.isfinite(v):
            raise EngineError(f"build_spool_fmu: {k} = {v!r} is not finite")
        values[k] = v
    script_bytes = SPOOL_SCRIPT.read_bytes()
    tag = hashlib.sha256(script_bytes + pythonfmu_version.encode()).hexdigest()[:10]
    module_name = f"lpspool_{tag}"
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    out_file = dest / f"{SPOOL_ID}.fmu"
    before = set(sys.modules)
    path_before = list(sys.path)
    with tempfile.TemporaryDirectory(prefix="rotorub_spool_") as tmp:
        stage = Path(tmp) / "stage"
        stage.mkdir()
        script = stage / f"{module_name}.py"
        script.write_bytes(script_bytes)
        defaults_file = stage / "lpspool_defaults.json"
        defaults_file.write_text(json.dumps(values, indent=1))
        doc = Path(tmp) / "documentation"
        doc.mkdir()
        rows = "\n".join(f"<tr><td><code>{k}</code></td><td>{v!r}</td></tr>" for k, v in values.items())
        (doc / "index.html").write_text(
            "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>LPSpool</title></head><body>\n"
            "<h1>LPSpool &mdash; low-pressure spool speed (FMI 2.0 co-simulation, pythonfmu)</h1>\n"
            "<p>J dOmega/dt = tau_drive(t) - c_w Omega<sup>2</sup> + friction_torque. The drive torque schedule "
            "tau_drive = J dOmega_s/dt + c_w Omega_s<sup>2</sup> makes the spool follow the half-cosine speed "
            "schedule Omega_s(t) (Omega0 until t_ramp_start, Omega1 after t_ramp_start + t_ramp) exactly when no "
            "external torque acts. Integration: RK4 on e = Omega - Omega_s with ceil(h/dt_max) substeps per "
            "communication step, friction_torque held (zero-order hold). Rollback: fmi2Get/SetFMUstate and "
            "serialization. Bad parameters or inputs: fmi2DoStep returns fmi2Discard after a log message naming "
            "the variable (log with loggingOn = true).</p>\n<p>Needs a CPython 3.10+ host (pythonfmu); no other "
            f"package.</p>\n<h2>Parameter start values</h2><table border=\"1\">\n{rows}\n</table></body></html>\n")
        try:
            FmuBuilder.build_FMU(script, dest=out_file, project_files=[defaults_file], documentation_folder=doc,
                                 canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        finally:
            for m in set(sys.modules) - before:
                if m.split(".")[0] == module_name:
                    sys.modules.pop(m, None)
            sys.path[:] = path_before
    return out_file


def build_contact_fmu(dest: str | Path = "fmus") -> Path:
    """``RotorCasingContact.fmu`` from fmu_src/build/pythonfmu_fmu.py (reference parameters)."""
    from ..build.pythonfmu_fmu import build_fmu

    return Path(build_fmu(dest)["fmu"])


