"""Rayleigh–Ritz bases and quadrature.

Shaft: Legendre polynomials on [0, L] (the first two are the rigid translation
and the rigid tilt; higher ones bend the shaft). Blades: clamped-free monomials
(s/l)^(k+1), k = 1..n, which satisfy the geometric boundary conditions at the root.
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import legendre


def gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre points and weights on [a, b] (exact for degree 2n-1)."""
    x, w = legendre.leggauss(n)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def legendre_basis(z: np.ndarray | float, length: float, n: int, deriv: int = 0) -> np.ndarray:
    """Values (or derivatives w.r.t. z) of the n shaft functions at z, shape (len(z), n)."""
    z = np.atleast_1d(np.asarray(z, dtype=float))
    xi = 2.0 * z / length - 1.0
    out = np.empty((z.size, n))
    for k in range(n):
        c = np.zeros(k + 1)
        c[k] = 1.0
        if deriv:
            c = legendre.legder(c, deriv) * (2.0 / length) ** deriv
        out[:, k] = legendre.legval(xi, c)
    return out


def cantilever_basis(s: np.ndarray | float, length: float, n: int, deriv: int = 0) -> np.ndarray:
    """Values (or derivatives) of psi_k(s) = (s/l)^(k+1), k = 1..n, shape (len(s), n)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    out = np.empty((s.size, n))
    x = s / length
    for k in range(1, n + 1):
        p = k + 1
        if deriv > p:
            out[:, k - 1] = 0.0
            continue
        coef = 1.0
        for d in range(deriv):
            coef *= p - d
        out[:, k - 1] = coef * x ** (p - deriv) / length**deriv
    return out


def cantilever_foreshortening(s: np.ndarray | float, length: float, n: int) -> np.ndarray:
    """int_0^s psi_k' psi_m' ds' for each s, shape (len(s), n, n) (closed form for monomials)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    p = np.arange(2, n + 2, dtype=float)
    pk, pm = np.meshgrid(p, p, indexing="ij")
    e = pk + pm - 1.0
    return (pk * pm / e)[None, :, :] * (s[:, None, None] / length) ** e[None, :, :] / length
