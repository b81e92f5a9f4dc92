"""What the engine system's modules share: its two FMUs' names, the connections between them, the
scenario's constants, reading an FMU's variables, and the error they raise."""

from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

SPOOL_ID = "LPSpool"
CONTACT_ID = "RotorCasingContact"
OMEGA_REF = 53.4  # rad/s, normalisation speed of the reference parameters
FIRST_CRITICAL = 3.49 * OMEGA_REF  # rad/s, first critical speed of the reference model (about 186.4 rad/s)
# the connections of the coupled system: (start element, start connector, end element, end connector)
CONNECTIONS = (("spool", "Omega", "contact", "Omega"), ("contact", "friction_torque", "spool", "friction_torque"))
# scenario: reference imbalance, reference clearance, rub disabled by a large clearance
ME_REF = 22.0e-3  # kg m
G0_RUB = 1.0e-3  # m
G0_NO_RUB = 0.05  # m: 50 mm, ten times any closure of the reference (and inside the declared range)


class EngineError(RuntimeError):
    """A build, SSP or co-simulation problem; ``messages`` holds what the FMUs logged."""

    def __init__(self, what: str, messages=(), result=None):
        self.messages = list(messages)
        self.result = result  # the CoupledResult up to the failure, if any
        detail = ("; ".join(self.messages)) if self.messages else ""
        super().__init__(f"{what}: {detail}" if detail else what)


@dataclass(frozen=True)
class FmuVariable:
    name: str
    type: str  # Real, Integer, Boolean, String, Enumeration
    causality: str
    variability: str
    unit: str | None
    start: str | None
    declared_type: str | None = None  # an Enumeration's type name (its items: enumerations(root))


def specs_variables(specs, values: dict):
    """A small engine FMU's SPECS ((name, type, causality, variability, unit, (min, max) or None, description), in
    value-reference order) as interface.Var, with ``values`` as the start values. The nominal value is the start's
    magnitude, or, for a start of 0, 1 in the unit unless the range is smaller (a closure0 of range +-10 mm is
    nominal 10 mm, not 1 m)."""
    from ..interface import Var

    out = []
    for k, (name, typ, causality, variability, unit, rng, desc) in enumerate(specs):
        start = values.get(name, 0.0) if causality != "output" else None
        nominal = None
        if typ == "Real" and causality != "output":
            nominal = abs(start) or min(1.0, max(abs(rng[0]), abs(rng[1])) if rng else 1.0) or 1.0
        out.append(Var(name, typ, causality, variability, desc, unit=unit, start=start,
                       min=None if rng is None else rng[0], max=None if rng is None else rng[1], nominal=nominal,
                       vr=k))
    return out


def read_description(source) -> tuple[dict[str, FmuVariable], dict[str, dict[str, float]], ET.Element]:
    """(variables by name, unit name -> base-unit exponents, root) of an FMU file, FMU bytes or folder."""
    if isinstance(source, bytes | bytearray):
        with zipfile.ZipFile(io.BytesIO(source)) as z:
            xml = z.read("modelDescription.xml")
    else:
        p = Path(source)
        if p.is_dir():
            xml = (p / "modelDescription.xml").read_bytes()
        else:
            with zipfile.ZipFile(p) as z:
                xml = z.read("modelDescription.xml")
    root = ET.fromstring(xml)
    variables = {}
    for sv in root.iter("ScalarVariable"):
        typ = next(iter(sv))
        variables[sv.get("name")] = FmuVariable(sv.get("name"), typ.tag, sv.get("causality", "local"),
                                                sv.get("variability", "continuous"), typ.get("unit"), typ.get("start"),
                                                typ.get("declaredType"))
    units = {}
    for u in root.iter("Unit"):
        bu = u.find("BaseUnit")
        units[u.get("name")] = {} if bu is None else {k: float(v) for k, v in bu.attrib.items()}
    return variables, units, root




def enumerations(root: ET.Element) -> dict[str, list[tuple[str, int]]]:
    """The Enumeration types of a model description: name -> [(item name, value), ...]."""
    out = {}
    for st in root.iter("SimpleType"):
        en = st.find("Enumeration")
        if en is not None:
            out[st.get("name")] = [(it.get("name"), int(it.get("value"))) for it in en.findall("Item")]
    return out
