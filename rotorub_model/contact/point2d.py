"""2D contact geometry (eq. 1): a point blade tip facing a cylindrical casing.

The gap only sees the fan-disk translation, the casing translation and the
casing's radial deformation u at the blade angle:
g_j = g0 + u(alpha_j) + (x_c - x_d) cos alpha_j + (y_c - y_d) sin alpha_j.
Friction acts along e_t and does work on the disk translation, the casing
translation and the ring's tangential deformation (no blade flexure, no
rotations: the 2D kinematics). Built by the kernel (``rr_contact_geometry``, np = 1).
"""

from __future__ import annotations

from ..structure.model import Model
from .geometry import ContactGeometry, build_geometry


def geometry_2d(model: Model) -> ContactGeometry:
    return build_geometry(model, 1)
