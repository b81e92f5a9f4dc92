"""A bracketed scalar root on [0, 1]: the Illinois variant of regula falsi.

Used to locate special points along a segment (contact events, folds, Hopf points, boundary
crossings), where each evaluation is a corrector solve that may fail (``f`` returns None).
"""

from __future__ import annotations

from collections.abc import Callable


def illinois(f: Callable[[float], float | None], fa: float, fb: float, tol_x: float, f_tol: float = 0.0,
             max_iter: int = 60, retry_midpoint: bool = False) -> float | None:
    """Root of f on [0, 1] with f(0) = fa, f(1) = fb of opposite signs, to |f| <= f_tol or a bracket
    narrower than tol_x. A failed evaluation (None) ends the search with None, or, with
    ``retry_midpoint``, is tried once more at the bracket's midpoint."""
    a, b, side = 0.0, 1.0, 0
    x = a
    for _ in range(max_iter):
        x = (a * fb - b * fa) / (fb - fa) if fb != fa else 0.5 * (a + b)
        fx = f(x)
        if fx is None and retry_midpoint:
            x = 0.5 * (a + b)
            fx = f(x)
        if fx is None:
            return None
        if abs(fx) <= f_tol or (b - a) <= tol_x:
            return x
        if (fx > 0) == (fb > 0):
            b, fb = x, fx
            if side == 1:
                fa *= 0.5
            side = 1
        else:
            a, fa = x, fx
            if side == -1:
                fb *= 0.5
            side = -1
    return x
