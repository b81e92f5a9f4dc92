"""Regenerate the golden results the kernel refactor is held to (tests/library/test_golden.py).

    python tests/library/golden/make_golden.py    # writes tests/library/golden/golden.npz

What is saved (reference configuration, numbers only, no plots):

* ``tr_{2D,3D}_*``: the paper's section-6 transients at the fact-6 point
  (Omega = 3.3 omega_ref, g0 = 0.334 mm), imbalance ramped over 1 s, 2.5 s, recorded every
  5 ms: time, states q and every output of :func:`run_transient`;
* ``hold_3D_*``: the same 3D run as a co-simulation master drives it
  (``run_transient(hold=1 ms)``), the path the FMU reproduces;
* ``runup_*``: a 3D run-up through the first critical (2.6 -> 4.4 omega_ref in 3 s,
  g0 = 1 mm, full imbalance from t = 0), with the Euler terms (library path) and held
  (``hold=1 ms``, FMU path);
* ``static_{2D,3D}_*``: balanced static solutions on a 4 x 4 (Omega, g0) grid around the
  first critical: q, convergence flag, residual, blades in contact, largest eigenvalue
  real part and the sum of positive real parts;
* ``laws_{2D,3D}_*``: contact forces, Jacobian and outputs at states taken from the
  transients (the contact law and its derivatives on their own);
* ``det_*``: detection closures of every studied configuration on a small speed grid.

The file is written by whatever code is installed: regenerate it only when a change of
the physics is intended, and say in the commit what moved and why.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
FACT6 = (3.3, 0.334e-3)  # normalised speed, g0 [m]: the fact-6 point of the reference (docs/THEORY.md 6.7)
STATIC_SPEEDS = (3.0, 3.3, 3.5, 3.8)
STATIC_G0 = (0.1e-3, 0.3e-3, 0.6e-3, 1.0e-3)
RUNUP = dict(speed_from=2.6, speed_to=4.4, duration=3.0, g0=1.0e-3)


def _runup_omega(w_ref: float):
    a, b, d = RUNUP["speed_from"], RUNUP["speed_to"], RUNUP["duration"]
    return lambda t: w_ref * (a + (b - a) * min(max(t / d, 0.0), 1.0))


def _transient_arrays(prefix: str, r) -> dict[str, np.ndarray]:
    out = {f"{prefix}_t": r.t, f"{prefix}_q": r.q, f"{prefix}_omega": r.omega}
    for k, v in r.outputs.items():
        out[f"{prefix}_{k}"] = v
    return out


def compute() -> dict[str, np.ndarray]:
    """Every golden array, computed with the installed library."""
    from rotorub_model.analyses.detection import run_detection
    from rotorub_model.analyses.stability import stability_of
    from rotorub_model.analyses.static import solve_static
    from rotorub_model.analyses.transient import run_transient
    from rotorub_model.contact import make_contact
    from rotorub_model.structure.model import build_model

    m = build_model()
    w_ref = m.params.normalisation.omega_ref
    speed, g0 = FACT6
    data: dict[str, np.ndarray] = {}
    for f in ("2D", "3D"):
        r = run_transient(m, make_contact(m, f, g0=g0), speed * w_ref, t_end=2.5, record_dt=5e-3)
        data.update(_transient_arrays(f"tr_{f}", r))
        # contact law on its own, at states the transient visits (contact on 0..3 blades)
        c = make_contact(m, f, g0=g0)
        states = r.q[:: max(1, len(r.q) // 12)]
        data[f"laws_{f}_q"] = states
        data[f"laws_{f}_force"] = np.array([c.forces(q, speed * w_ref) for q in states])
        data[f"laws_{f}_jac"] = np.array([c.jacobian(q, speed * w_ref) for q in states])
        data[f"laws_{f}_laws"] = np.array([c.laws(q)[:, :7] for q in states])  # the potential (column 8) came later
        outs = [c.outputs(q, speed * w_ref) for q in states]
        data[f"laws_{f}_casing_force"] = np.array([o["casing_force"] for o in outs])
        data[f"laws_{f}_friction_torque"] = np.array([o["friction_torque"] for o in outs])
    r = run_transient(m, make_contact(m, "3D", g0=g0), speed * w_ref, t_end=2.5, record_dt=5e-3, hold=1e-3)
    data.update(_transient_arrays("hold_3D", r))

    om = _runup_omega(w_ref)
    c = make_contact(m, "3D", g0=RUNUP["g0"])
    r = run_transient(m, c, om, t_end=RUNUP["duration"], t_ramp=0.0, record_dt=5e-3)
    data.update(_transient_arrays("runup", r))
    r = run_transient(m, c, om, t_end=RUNUP["duration"], t_ramp=0.0, record_dt=5e-3, hold=1e-3)
    data.update(_transient_arrays("runup_hold", r))

    for f in ("2D", "3D"):
        qs, conv, res, nc, mx, sp = [], [], [], [], [], []
        for s in STATIC_SPEEDS:
            for g in STATIC_G0:
                c = make_contact(m, f, g0=g)
                st = solve_static(m, c, s * w_ref)
                stab = stability_of(m, c, s * w_ref, st.q)
                qs.append(st.q)
                conv.append(st.converged)
                res.append(st.residual)
                nc.append(st.n_contact)
                mx.append(stab.max_real)
                sp.append(stab.sum_positive_real)
        data[f"static_{f}_q"] = np.array(qs)
        data[f"static_{f}_converged"] = np.array(conv)
        data[f"static_{f}_residual"] = np.array(res)
        data[f"static_{f}_n_contact"] = np.array(nc)
        data[f"static_{f}_max_real"] = np.array(mx)
        data[f"static_{f}_sum_positive_real"] = np.array(sp)

    det = run_detection(m, n_speeds=60, n_g0=10, progress=False)
    data["det_speeds"] = det.speeds
    for label, cl in det.closures.items():
        data[f"det_{label}"] = cl
    return data


def main(argv: list[str] | None = None) -> int:
    path = Path(argv[0]) if argv else HERE / "golden.npz"
    t = time.perf_counter()
    data = compute()
    np.savez_compressed(path, **data)
    print(f"wrote {path} ({len(data)} arrays, {path.stat().st_size / 1e6:.2f} MB) in {time.perf_counter() - t:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
