"""Penalty contact laws, compiled (numba) so the transient's hot loop can call them.

Point law (2D): F_N = -k_r g for g < 0, else 0.

Chord law (3D, eq. 5-8): the gap is linear along the chord c in [-l/2, l/2],
gap(c) = zeta c + eta with eta = (g_LE + g_TE)/2 and zeta = (g_TE - g_LE)/l, and the
pressure p_N(c) = -(k_r/l) gap(c) acts where gap(c) < 0:

    F_N = int p_N dc,   M_N = int c p_N dc   over [c1, c2] (the three cases of eq. 8).

Because the integrand vanishes at the moving contact front c* = -eta/zeta, the
derivatives with respect to (eta, zeta) only involve the fixed limits (Leibniz),
which gives the analytic Jacobian; F_N and M_N are C1 across front crossings.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def chord_law(g_le: float, g_te: float, k: float, l: float):
    """(F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, fraction in contact) of one chord."""
    if g_le >= 0.0 and g_te >= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    eta = 0.5 * (g_le + g_te)
    zeta = (g_te - g_le) / l
    h = 0.5 * l
    if g_le < 0.0 and g_te < 0.0:
        c1, c2 = -h, h
    elif g_le < 0.0:
        c1, c2 = -h, -eta / zeta
    else:
        c1, c2 = -eta / zeta, h
    s = k / l
    d1 = c2 - c1
    d2 = 0.5 * (c2 * c2 - c1 * c1)
    d3 = (c2 * c2 * c2 - c1 * c1 * c1) / 3.0
    F = -s * (zeta * d2 + eta * d1)
    M = -s * (zeta * d3 + eta * d2)
    return F, M, -s * d1, -s * d2, -s * d2, -s * d3, d1 / l


@njit(cache=True)
def point_law(g: float, k: float):
    """(F_N, dF/dg) of a point contact."""
    if g >= 0.0:
        return 0.0, 0.0
    return -k * g, -k


@njit(cache=True)
def blade_laws(gaps: np.ndarray, k: float, l: float, chord: bool, out: np.ndarray) -> None:
    """Evaluate the law of every blade; gaps is (N, 1) or (N, 2) (LE, TE).

    out[j] = (F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, fraction).
    """
    for j in range(gaps.shape[0]):
        if chord:
            r = chord_law(gaps[j, 0], gaps[j, 1], k, l)
            for i in range(7):
                out[j, i] = r[i]
        else:
            F, dF = point_law(gaps[j, 0], k)
            out[j, 0] = F
            out[j, 1] = 0.0
            out[j, 2] = dF
            out[j, 3] = 0.0
            out[j, 4] = 0.0
            out[j, 5] = 0.0
            out[j, 6] = 1.0 if F > 0.0 else 0.0
