"""Timing of the contact detection maps (prints numbers; not a test).

    /work/venv/bin/python benchmarks/bench_detection.py

* linear responses q(Omega) on 400 speeds (one batched solve), and the per-speed
  loop over rotorub_model.analyses.linear.linear_response for comparison;
* one 400 x 400 (Omega, g0) boolean map for one formulation once q(Omega) is known:
  the closure c(Omega) = max_p -(G_p q) and the comparison g0 < c(Omega)
  (target < 1 s), with and without building the contact model;
* the brute-force map (every gap of ContactModel.gaps at every (Omega, g0)) on a
  small grid, to show what the closed form saves;
* the whole run_detection study (every formulation and sweep, no figures).
"""

from __future__ import annotations

import numpy as np
from timing import best_of

from rotorub_model.analyses.detection import closure, contact_map, linear_responses, run_detection
from rotorub_model.analyses.linear import linear_response
from rotorub_model.contact import make_contact
from rotorub_model.structure.model import build_model


def main() -> None:
    model = build_model()
    wref = model.params.normalisation.omega_ref
    speeds = np.linspace(0.05, 10.0, 400)
    omegas = speeds * wref

    t_batch = best_of(lambda: linear_responses(model, omegas))
    t_loop = best_of(lambda: [linear_response(model, w) for w in omegas], repeat=3)
    Q = linear_responses(model, omegas)
    print(f"linear responses, 400 speeds, batched solve         : {t_batch * 1e3:8.2f} ms")
    print(f"linear responses, 400 speeds, linear_response loop  : {t_loop * 1e3:8.2f} ms")

    for form in ("2D", "3D"):
        c = make_contact(model, form)
        cl = closure(c, Q)
        g0 = np.linspace(0.0, 1.05 * cl.max(), 400)

        def only_map(c=c, g0=g0):
            return contact_map(closure(c, Q), g0)

        def with_contact(form=form, g0=g0):
            return contact_map(closure(make_contact(model, form), Q), g0)

        m = only_map()
        assert m.shape == (400, 400)
        t_map = best_of(only_map, repeat=20)
        t_full = best_of(with_contact, repeat=5)
        ok = "OK" if t_full < 1.0 else "SLOW"
        print(f"{form} map 400 x 400 (q known)                          : {t_map * 1e3:8.3f} ms")
        print(f"{form} map 400 x 400 incl. make_contact                 : {t_full * 1e3:8.3f} ms  (target < 1 s: {ok})")

    c = make_contact(model, "3D")
    sub = Q[::20]
    g0s = np.linspace(0.0, 5e-3, 20)

    def brute():
        return np.array([[np.any(c.with_clearance(g).gaps(q) < 0) for g in g0s] for q in sub])

    t_brute = best_of(brute, repeat=2)
    assert np.array_equal(brute(), contact_map(closure(c, sub), g0s))
    print(f"3D brute-force map 20 x 20 via ContactModel.gaps    : {t_brute * 1e3:8.2f} ms "
          f"(~{t_brute / 400 * 160000:.2f} s extrapolated to 400 x 400)")

    t_study = best_of(lambda: run_detection(model, progress=False), repeat=3)
    print(f"run_detection (all studies, ~560 speeds, no plots)  : {t_study * 1e3:8.2f} ms")


if __name__ == "__main__":
    main()
