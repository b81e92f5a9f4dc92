"""Build LPSpool.fmu in both flavours, from the one variable list (variables.py):

* :func:`build_native_spool_fmu`: ``LPSpool.fmu`` in C (model.c behind the FMI layer's wrapper, the same build
  route as the native contact FMU): no Python on the host; the engine system's spool.
* :func:`build_spool_fmu`: the same FMU written in Python with pythonfmu (slave.py), the example of a slave in
  Python, staged under a hashed module name, ``lpspool_<hash>`` (fmu_src/fmi/pythonfmu.py says why).

Both have the same variables, value references, ranges, start values and model description (but its GUID and
tool), and the same numbers to round-off (the native schedule's cosine is rr_math.h's, the slave's Python's).
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

from ...fmi.description import model_description, xml_bytes
from ...fmi.package import NativeBuild, build_native, documentation_html, guid_of
from ...fmi.pythonfmu import build_pythonfmu, pythonfmu_version
from ...fmi.variables import as_plain, declared, scalars
from . import variables as sv

HERE = Path(__file__).resolve().parent  # fmu_src/models/spool/
SLAVE = HERE / "slave.py"
FACTS = ("J dOmega/dt = tau_drive(t) - c_w Omega<sup>2</sup> + friction_torque, RK4 in ceil(h/dt_max) substeps "
         "with the input held; the drive schedule makes the rub-free spool follow the half-cosine run-up "
         "Omega0 &rarr; Omega1 exactly. A step at whose end the spool would stop is refused (fmi2Discard, "
         "status 1) and ends the run (fmi2Terminated).")


class SpoolError(ValueError):
    """A spool FMU that cannot be built as asked (one line: the parameter and what is accepted)."""


def spool_defaults() -> dict:
    """The spool FMU's default parameter values (variables.DEFAULTS)."""
    return dict(sv.DEFAULTS)


def _values(defaults: dict) -> dict:
    values = spool_defaults()
    unknown = sorted(set(defaults) - set(values))
    if unknown:
        raise SpoolError(f"spool FMU: unknown parameter(s) {', '.join(unknown)}; known: {', '.join(values)}")
    ranges = {v.name: (v.min, v.max) for v in sv.variables() if v.min is not None}
    for k, v in defaults.items():
        v = float(v)
        lo, hi = ranges[k]
        if not (math.isfinite(v) and lo <= v <= hi):
            raise SpoolError(f"spool FMU: {k} = {v!r} out of range; accepted range [{lo!r}, {hi!r}]")
        values[k] = v
    return values


def build_native_spool_fmu(dest: str | Path = "fmus/native", platforms: tuple[str, ...] | None = None,
                           fmi: str = "2.0", **defaults) -> Path:
    """Build ``dest/LPSpool.fmu`` in C (FMI ``fmi``: the engine's systems use "2.0"; "3.0" from the same wrappers);
    keyword arguments override the parameters' start values."""
    from rotorub_model import __version__ as lib_version

    out = build_native(NativeBuild(model=sv.MODEL, variables=sv.variables(_values(defaults)), model_dir=HERE,
                                   fmi=fmi, facts=FACTS), dest, platforms, f"rotorub {lib_version}", lib_version)
    return Path(out["fmu"])


def build_spool_fmu(dest: str | Path = "fmus", **defaults) -> Path:
    """Build ``dest/LPSpool.fmu`` with pythonfmu; keyword arguments override the parameters' start values
    (J, c_w, Omega0, Omega1, t_ramp_start, t_ramp, dt_max). Needs pythonfmu."""
    version = pythonfmu_version()
    variables = sv.variables(_values(defaults))
    own = scalars(declared(variables, ("fmi2", "pythonfmu")))  # what the slave registers
    plain = [as_plain(v) for v in own]
    tag = hashlib.sha256(SLAVE.read_bytes() + json.dumps(plain).encode() + version.encode()).hexdigest()[:10]
    guid = guid_of("pythonfmu", tag)
    md = model_description(sv.MODEL, variables, fmi="2.0", token=guid, flavour="pythonfmu",
                           generation_tool=f"rotorub (PythonFMU {version})", version="1.0")
    doc = documentation_html(sv.MODEL_IDENTIFIER, "FMI 2.0 co-simulation (pythonfmu)", sv.DESCRIPTION, own,
                             "<p>The same model as the native LPSpool.fmu (which the engine system uses); this one "
                             "is the example of a slave written in Python. Needs a CPython 3.10+ host (pythonfmu); "
                             "no other package.</p>")
    out_file = Path(dest) / f"{sv.MODEL_IDENTIFIER}.fmu"
    manifest = {"guid": guid, "variables": plain, "constants": sv.SLAVE_CONSTANTS}
    build_pythonfmu(out_file, identifier=sv.MODEL_IDENTIFIER, script=SLAVE, module_name=f"lpspool_{tag}",
                    description_xml=xml_bytes(md), resources={"lpspool.json": json.dumps(manifest, indent=1)},
                    documentation={"index.html": doc, **({"FMU.md": HERE / "FMU.md"}
                                                         if (HERE / "FMU.md").exists() else {})})
    return out_file
