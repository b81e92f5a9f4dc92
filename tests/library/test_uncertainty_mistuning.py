"""Mistuning in the model (structure/blades.py hook) and in the studies (uncertainty/mistuning.py)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotorub_model.analyses.linear import first_order, run_modes
from rotorub_model.errors import ParameterError
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters, to_dict
from rotorub_model.uncertainty.evaluate import evaluate_chunk
from rotorub_model.uncertainty.mistuning import MistuningSpec, blade_tip_deflections, mistuned_model

DELTA = np.array([0.03, -0.02, 0.05, 0.0, -0.04, 0.01, 0.02, -0.01, 0.04, -0.03])


@pytest.fixture(scope="module")
def tuned():
    return build_model()


def test_tuned_is_unchanged_bit_for_bit(tuned):
    for m in (build_model(mistuning=None), build_model(mistuning=[]), build_model(mistuning=np.zeros(10))):
        for k in ("M", "D", "K", "G1", "N2", "S2", "E1"):
            assert np.array_equal(getattr(m, k), getattr(tuned, k)), k


def test_fast_mistuned_model_is_the_assembled_one_bit_for_bit(tuned):
    a, b = mistuned_model(tuned, DELTA), build_model(mistuning=DELTA)
    for k in ("M", "D", "K", "G1", "C1", "N2", "S2", "E1", "f_unit"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    assert a.mistuning == b.mistuning == tuple(DELTA)


def test_only_the_blade_blocks_change_by_their_factor(tuned):
    m = build_model(mistuning=DELTA)
    dK = m.K - tuned.K
    s0, nb = tuned.slices["blades"].start, 2
    for j, d in enumerate(DELTA):
        sl = slice(s0 + j * nb, s0 + (j + 1) * nb)
        np.testing.assert_allclose(dK[sl, sl], d * tuned.K[sl, sl], rtol=1e-14, atol=0)
        dK[sl, sl] = 0
    assert not dK.any()


def test_a_blades_frequencies_at_rest_scale_by_the_root_of_its_factor(tuned):
    """The clamped blade alone (its block, disk held): frequencies x sqrt(1 + delta), mass unchanged."""
    m = build_model(mistuning=DELTA)
    s0 = tuned.slices["blades"].start
    for j in (0, 4):
        sl = slice(s0 + 2 * j, s0 + 2 * j + 2)
        w0 = np.sqrt(np.linalg.eigvals(np.linalg.solve(tuned.M[sl, sl], tuned.K[sl, sl])).real)
        w1 = np.sqrt(np.linalg.eigvals(np.linalg.solve(m.M[sl, sl], m.K[sl, sl])).real)
        np.testing.assert_allclose(np.sort(w1), np.sort(w0) * np.sqrt(1 + DELTA[j]), rtol=1e-12)


def test_cyclic_blocks_merge_and_stay_exact(tuned):
    """The tuned reference splits into 7-dof blocks and smaller; a mistuned disk couples every blade wave
    with the shaft whirl into one block (30 dofs: shaft 10 + blades 20), and the block solver still gives the
    dense problem's eigenvalues."""
    m = build_model(mistuning=DELTA)
    assert max(len(b) for b in tuned.cyclic.blocks) == 7
    assert max(len(b) for b in m.cyclic.blocks) == 30
    for s in (0.0, 3.3):
        lam = np.linalg.eigvals(first_order(m, s * 53.4))
        lam = lam[lam.imag >= -1e-9]
        blocks = run_modes(m, s).eigenvalues
        np.testing.assert_allclose(np.sort(np.abs(blocks)), np.sort(np.abs(lam)), rtol=1e-9)


def test_bad_mistuning_is_one_line():
    with pytest.raises(ParameterError, match=r"mistuning: 3 values for 10 blades"):
        build_model(mistuning=[0.1, 0.2, 0.3])
    with pytest.raises(ParameterError, match=r"mistuning\[2\]: -1.5 out of range; accepted range \(-1, inf\)"):
        build_model(mistuning=[0, 0, -1.5, 0, 0, 0, 0, 0, 0, 0])


def test_frequency_scatter_and_neighbour_correlation():
    spec = MistuningSpec.from_table({"kind": "frequency", "sd": 0.02, "correlation": 0.6}, 10)
    u = np.random.default_rng(0).random((20000, 10))
    delta = spec.deviations(u)
    eps = np.sqrt(1 + delta) - 1
    assert eps.std() == pytest.approx(0.02 * 0.986, rel=0.02)  # truncnormal at 3 sd: sd x 0.9866
    assert np.abs(eps).max() <= 0.06 + 1e-12
    r = np.corrcoef(eps.T)
    assert np.mean([r[j, (j + 1) % 10] for j in range(10)]) == pytest.approx(0.6, abs=0.03)
    assert np.mean([r[j, (j + 2) % 10] for j in range(10)]) == pytest.approx(0.36, abs=0.03)
    with pytest.raises(ParameterError, match="support .* leaves the accepted range"):
        MistuningSpec.from_table({"sd": 0.02, "distribution": "normal"}, 10)


def test_amplification_factors_are_one_for_a_tuned_sample_and_move_with_mistuning():
    spec = json.dumps({"model": "rotorub", "params": to_dict(reference_parameters()), "formulation": "3D",
                       "speeds": [3.3], "quantities": ["amp_linear", "amp_contact", "amp_force"],
                       "targets": ["contact.g0"], "t_end": 1.5, "t_ramp": 1.0}, sort_keys=True)
    r = evaluate_chunk(spec, [[0.335e-3], [0.335e-3]], [np.zeros(10).tolist(), DELTA.tolist()])
    for k in ("amp_linear", "amp_contact", "amp_force"):
        assert r[k][0] == pytest.approx(1.0, abs=1e-12), k
        assert abs(r[k][1] - 1.0) > 1e-4, k


def test_blade_tip_deflection_is_the_blade_functions_at_the_tip(tuned):
    q = np.zeros(tuned.n_dofs)
    q[tuned.index("blade3.b1")] = 1e-3
    r = blade_tip_deflections(tuned, q)
    assert r[2] == pytest.approx(1e-3)  # the kept functions are scaled to a unit tip deflection (blades.py)
    assert np.count_nonzero(r) == 1


def test_stability_map_of_a_mistuned_disk_is_that_disks(tuned):
    """The maps' workers rebuild the model from its parameters: a mistuned model's deviations travel with the
    rows (analyses/maps.py), so its map is its own, cell by cell, and not the tuned disk's."""
    from rotorub_model.analyses.maps import run_stability_map
    from rotorub_model.analyses.stability import stability_indicators
    from rotorub_model.analyses.static import solve_static
    from rotorub_model.contact import make_contact

    m = build_model(mistuning=3 * DELTA)
    speeds, g0s = np.array([3.3]), np.array([0.2e-3, 0.335e-3])
    mp = run_stability_map(m, "3D", speeds, g0s, executor="serial", progress=False)
    tp = run_stability_map(tuned, "3D", speeds, g0s, executor="serial", progress=False)
    w = 3.3 * 53.4
    q = None
    for j in (1, 0):  # the map continues from the largest clearance down
        c = make_contact(m, "3D", g0=float(g0s[j]))
        st = solve_static(m, c, w, q0=q)
        q = st.q
        assert mp.max_real[0, j] == stability_indicators(m, c, w, st.q)[0]
    assert not np.array_equal(mp.max_real, tp.max_real)


def test_saved_mistuned_model_keeps_its_deviations(tmp_path):
    from rotorub_model.structure.model import load_model, save_model

    m = load_model(save_model(build_model(mistuning=DELTA), tmp_path / "m.npz"))
    assert m.mistuning == tuple(DELTA)
    assert load_model(save_model(build_model(), tmp_path / "t.npz")).mistuning is None
