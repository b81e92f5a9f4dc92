"""3D contact geometry (eq. 3-4): leading and trailing edges facing a conical casing.

Blade j's tip chord runs from LE (c = -l_c/2) to TE (c = +l_c/2) along
c_dir = cos(beta) e_z - sin(beta) e_t (stagger beta from the axis; the TE trails
in the spin direction and lies downstream). The tip is cut parallel to the casing:
each edge sits at the normal distance g0 from the cone, whose radius decreases
downstream as R(z) = R_tip + g0/cos(theta) - z tan(theta) (theta = 0: a cylinder).

The edge positions follow eq. (3) linearised: disk translation, disk tilt (about
the disk centre, lever arm = the edge's position), blade tip deflection along the
flexible direction n_j; casing translation, casing tilt about its centre of
gravity, and the ring's radial (normal) deformation at the edge's initial angle
(eq. 4's u(alpha(P)) with the cos(theta) projection). Built by the kernel
(``rr_contact_geometry``, np = 2).
"""

from __future__ import annotations

from ..structure.model import Model
from .geometry import ContactGeometry, build_geometry


def geometry_3d(model: Model, theta: float, chord: float, rotations: bool = True) -> ContactGeometry:
    """Geometry of the LE/TE points; ``rotations=False`` is the paper's 'geometry only'
    variant (no disk or casing rotation, no blade flexure in the gap)."""
    return build_geometry(model, 2, theta, chord, rotations)
