"""The boundary tracer's fast correctors (issue 13) against what they replace: the bracketing
corrector and the continuation's own special points. Each fast corrector solves for the offset along
the normal by Newton/secant on the quantity that vanishes on the curve; if it located a different
point than the bracket does, the curves would be wrong, quickly."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model.analyses.continuation.boundary import BoundaryTracer
from rotorub_model.analyses.continuation.branch import continue_static
from rotorub_model.analyses.continuation.equilibria import Equilibria
from rotorub_model.app.studies import default_grid
from rotorub_model.structure.model import build_model


@pytest.fixture(scope="module")
def model():
    return build_model()


def tracer(model, formulation: str) -> BoundaryTracer:
    speeds, g0s = default_grid(model, quick=True)
    cs = (speeds[-1] - speeds[0]) / (len(speeds) - 1)
    cg = (g0s.max() - g0s.min()) / (len(g0s) - 1)
    return BoundaryTracer(Equilibria(model, formulation), (float(speeds[0]), float(speeds[-1])),
                          (float(g0s.min()), float(g0s.max())), (cs, cg))


def first_point(tr: BoundaryTracer, speed: float, g_hi: float, g_lo: float):
    """The boundary point on the segment (speed, g_hi) -> (speed, g_lo) by the bracketing corrector:
    (point, kind, stable sample, unstable sample, unit normal towards the unstable side)."""
    a, b = tr.to_xy(speed, g_hi), tr.to_xy(speed, g_lo)
    sa = tr.sample(a, None)
    sb = tr.sample(b, sa.q, sa)
    assert not sa.unstable and sb.unstable
    p, kind, ra, rb = tr.locate(a, b, sa, sb)
    return p, kind, ra, rb, (b - a) / np.linalg.norm(b - a)


@pytest.mark.parametrize("formulation, g_hi, g_lo, kind", [("3D", 0.36e-3, 0.31e-3, "hopf"),
                                                           ("2D", 0.56e-3, 0.50e-3, "switch")])
def test_fast_corrector_lands_where_the_bracket_does(model, formulation, g_hi, g_lo, kind):
    """A tenth of a cell along the curve from a point both correctors start from, the fast one (secant
    on Re mu, or on the contact point's gap) and the bracketing one (regula falsi inside a stable /
    unstable bracket) locate the same point of the normal line to 1e-5 cells, the fast one with far
    fewer balanced solutions."""
    tr = tracer(model, formulation)
    p, k, ra, rb, n = first_point(tr, 3.3, g_hi, g_lo)
    assert k == kind
    tau = np.array([-n[1], n[0]])
    c = p + 0.1 * tau
    e0 = tr.evaluations
    fast = tr._fast(c, n, kind, (ra, rb))
    e_fast = tr.evaluations - e0
    assert fast is not None and fast[1] == kind
    e0 = tr.evaluations
    slow = tr._bracket(c, n, (ra, rb), 0.1)
    e_slow = tr.evaluations - e0
    assert slow is not None and slow[1] == kind
    assert np.linalg.norm(fast[0] - slow[0]) <= 1e-5
    assert e_fast < e_slow
    # and it is the boundary
    pt, _, left, right = fast
    if kind == "hopf":  # the critical eigenvalue on the axis, as the Hopf test asks of a special point
        assert min(abs(left.mu.real), abs(right.mu.real)) <= 1e-8
        assert not left.unstable
    else:  # stable on one side of the event, unstable on the other
        assert not left.unstable and right.unstable
        k_ev = left.event
        assert left.contact_set[k_ev] != right.contact_set[k_ev]
        gap = tr.eq.gaps(left.q, left.g0).ravel()[k_ev]
        assert abs(gap) <= 1e-6 * tr.cg


def test_branch_end_is_the_fold_of_the_continuation(model):
    """3D at g0 = 2 mm: the branch followed up in speed ends at the fold the pseudo-arclength
    continuation locates; the tracer's secant on det^2 finds it to 2e-4 cells (the continuation's own
    location tolerance) in fewer balanced solutions than bisection would take (16)."""
    wr = model.params.normalisation.omega_ref
    tr = tracer(model, "3D")
    b = continue_static(tr.eq, "omega", 2.0e-3, 3.45 * wr, 3.6 * wr, spectrum=False)
    f = b.of_kind("fold")[0].point
    ws = b.values()
    turn = int(np.flatnonzero(np.diff(ws) < 0)[0])  # the branch's points up to the fold
    before = [p for p in b.points[:turn + 1] if p.omega < f.omega - 0.05 * tr.cs * wr][-1]
    x0 = tr.to_xy(before.omega / wr, before.g0)
    x1 = tr.to_xy(before.omega / wr + 0.01 * tr.cs, before.g0)
    q1 = tr.eq.solve(before.omega + 0.01 * tr.cs * wr, before.g0, before.q, follow=True)
    tr._rate = float(np.linalg.norm(q1 - before.q) / np.linalg.norm(x1 - x0))
    n = np.array([1.0, 0.0])
    c = tr.to_xy(f.omega / wr, f.g0) + 0.013 * n  # a predictor off by a seventy-seventh of a cell
    e0 = tr.evaluations
    end = tr.branch_end(c, n, before.q, x0)
    assert end is not None
    lo, hi, q_end = end
    assert hi - lo <= 1e-6
    located = (c + 0.5 * (lo + hi) * n)[0] * tr.cs * wr
    assert abs(located - f.omega) / (tr.cs * wr) <= 2e-4
    assert tr.evaluations - e0 < 16
    # past the end: no solution of the branch's orientation near it
    assert tr.eq.orientation(q_end, located, f.g0)[0] == tr.eq.orientation(before.q, before.omega, f.g0)[0]


def test_2d_spectrum_is_a_function_of_the_contact_set_and_the_speed(model):
    """The tracer computes the 2D spectrum once per (contact set, speed): it relies on the point law
    being piecewise linear with saturated friction, so that the linearisation (K_e, C_e) does not
    depend on the solution within a contact set. Checked at two clearances with the same set (and
    it does change when the set does)."""
    eq = Equilibria(model, "2D")
    w = 3.3 * model.params.normalisation.omega_ref
    q1 = eq.solve(w, 0.60e-3)
    q2 = eq.solve(w, 0.58e-3, q1)
    assert eq.contact_set(q1, 0.60e-3) == eq.contact_set(q2, 0.58e-3) and any(eq.contact_set(q1, 0.60e-3))
    assert np.linalg.norm(q2 - q1) > 1e-3 * np.linalg.norm(q1)  # different solutions
    K1, C1 = eq.linearisation(q1, w, 0.60e-3)
    K2, C2 = eq.linearisation(q2, w, 0.58e-3)
    assert np.array_equal(K1, K2) and np.array_equal(C1, C2)
    q3 = eq.solve(w, 0.45e-3, q2)
    assert eq.contact_set(q3, 0.45e-3) != eq.contact_set(q2, 0.58e-3)
    K3, _ = eq.linearisation(q3, w, 0.45e-3)
    assert not np.allclose(K3, K1)
