"""Quantities of interest, each from the cheapest analysis that answers it.

The rule (docs/THEORY.md section 10): a quantity is computed by the analysis that its entry names, and a
sample runs the analyses its study's quantities name and no other:

* ``detection`` (linear response + gaps, analyses/linear.py and detection.py): whether and by how much the
  blades touch, from the rotor's response without contact. Exact for first contact: up to the first touch
  the contact force is zero, so the response is the linear one. Microseconds per sample once the linear
  responses are known.
* ``static`` (balanced static solution with contact + its eigenvalues, analyses/static.py, stability.py):
  what the rub settles to in the rotating frame and whether it stays there. About 2 ms per sample.
* ``transient`` (central differences, analyses/transient.py): what a static solution cannot say: the peak
  force on the way, the divergence of an unstable rub. 10 ms per simulated second at 38 dofs.
* ``wear`` (the transient against the wearing liner, analyses/wear.py / contact/liner.py): the depth cut.

Events are booleans (their probability is estimated); a threshold event ``"NAME > value"`` or
``"NAME < value"`` turns a value quantity into one, and is what FORM and subset sampling need (a limit state).

Examples
--------
>>> QUANTITIES["margin"].level, QUANTITIES["rub"].kind
('detection', 'event')
>>> parse_event("peak_force > 500").threshold
500.0
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import ParameterError

LEVELS = ("analytic", "detection", "static", "transient", "wear")


@dataclass(frozen=True)
class Quantity:
    name: str
    level: str
    unit: str
    kind: str  # "value" or "event"
    doc: str


QUANTITIES: dict[str, Quantity] = {q.name: q for q in (
    Quantity("margin", "detection", "m", "value",
             "first-contact margin at the operating point: the smallest gap over the blades, their contact points "
             "and a revolution, with no contact force (g0 - closure - max_p(-G_p q + n_r,p |offset|)); < 0: rub"),
    Quantity("rub", "detection", "-", "event", "the blades touch at the operating point (margin < 0)"),
    Quantity("static_max_force", "static", "N", "value",
             "largest blade normal force of the balanced static solution with contact"),
    Quantity("static_blades_in_contact", "static", "-", "value", "blades touching in the balanced static solution"),
    Quantity("static_max_real", "static", "1/s", "value",
             "largest real part of the eigenvalues linearised about the static solution"),
    Quantity("static_unstable", "static", "-", "event",
             "the balanced static solution is unstable (an eigenvalue with a positive real part)"),
    Quantity("peak_force", "transient", "N", "value",
             "largest blade normal force over the transient (imbalance ramped in from rest)"),
    Quantity("diverged", "transient", "-", "event",
             "the transient diverges: through the penetration limit, or (runs of 4 s or more) its distance to the "
             "static solution grows 1.5-fold over the second half at a steady rate (app/studies.py verdict)"),
    Quantity("wear_depth", "wear", "m", "value", "deepest cut in the abradable liner at the end of the transient"),
    Quantity("amp_linear", "detection", "-", "value",
             "linear amplification factor: largest blade tip deflection of the mistuned disk over the tuned one's, "
             "linear imbalance response (no contact) at the operating point"),
    Quantity("amp_contact", "static", "-", "value",
             "contact amplification factor: the same ratio on the balanced static solution with contact"),
    Quantity("amp_force", "static", "-", "value",
             "largest blade normal force of the mistuned disk's static solution over the tuned one's"),
    Quantity("amp_contact_transient", "transient", "-", "value",
             "contact amplification factor from the transient: largest blade tip deflection after the imbalance "
             "ramp, mistuned over tuned"),
    Quantity("y", "analytic", "-", "value", "the test function's output (model = \"ishigami\")"),
)}
ALIASES = {"rub": ("margin", "<", 0.0)}  # the events that are thresholds of a value quantity
NEEDS_MISTUNING = ("amp_linear", "amp_contact", "amp_force", "amp_contact_transient")


@dataclass(frozen=True)
class Event:
    """``quantity`` (a value) ``op`` (< or >) ``threshold``, or a boolean quantity (op None)."""

    text: str
    quantity: str
    op: str | None = None
    threshold: float = 0.0

    def of(self, values):
        """The event's indicator (1.0 / 0.0, NaN where the quantity is undefined) on an array of values."""
        import numpy as np

        v = np.asarray(values, dtype=float)
        if self.op is None:
            return v
        hit = v < self.threshold if self.op == "<" else v > self.threshold
        return np.where(np.isnan(v), np.nan, hit.astype(float))

    @property
    def display(self) -> str:
        """The event as a person reads it, with its unit: "margin < 0.5 mm" for "margin < 0.5e-3"."""
        if self.op is None:
            return self.text
        unit = QUANTITIES[self.quantity].unit
        if unit == "m":
            return f"{self.quantity} {self.op} {self.threshold * 1e3:.4g} mm"
        return f"{self.quantity} {self.op} {self.threshold:.4g}" + ("" if unit == "-" else f" {unit}")

    @property
    def limit_state(self) -> tuple[str, str, float] | None:
        """(value quantity, op, threshold) for FORM and subset sampling; None for a boolean quantity."""
        if self.op is not None:
            return self.quantity, self.op, self.threshold
        return ALIASES.get(self.quantity)


def parse_event(text: str, where: str = "study.events") -> Event:
    if not isinstance(text, str):
        raise ParameterError(f"{where}: expected text such as \"rub\" or \"peak_force > 500\", got {text!r}")
    m = re.fullmatch(r"\s*([A-Za-z_]\w*)\s*(?:([<>])\s*([-+0-9.eE]+))?\s*", text)
    if not m:
        raise ParameterError(f"{where}: {text!r} not understood; accepted: an event quantity (rub, static_unstable, "
                             "diverged) or 'NAME < value' / 'NAME > value' on a value quantity")
    name, op, val = m.groups()
    if name not in QUANTITIES:
        raise ParameterError(f"{where}: {text!r}: quantity '{name}' unknown; accepted: {', '.join(QUANTITIES)}")
    q = QUANTITIES[name]
    if op is None:
        if q.kind != "event":
            raise ParameterError(f"{where}: {text!r}: '{name}' is a value; give a threshold ('{name} > value')")
        return Event(text.strip(), name)
    if q.kind != "value":
        raise ParameterError(f"{where}: {text!r}: '{name}' is an event already; give it without a threshold")
    try:
        thr = float(val)
    except ValueError:
        raise ParameterError(f"{where}: {text!r}: threshold {val!r} is not a number") from None
    return Event(text.strip(), name, op, thr)


def check_quantities(names, where: str = "study.quantities") -> list[Quantity]:
    if isinstance(names, str) or not isinstance(names, list) or not names:
        raise ParameterError(f"{where}: expected a non-empty list of names; accepted: {', '.join(QUANTITIES)}")
    out = []
    for n in names:
        if n not in QUANTITIES:
            raise ParameterError(f"{where}: '{n}' unknown; accepted: {', '.join(QUANTITIES)}")
        if n not in [q.name for q in out]:
            out.append(QUANTITIES[n])
    return out


def event_display(text: str) -> str:
    """:attr:`Event.display` of an event's text (the text itself if it does not parse).

    >>> event_display("margin < 0.5e-3"), event_display("peak_force > 500"), event_display("rub")
    ('margin < 0.5 mm', 'peak_force > 500 N', 'rub')
    """
    try:
        return parse_event(text).display
    except ParameterError:
        return text
