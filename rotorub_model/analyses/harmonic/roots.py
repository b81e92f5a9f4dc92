"""A bracketed scalar root (regula falsi, Illinois variant) for locating special points along a step."""

from __future__ import annotations

from collections.abc import Callable


def regula_falsi(f: Callable[[float], float | None], a: float, b: float, fa: float, fb: float, tol: float,
                 max_iter: int = 40, sign_only: bool = False) -> float | None:
    """A root of f in [a, b] with f(a) fa < 0 < ..., to ``tol`` in the argument; None if f fails (returns None)
    or the bracket is not one. ``sign_only``: f gives only a sign (bisection).

    >>> round(regula_falsi(lambda x: x * x - 2, 0.0, 2.0, -2.0, 2.0, 1e-12), 9)
    1.414213562
    """
    if fa == 0:
        return a
    if fb == 0:
        return b
    if (fa > 0) == (fb > 0):
        return None
    side = 0
    for _ in range(max_iter):
        x = 0.5 * (a + b) if sign_only else (a * fb - b * fa) / (fb - fa)
        fx = f(x)
        if fx is None:
            x = 0.5 * (a + b)
            fx = f(x)
            if fx is None:
                return None
        if fx == 0 or abs(b - a) <= tol:
            return x
        if (fx > 0) == (fa > 0):
            a, fa = x, fx
            if side == -1 and not sign_only:
                fb *= 0.5
            side = -1
        else:
            b, fb = x, fx
            if side == 1 and not sign_only:
                fa *= 0.5
            side = 1
    return 0.5 * (a + b)
