"""Rayleigh–Ritz bases and quadrature.

Shaft: Legendre polynomials on [0, L] (the first two are the rigid translation
and the rigid tilt; higher ones bend the shaft). Blades: the polynomials of degree 2..n+1
in x = s/l, which satisfy the geometric boundary conditions at the root (v = v' = 0): up to
three of them the paper's monomials x^(k+1) (:func:`cantilever_basis`); from four on the same
space written as x^2 P_(k-1)(2x - 1) (:func:`conditioned_basis`, P the Legendre polynomials),
because the monomials' mass matrix is a Hilbert-like matrix whose condition number grows
40-fold a function (2e12 at 8, 3e15 at 10, where the first frequency loses its digits and
the explicit scheme diverges) while these stay near 1e5..4e6 up to 12 (:func:`blade_polynomials`).
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


RAW_MAX = 3  # up to this many blade functions, the paper's monomials (the reference's two: results unchanged)


def conditioned_basis(s: np.ndarray | float, length: float, n: int, deriv: int = 0) -> np.ndarray:
    """x^2 P_(k-1)(2x - 1), k = 1..n, x = s/l (or their derivatives in s, up to 2), shape (len(s), n): the
    monomials' space, evaluated as Legendre series (no cancelling monomial coefficients)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    x = s / length
    xi = 2.0 * x - 1.0
    out = np.empty((s.size, n))
    for j in range(n):
        c = np.zeros(j + 1)
        c[j] = 1.0
        P = legendre.legval(xi, c)
        d1 = 2.0 * legendre.legval(xi, legendre.legder(c, 1)) if j >= 1 else np.zeros_like(x)
        if deriv == 0:
            out[:, j] = x * x * P
        elif deriv == 1:
            out[:, j] = (2.0 * x * P + x * x * d1) / length
        elif deriv == 2:
            d2 = 4.0 * legendre.legval(xi, legendre.legder(c, 2)) if j >= 2 else np.zeros_like(x)
            out[:, j] = (2.0 * P + 4.0 * x * d1 + x * x * d2) / length**2
        else:
            raise ValueError(f"deriv: {deriv}; accepted: 0, 1, 2")
    return out


def conditioned_foreshortening(s: np.ndarray | float, length: float, n: int) -> np.ndarray:
    """int_0^s psi_k' psi_m' ds' of :func:`conditioned_basis` for each s, shape (len(s), n, n): Gauss on [0, s]
    with n + 1 points (the integrand has degree 2n: exact)."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    out = np.empty((s.size, n, n))
    for i, si in enumerate(s):
        t, w = gauss(0.0, float(si), n + 1)
        d = conditioned_basis(t, length, n, 1)
        out[i] = (d.T * w) @ d
    return out


def blade_polynomials(s: np.ndarray | float, length: float, n: int, deriv: int = 0) -> np.ndarray:
    """The n blade polynomials (see the module's note): the paper's monomials up to RAW_MAX, the conditioned
    form of the same space beyond.

    >>> s = np.linspace(0.0, 0.4, 5)
    >>> bool(np.allclose(blade_polynomials(s, 0.4, 2), cantilever_basis(s, 0.4, 2)))
    True
    >>> a, b = blade_polynomials(s, 0.4, 5), cantilever_basis(s, 0.4, 5)   # the same space
    >>> bool(np.allclose(a, b @ np.linalg.lstsq(b, a, rcond=None)[0]))
    True
    """
    return (cantilever_basis if n <= RAW_MAX else conditioned_basis)(s, length, n, deriv)


def blade_foreshortening_polynomials(s: np.ndarray | float, length: float, n: int) -> np.ndarray:
    """int_0^s psi_k' psi_m' ds' of :func:`blade_polynomials`, shape (len(s), n, n)."""
    return (cantilever_foreshortening if n <= RAW_MAX else conditioned_foreshortening)(s, length, n)
