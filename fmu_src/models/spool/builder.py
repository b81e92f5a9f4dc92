"""The LP spool FMU in both flavours and the contact FMU for the engine system.

* :func:`build_native_spool_fmu`: ``LPSpool.fmu`` in C (fmu_src/native/spool_model.c behind the same FMI
  wrapper and build route as the native contact FMU): no Python on the host; the engine system's spool.
* :func:`build_spool_fmu`: the same FMU written in Python with pythonfmu (fmu_src/pythonfmu/spool_slave.py),
  the example of a slave in Python. The script is staged under a hashed module name, ``lpspool_<hash>``,
  because every pythonfmu FMU in a process shares one ``sys.modules``, with the interface next to it.

Both have fmu_src/engine/spool_interface.py's variables, value references, ranges and start values, and
the same numbers to round-off (the native schedule's cosine is rr_math.h's, the slave's Python's).
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
import tempfile
from pathlib import Path

from . import spool_interface as si
from .system import SPOOL_ID, EngineError, build_small_native_fmu, specs_variables

HERE = Path(__file__).resolve().parent.parent  # fmu_src/
SPOOL_SCRIPT = HERE / "pythonfmu" / "spool_slave.py"
INTERFACE = Path(si.__file__)
# the value references spool_model.c reads (its enum), checked against the interface at build
C_ORDER = ("friction_torque", "J", "c_w", "Omega0", "Omega1", "t_ramp_start", "t_ramp", "dt_max", "Omega",
           "Omega_schedule", "drive_torque", "windage_torque")


def spool_defaults() -> dict:
    """The spool FMU's default parameter values (spool_interface.DEFAULTS)."""
    return dict(si.DEFAULTS)


def _values(defaults: dict) -> dict:
    values = spool_defaults()
    unknown = sorted(set(defaults) - set(values))
    if unknown:
        raise EngineError(f"spool FMU: unknown parameter(s) {', '.join(unknown)}; known: {', '.join(values)}")
    for k, v in defaults.items():
        v = float(v)
        lo, hi = next(s[5] for s in si.SPECS if s[0] == k)
        if not (math.isfinite(v) and lo <= v <= hi):
            raise EngineError(f"spool FMU: {k} = {v!r} out of range; accepted range [{lo!r}, {hi!r}]")
        values[k] = v
    return values


def spool_variables(values: dict | None = None):
    """spool_interface.SPECS as interface.Var (what the native build writes; value reference = position)."""
    return specs_variables(si.SPECS, values or spool_defaults())


def build_native_spool_fmu(dest: str | Path = "fmus/native", platforms: tuple[str, ...] | None = None,
                           **defaults) -> Path:
    """Build ``dest/LPSpool.fmu`` in C; keyword arguments override the parameters' start values."""
    facts = ("J dOmega/dt = tau_drive(t) - c_w Omega<sup>2</sup> + friction_torque, RK4 in ceil(h/dt_max) substeps "
             "with the input held; the drive schedule makes the rub-free spool follow the half-cosine run-up "
             "Omega0 &rarr; Omega1 exactly. A step at whose end the spool would stop is refused (fmi2Discard, "
             "status 1) and ends the run (fmi2Terminated).")
    # the initial speed is Omega0's whatever torque the spool is given: no loop at initialisation
    return build_small_native_fmu(dest, SPOOL_ID, "spool_model.c", spool_variables(_values(defaults)), C_ORDER, si,
                                  facts, platforms, initial_from_parameters=True)


def build_spool_fmu(dest: str | Path = "fmus", **defaults) -> Path:
    """Build ``dest/LPSpool.fmu`` with pythonfmu; keyword arguments override the parameters' start values
    (J, c_w, Omega0, Omega1, t_ramp_start, t_ramp, dt_max). Needs pythonfmu."""
    try:
        from pythonfmu import FmuBuilder
        from pythonfmu import __version__ as pythonfmu_version
    except ImportError:
        raise EngineError("pythonfmu is not installed: pip install 'rotorub[fmu]'") from None
    from ..interface import guid_of

    values = _values(defaults)
    script_bytes, interface_bytes = SPOOL_SCRIPT.read_bytes(), INTERFACE.read_bytes()
    tag = hashlib.sha256(script_bytes + interface_bytes + pythonfmu_version.encode()).hexdigest()[:10]
    module_name, interface_name = f"lpspool_{tag}", f"lpspool_interface_{tag}"
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
        (stage / f"{interface_name}.py").write_bytes(interface_bytes)
        manifest = stage / "lpspool_defaults.json"
        manifest.write_text(json.dumps({"interface": interface_name, "defaults": values,
                                        "guid": guid_of("pythonfmu", tag, json.dumps(values, sort_keys=True))},
                                       indent=1))
        doc = Path(tmp) / "documentation"
        doc.mkdir()
        rows = "\n".join(f"<tr><td><code>{k}</code></td><td>{v!r}</td></tr>" for k, v in values.items())
        (doc / "index.html").write_text(
            "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>LPSpool</title></head><body>\n"
            "<h1>LPSpool &mdash; low-pressure spool speed (FMI 2.0 co-simulation, pythonfmu)</h1>\n"
            f"<p>{si.DESCRIPTION}</p>\n<p>The same model as the native LPSpool.fmu (which the engine system "
            "uses); this one is the example of a slave written in Python. Needs a CPython 3.10+ host "
            f"(pythonfmu); no other package.</p>\n<h2>Parameter start values</h2><table border=\"1\">\n{rows}\n"
            "</table></body></html>\n")
        try:
            FmuBuilder.build_FMU(script, dest=out_file, project_files=[manifest, stage / f"{interface_name}.py"],
                                 documentation_folder=doc, canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        finally:
            for m in set(sys.modules) - before:
                if m.split(".")[0] in (module_name, interface_name):
                    sys.modules.pop(m, None)
            sys.path[:] = path_before
    return out_file


def build_contact_fmu(dest: str | Path = "fmus") -> Path:
    """``RotorCasingContact.fmu`` from fmu_src/build/pythonfmu_fmu.py (reference parameters)."""
    from ..build.pythonfmu_fmu import build_fmu

    return Path(build_fmu(dest)["fmu"])
