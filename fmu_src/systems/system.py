"""What the engine system's modules share: its FMUs' names, the connections between them, the scenario's
constants, and the error they raise."""

from __future__ import annotations

from ..models.clearance.variables import MODEL_IDENTIFIER as CLEARANCE_ID
from ..models.contact.variables import MODEL_IDENTIFIER as CONTACT_ID
from ..models.spool.variables import MODEL_IDENTIFIER as SPOOL_ID

__all__ = ["CLEARANCE_ID", "CONNECTIONS", "CONTACT_ID", "EngineError", "FIRST_CRITICAL", "G0_NO_RUB", "G0_RUB",
           "ME_REF", "OMEGA_REF", "SPOOL_ID"]
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
