"""Blade-tip / casing contact: the 2D and 3D geometries and the contact model built on them.

``make_contact(model, "3D", g0=...)`` is the entry point; the laws themselves run in the
compiled kernel (``rotorub_model.kernel``).
"""

from .contact_model import FORMULATIONS, VARIANTS, ContactModel, make_contact
from .geometry import ContactGeometry

__all__ = ["FORMULATIONS", "VARIANTS", "ContactGeometry", "ContactModel", "make_contact"]
