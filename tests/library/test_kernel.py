"""The kernel's own numerics against numpy/LAPACK: eigenvalues (balancing + Hessenberg + double-shift QR),
the inverse (LU with partial pivoting) and the central-difference matrices the FMUs build with them."""

from __future__ import annotations

import numpy as np
import pytest

from rotorub_model import kernel
from rotorub_model.analyses.linear import first_order
from rotorub_model.analyses.static import solve_static
from rotorub_model.contact import make_contact


def _match(ev: np.ndarray, ref: np.ndarray) -> float:
    """Largest distance from an eigenvalue to the nearest reference one."""
    return float(max(np.min(np.abs(ref - e)) for e in ev))


@pytest.mark.parametrize("n", [1, 2, 3, 7, 30, 76])
def test_eigenvalues_of_random_matrices(n):
    A = np.random.default_rng(n).normal(size=(n, n))
    ev = kernel.eigenvalues(A)
    ref = np.linalg.eigvals(A)
    assert _match(ev, ref) <= 1e-12 * np.abs(ref).max()
    assert _match(ref, ev) <= 1e-12 * np.abs(ref).max()  # and none is missed


def test_eigenvalues_of_a_defective_and_a_graded_matrix():
    J = np.array([[2.0, 1.0, 0.0], [0.0, 2.0, 1.0], [0.0, 0.0, 2.0]])  # one Jordan block
    assert np.allclose(kernel.eigenvalues(J), 2.0, atol=1e-5)
    D = np.diag([1e-6, 1.0, 1e6]) @ np.random.default_rng(0).normal(size=(3, 3)) @ np.diag([1e6, 1.0, 1e-6])
    assert _match(kernel.eigenvalues(D), np.linalg.eigvals(D)) <= 1e-9 * np.abs(np.linalg.eigvals(D)).max()


def test_stability_matrix_largest_real_part(ref_model):
    """The 76 x 76 first-order matrix of a 3D static solution with contact: the largest real part
    (the FMUs' stability indicator) agrees with LAPACK to 1e-12 of the matrix norm."""
    w = 3.3 * ref_model.params.normalisation.omega_ref
    c = make_contact(ref_model, "3D", g0=0.2e-3)
    st = solve_static(ref_model, c, w)
    A = first_order(ref_model, w, *c.jacobians(st.q, w))
    ours, ref = kernel.eigenvalues(A).real.max(), np.linalg.eigvals(A).real.max()
    assert abs(ours - ref) <= 1e-12 * np.abs(A).max()
    assert ref > 0  # an unstable point: the sign is what matters
    assert ours > 0


def test_inverse(ref_model):
    A = ref_model.M / 1e-8 + ref_model.D / 2e-4
    Ai = kernel.inverse(A)
    assert np.abs(Ai @ A - np.eye(ref_model.n_dofs)).max() < 1e-10
    with pytest.raises(np.linalg.LinAlgError, match="singular"):
        kernel.inverse(np.zeros((3, 3)))


def test_no_compiler_at_all_is_one_clear_error(monkeypatch, tmp_path):
    """No system compiler, no ziglang, no $CC: one message naming what to install."""
    from rotorub_model.kernel import compiler

    monkeypatch.setenv("PATH", str(tmp_path))  # an empty folder: no cc, gcc, clang
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv("ROTORUB_CC", raising=False)
    monkeypatch.setattr(compiler, "zig_command", lambda: None)
    with pytest.raises(compiler.CompilerError) as err:
        compiler.find_compiler()
    msg = str(err.value)
    assert "no C compiler found" in msg and "pip install ziglang" in msg and "apt install gcc" in msg


def test_ziglang_alone_builds_a_kernel_that_gives_the_same_numbers(monkeypatch, tmp_path):
    """The machine-with-only-Python route: the kernel built by ziglang equals the system compiler's."""
    from rotorub_model.kernel import compiler

    if compiler.zig_command() is None:
        pytest.skip("ziglang is not installed")
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.delenv("ROTORUB_CC", raising=False)
    found = compiler.find_compiler()
    assert found.kind == "zig"
    out = kernel.build(tmp_path / "zig_kernel.so")
    import ctypes

    lib = ctypes.CDLL(str(out))
    args = [ctypes.c_double(v) for v in (-1e-3, 2e-4, 1.5e6, 0.2)]
    law = kernel.make_law("bilinear", (0.3e-3, 4.0))
    res = (ctypes.c_double * kernel.LAW_WIDTH)()
    lib.rr_blade_law(ctypes.byref(law), 2, *args, res)
    assert tuple(res) == kernel.blade_law(-1e-3, 2e-4, 1.5e6, 0.2, law)


def test_eigenvalues_converge_where_the_classic_hqr_stopped(ref_model):
    """M^-1 (K(Omega) + Kc) at 71 rad/s with every 3D contact closed, multiplied in the native FMU's loop
    order: the classic hqr's 30 sweeps per eigenvalue were not enough (the native FMU refused its first step
    at that speed). With LAPACK's allowance (30 max(10, n), an exceptional shift every 10) it converges, to
    the eigenvalues LAPACK finds."""
    from rotorub_model.analyses.transient import all_closed_stiffness
    from rotorub_model.contact import make_contact

    c = make_contact(ref_model, "3D", g0=-0.1e-3)
    Minv = kernel.inverse(ref_model.M)
    Kc = ref_model.K_omega(71.0) + all_closed_stiffness(c, 71.0)
    P = np.zeros_like(Kc)
    for i in range(Kc.shape[0]):  # the C loop's order of summation, term by term
        for j in range(Kc.shape[1]):
            acc = 0.0
            for k in range(Kc.shape[0]):
                acc += Minv[i, k] * Kc[k, j]
            P[i, j] = acc
    lam = kernel.eigenvalues(P)
    ref = np.linalg.eigvals(P)
    np.testing.assert_allclose(np.sort(np.abs(lam)), np.sort(np.abs(ref)), rtol=1e-12, atol=1e-9 * np.abs(ref).max())


def _advance_in_calls(model, contact, calls, between=None):
    """Central differences from rest, in calls of the given step counts; `between(cd, k)` after call k. Returns the
    final q and the records' outputs (rotating frame, one per step)."""
    from rotorub_model.analyses.transient import CentralDifference

    w = 3.3 * model.params.normalisation.omega_ref
    cd = CentralDifference(model, contact, dt=2e-4, t_ramp=0.0)
    cd.q[:] = 1e-4 * np.sin(np.arange(model.n_dofs))  # a state with blades in contact from the first step
    cd.q_prev[:] = cd.q
    rec_q, rec_out = np.zeros((sum(calls), model.n_dofs)), np.zeros((sum(calls), contact.n_outputs))
    written = 0
    for k, n in enumerate(calls):
        _, written = cd.advance(n, w, model.params.imbalance.me, rec_every=1, rec_q=rec_q, rec_start=written,
                                rec_out=rec_out)
        if between is not None:
            between(cd, k)
    return cd.q.copy(), rec_out


@pytest.mark.parametrize("formulation", ["2D", "3D"])
def test_a_run_cut_into_calls_is_the_run_in_one_call(ref_model, formulation):
    """The kernel keeps the contact evaluation of a call's last state for the next call (a communication step costs
    its substeps, not one evaluation more): cut into calls, a run is the same run, bit for bit."""
    c = make_contact(ref_model, formulation, g0=0.05e-3)
    q1, out1 = _advance_in_calls(ref_model, c, [60])
    q3, out3 = _advance_in_calls(ref_model, c, [1, 20, 39])
    assert np.abs(out1[:, :10 * (c.n_points + 4)]).max() > 0  # blades touch: the kept evaluation carries forces
    assert np.array_equal(q1, q3) and np.array_equal(out1, out3)


def test_a_state_changed_between_calls_is_evaluated_afresh(ref_model):
    """Between two calls the state may be written (a master restoring a state, a restart at the same velocity): the
    kept evaluation must then not serve. The changed run equals a run that starts from the changed state; and the
    same run with the kernel deceived into taking the kept evaluation (its record of the state overwritten with the
    changed one) differs: the check is what keeps the two apart."""
    c = make_contact(ref_model, "3D", g0=0.05e-3)
    n = ref_model.n_dofs
    evaluation = 2 * c.n_segments * c.n_points + 8 * c.n_segments  # gaps, friction factors; laws (RR_LAW_WIDTH)

    def nudge(cd, k):
        if k == 0:
            cd.q[7] += 2e-5  # a dof of the first blade, in contact
            cd.q_prev[7] += 2e-5

    def nudge_deceived(cd, k):
        nudge(cd, k)
        if k == 0:  # the cache: key, q, q_prev, evaluation
            at = len(cd._cache) - evaluation - 2 * n
            cd._cache[at:at + n], cd._cache[at + n:at + 2 * n] = cd.q, cd.q_prev

    q_a, out_a = _advance_in_calls(ref_model, c, [10, 30], between=nudge)
    q_d, _ = _advance_in_calls(ref_model, c, [10, 30], between=nudge_deceived)
    assert not np.array_equal(q_a, q_d)
    # the changed run, from its changed state in one call
    from rotorub_model.analyses.transient import CentralDifference

    w = 3.3 * ref_model.params.normalisation.omega_ref
    first = CentralDifference(ref_model, c, dt=2e-4, t_ramp=0.0)
    first.q[:] = 1e-4 * np.sin(np.arange(n))
    first.q_prev[:] = first.q
    first.advance(10, w, ref_model.params.imbalance.me)
    fresh = CentralDifference(ref_model, c, dt=2e-4, t_ramp=0.0)
    fresh.q[:], fresh.q_prev[:] = first.q, first.q_prev
    fresh.t, fresh.phi, fresh.steps = first.t, first.phi, first.steps
    nudge(fresh, 0)
    fresh.advance(30, w, ref_model.params.imbalance.me)
    assert np.array_equal(q_a, fresh.q)
