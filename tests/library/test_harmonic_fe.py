"""The harmonic balance with imported blades (the example fan blade, examples/fan_blade: 10 blades of 16 reduced
dofs, a tip of 12 chord stations = 11 contact segments a blade with compact rows): the kernel's reduced batch
(rr_batch_reduced) over compact rows and segment lengths, against the kernel's own force and Jacobian on all dofs;
the exact Jacobian of the residual; the condensed balance in every dof; an orbit the transient settles on."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hb_checks import balance_in_every_dof, jacobian_error_in_contact  # tests/library/hb_checks.py
from threadpoolctl import threadpool_limits

from rotorub_model import kernel
from rotorub_model.analyses.harmonic.orbit import OrbitView, tip_deflection
from rotorub_model.analyses.harmonic.problem import HBProblem, newton
from rotorub_model.analyses.harmonic.stability import monodromy_multipliers
from rotorub_model.analyses.harmonic.surface import CasingForcing
from rotorub_model.analyses.harmonic.transients import KINDS, forced_transient
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import load_parameters, to_dict

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fan_blade" / "example.toml"


@pytest.fixture(autouse=True)
def one_thread():
    with threadpool_limits(limits=1):
        yield


@pytest.fixture(scope="module")
def model():
    return build_model(load_parameters(EXAMPLE))


G0 = 0.1e-3  # the example's clearance is 1 mm: at 0.1 mm an oval of 0.03 mm is rubbed at every sample from 3.0


def _setup(model, speed: float = 3.0, harmonics: int = 4):
    g0 = G0
    forcing = CasingForcing.lobe(2, 0.3 * g0)
    om = speed * model.params.normalisation.omega_ref
    return HBProblem(model, make_contact(model, "3D", g0=g0), harmonics, forcing=forcing), om, g0, forcing


def test_the_reduced_batch_equals_the_kernels_force_and_jacobian_on_compact_rows(model):
    """y = P q at contact states of every segment: P F(P^T y) and P J P^T from the reduced batch equal the kernel's
    rr_force and rr_jacobian on all 158 dofs (which read the compact rows their own way), to round-off. Before
    the batch read compact rows it took each segment's rows as dense (n wide) and the global chord for every
    segment's length."""
    pb, om, g0, _ = _setup(model)
    c, nl = pb.contact, pb.nl
    P = nl.P
    rng = np.random.default_rng(3)
    y = rng.standard_normal((6, P.shape[0])) * 1e-3
    yd = rng.standard_normal((6, P.shape[0])) * 1e-2
    F, J, Jv, touching = nl.batch(y, yd, om, np.zeros(6))
    assert touching == 6  # every sample has a segment in contact (the test means something)
    n = model.n_dofs
    for i in range(6):
        q, qd = P.T @ y[i], P.T @ yd[i]
        f, Jf, Jvf = np.empty(n), np.empty((n, n)), np.empty((n, n))
        k = nl._view
        c.lib.rr_force(nl._vref, kernel.ptr(q), kernel.ptr(qd), om, kernel.ptr(f))
        c.lib.rr_jacobian(nl._vref, kernel.ptr(q), kernel.ptr(qd), om, kernel.ptr(Jf), kernel.ptr(Jvf))
        assert k.nloc > 0  # compact rows indeed
        assert np.abs(P @ f - F[i]).max() <= 1e-12 * np.abs(f).max()
        assert np.abs(P @ Jf @ P.T - J[i]).max() <= 1e-10 * np.abs(Jf).max()
        assert np.abs(P @ Jvf @ P.T - Jv[i]).max() <= 1e-10 * max(np.abs(Jvf).max(), 1e-300)
        # nothing of the force lies outside the contact coordinates: the condensation loses nothing
        assert np.abs(f - P.T @ (P @ f)).max() <= 1e-12 * np.abs(f).max()


def test_jacobian_is_the_derivative_of_the_residual(model):
    pb, om, _, _ = _setup(model, harmonics=3)
    assert jacobian_error_in_contact(pb, om) <= 1e-6


def test_condensation_is_exact(model):
    """The full response rebuilt from the contact coordinates balances harmonic by harmonic in all 158 dofs, with
    the force from the kernel's rr_force at every sample (each at its own frame angle of the oval casing)."""
    pb, om, _, _ = _setup(model, harmonics=6)
    res = newton(pb, pb.linear_start(om, om), om, om)
    assert res.converged
    lhs, rhs, F = balance_in_every_dof(pb, res.Y, om)
    assert np.abs(F).max() > 0  # it rubs
    assert np.abs(lhs - rhs).max() <= 1e-8 * np.abs(rhs).max()


def test_hb_equals_the_settled_transient(model):
    """Where the orbit is stable (2.5 omega_ref, largest multiplier 0.966), a transient of the imported-blade rotor
    against the oval casing settles on it: periodic, the same blade-tip and fan-disk amplitudes within 1 % and the
    largest blade force within 2 % (read on the transient's own 64 phases; measured 0.27 %, 0.07 %, 0.49 %)."""
    from rotorub_model.analyses.harmonic.orbit import measures_at_phases

    pb, om, g0, forcing = _setup(model, speed=SPEED, harmonics=10)
    Y = newton(pb, pb.linear_start(om, om), om, om).Y
    assert monodromy_multipliers(pb, Y, om, om).stable
    me = measures_at_phases(pb, Y, om, om, 64)
    assert me.max_force > 0  # it rubs
    tr = forced_transient(to_dict(model.params), "3D", om, g0, forcing.offset, forcing.lobes, T_END)
    assert KINDS[int(tr["kind"])] == "periodic"
    assert abs(float(tr["disk_amplitude"]) / me.disk_amplitude - 1) <= 0.01
    assert abs(float(tr["tip_amplitude"]) / me.tip_amplitude - 1) <= 0.01
    assert abs(float(tr["max_force"]) / me.max_force - 1) <= 0.02
    v = tip_deflection(model, OrbitView(pb, Y, om, om).q)
    assert v.shape[1] == model.params.blades.count and np.ptp(v) > 0


SPEED, T_END = 2.5, 10.0
