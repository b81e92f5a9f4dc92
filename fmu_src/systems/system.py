"""What the engine system's modules share: its FMUs' names, the connections between them, the scenario's
constants, and the error they raise."""

from __future__ import annotations

from dataclasses import dataclass

from ..models.casing_load.variables import MODEL_IDENTIFIER as CASING_LOAD_ID
from ..models.clearance.variables import MODEL_IDENTIFIER as CLEARANCE_ID
from ..models.contact.variables import MODEL_IDENTIFIER as CONTACT_ID
from ..models.spool.variables import MODEL_IDENTIFIER as SPOOL_ID

__all__ = ["CASING_LOAD_ID", "CLEARANCE_ID", "CONNECTIONS", "CONTACT_ID", "EngineError", "FIRST_CRITICAL", "G0_NO_RUB",
           "G0_RUB", "ME_REF", "OMEGA_REF", "PARTS", "SPOOL_ID", "Part"]
OMEGA_REF = 53.4  # rad/s, normalisation speed of the reference parameters
FIRST_CRITICAL = 3.49 * OMEGA_REF  # rad/s, first critical speed of the reference model (about 186.4 rad/s)
# the connections of the coupled system: (start element, start connector, end element, end connector)
CONNECTIONS = (("spool", "Omega", "contact", "Omega"), ("contact", "friction_torque", "spool", "friction_torque"))


@dataclass(frozen=True)
class Part:
    """A component an engine package may add to the spool and the contact: its FMU (resources/<identifier>.fmu), the
    connectors it shows, the connections it brings, and the contact's connectors those need (and the outputs worth
    showing with them)."""

    identifier: str
    connectors: tuple[tuple[str, str], ...]  # (variable, kind)
    connections: tuple[tuple[str, str, str, str], ...]  # (start element, start connector, end element, end connector)
    contact_connectors: tuple[tuple[str, str], ...]


# the parts, in the order a package lists them (after the contact and the spool)
_CASING_INPUTS = ("casing_lobe2.amplitude", "casing_lobe2.phase", "casing_offset.x", "casing_offset.y")
PARTS = {
    # the clearance closure from the spool speed (the wear scenario)
    "clearance": Part(CLEARANCE_ID, (("Omega", "input"), ("closure", "output")),
                      (("spool", "Omega", "clearance", "Omega"),
                       ("clearance", "closure", "contact", "clearance_closure")),
                      (("clearance_closure", "input"), ("wear.depth_max", "output"), ("wear.volume", "output"),
                       ("clearance_effective", "output"))),
    # the casing's ovalization and offset during a manoeuvre (the manoeuvre scenario)
    "casing_load": Part(CASING_LOAD_ID, (("load_factor", "output"), *((v, "output") for v in _CASING_INPUTS)),
                        tuple(("casing_load", v, "contact", v) for v in _CASING_INPUTS),
                        (*((v, "input") for v in _CASING_INPUTS), ("wear.depth_max", "output"),
                         ("wear.volume", "output"), ("wear.lobes", "output"))),
}
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
