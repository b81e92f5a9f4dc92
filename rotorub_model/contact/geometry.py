"""The geometry a contact formulation hands to the contact model (no behaviour, no imports of the formulations)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ContactGeometry:
    """Per-point geometry: arrays of shape (N, P, ...) with P = 1 (2D) or 2 (LE, TE)."""

    points: np.ndarray  # (N, P, 3) rest positions, rotating frame, z from the blade-tip plane
    normals: np.ndarray  # (N, P, 3) outward casing normal
    tangents: np.ndarray  # (N, P, 3) e_t at the point
    Jb: np.ndarray  # (N, P, 3, n) blade-point displacement maps
    Jc: np.ndarray  # (N, P, 3, n) casing-point displacement maps
    chord: float  # l_c (0 for the point law)
    disk: np.ndarray  # (2, n) fan-disk centre translation (rotating x, y): an output of every state
