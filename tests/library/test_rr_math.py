"""The kernel's own elementary functions (rotorub_model/kernel/rr_math.h), against the C library's.

They exist so that every platform's binary computes the same bits (glibc, the Microsoft CRT and Apple's libm
differ in the last bit); they must still be as accurate as a libm. Reference: numpy (glibc's libm here),
itself within an ulp of the exact values; the bounds below are what the header promises.
"""

import numpy as np
import pytest

from rotorub_model import kernel

RNG = np.random.default_rng(20261201)


def ulps(got: np.ndarray, ref: np.ndarray) -> np.ndarray:
    return np.abs(got - ref) / np.spacing(np.abs(ref))


@pytest.mark.parametrize("name, lo, hi, bound", [
    ("sin", -7.0, 7.0, 1.0), ("sin", -1e4, 1e4, 1.0), ("sin", -1e6, 1e6, 1.0),  # spin angles of long runs
    ("cos", -7.0, 7.0, 1.0), ("cos", -1e6, 1e6, 1.0),
    ("tan", -1.5, 1.5, 2.0),
    ("tanh", -0.6, 0.6, 2.0), ("tanh", -30.0, 30.0, 2.0),  # the friction law's v / v_slip
    ("exp", -700.0, 700.0, 1.0), ("exp", -1.0, 1.0, 1.0),
])
def test_within_ulps_of_libm(name, lo, hi, bound):
    x = RNG.uniform(lo, hi, 200_000)
    u = ulps(kernel.elementary(name, x), getattr(np, name)(x))
    assert u.max() <= bound, f"{name} on [{lo}, {hi}]: {u.max()} ulp"
    assert np.mean(u > 0) < 0.5  # mostly the correctly rounded value, as a good libm


def test_atan2_all_quadrants():
    y, x = RNG.uniform(-2, 2, 200_000), RNG.uniform(-2, 2, 200_000)
    u = ulps(kernel.elementary("atan2", y, x), np.arctan2(y, x))
    assert u.max() <= 4.0


def test_reduction_near_multiples_of_half_pi():
    """The hard arguments of sin/cos: the doubles at and next to k pi/2, where the reduced argument is tiny
    and a reduction with too few bits of pi/2 loses the whole result (1000 ulp with a careless sum order)."""
    k = np.arange(1, 200_001, dtype=float)
    x = k * (np.pi / 2)
    x = np.concatenate([x, np.nextafter(x, 0), np.nextafter(x, np.inf)])
    for name in ("sin", "cos"):
        u = ulps(kernel.elementary(name, x), getattr(np, name)(x))
        assert u.max() <= 1.0, f"{name}: {u.max()} ulp at x = {x[np.argmax(u)]!r}"


def test_exact_ones():
    x = RNG.uniform(-1e3, 1e3, 50_000)
    x[:8] = [0.5, -0.5, 2.5, -2.5, 0.0, -0.0, 1e300, -7.0]
    assert np.array_equal(kernel.elementary("sqrt", np.abs(x)), np.sqrt(np.abs(x)))  # correctly rounded
    assert np.array_equal(kernel.elementary("floor", x), np.floor(x))
    assert np.array_equal(kernel.elementary("ceil", x), np.ceil(x))


def test_special_values():
    sp = np.array([0.0, -0.0, np.inf, -np.inf, np.nan])
    with np.errstate(invalid="ignore"):
        for name in ("sin", "cos", "tanh", "exp"):
            got, ref = kernel.elementary(name, sp), getattr(np, name)(sp)
            assert np.array_equal(got, ref, equal_nan=True), name
            assert np.array_equal(np.signbit(got[:2]), np.signbit(ref[:2])), name  # sin(-0) = -0
    assert kernel.elementary("tanh", np.array([1e-300]))[0] == 1e-300
    assert kernel.elementary("exp", np.array([710.0]))[0] == np.inf
    zeros = np.array([0.0, -0.0, 0.0, -0.0])
    signs = np.array([0.0, 0.0, -0.0, -0.0])
    assert np.array_equal(kernel.elementary("atan2", zeros, signs), np.arctan2(zeros, signs))


def test_unknown_function_is_refused():
    with pytest.raises(ValueError, match="accepted: sin"):
        kernel.elementary("log", np.ones(2))
