"""2D contact geometry (eq. 1): a point blade tip facing a cylindrical casing.

The gap only sees the fan-disk translation, the casing translation and the
casing's radial deformation u at the blade angle:
g_j = g0 + u(alpha_j) + (x_c - x_d) cos alpha_j + (y_c - y_d) sin alpha_j.
Friction acts along e_t and does work on the disk translation, the casing
translation and the ring's tangential deformation (no blade flexure, no
rotations: the 2D kinematics).
"""

from __future__ import annotations

import numpy as np

from ..structure.blades import blade_angles
from ..structure.casing import casing_point_map
from ..structure.model import Model
from .geometry import ContactGeometry


def geometry_2d(model: Model) -> ContactGeometry:
    p = model.params
    N, n = p.blades.count, model.n_dofs
    R = p.blades.tip_radius
    T, _ = model.disk_maps
    cs = model.slices["casing"]
    pts = np.zeros((N, 1, 3))
    nor = np.zeros((N, 1, 3))
    tan = np.zeros((N, 1, 3))
    Jb = np.zeros((N, 1, 3, n))
    Jc = np.zeros((N, 1, 3, n))
    for j, a in enumerate(blade_angles(p)):
        e_r = np.array([np.cos(a), np.sin(a), 0.0])
        pts[j, 0] = R * e_r
        nor[j, 0] = e_r
        tan[j, 0] = [-np.sin(a), np.cos(a), 0.0]
        Jb[j, 0] = T
        D = casing_point_map(p, pts[j, 0])
        D[:, 2:4] = 0.0  # no casing tilt in the 2D kinematics
        Jc[j, 0][:, cs] = D
    return ContactGeometry(pts, nor, tan, Jb, Jc, 0.0, np.ascontiguousarray(T[:2]))
