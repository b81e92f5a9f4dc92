"""Where the offset casing's known answer holds (docs/THEORY.md §4.1, issue 25.10): a casing moved by e over a rotor
without imbalance wears where the gap is smallest, the rigid closed form -(g0 + e cos θ) - F_y/k_r its depth.

    python benchmarks/offset_wear.py

Prints, for 2D and 3D, 0.5 and 1 Ω_ref, μ = 0, 0.12 (the reference's) and 0.3: the deepest cut against the closed
form, the worn arc against the rigid arc, and the fan disk's peak-to-peak over the run's second half (a
friction-driven whirl shows there). g0 = 0.2 mm, e = 0.3 mm, the offset applied at t = 0 (a step), 1 s runs.
"""

from __future__ import annotations

import numpy as np

from rotorub_model.analyses.transient import run_transient
from rotorub_model.contact import make_contact
from rotorub_model.contact.liner import Liner
from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters


def case(form: str, speed: float, mu: float, t_end: float = 1.0, g0: float = 0.2e-3, e: float = 0.3e-3) -> str:
    p = reference_parameters().replace(contact={"mu": mu})
    m = build_model(p)
    c = make_contact(m, form, g0=g0)
    liner = Liner.for_model(m, c, wears=True, offset=(e, 0.0))
    r = run_transient(m, c, speed * p.normalisation.omega_ref, t_end=t_end, me=0.0, t_ramp=0.0, liner=liner)
    th = liner.angles
    exact = np.maximum(-(g0 + e * np.cos(th)) - liner.yield_force / p.contact.k_r, 0.0)
    prof = liner.profile
    cell = 360.0 / len(th)
    half = r.t > 0.5 * r.t[-1]
    ptp = float(np.max(np.ptp(r.outputs["disk_fixed"][half], axis=0))) * 1e6
    rel = 100 * (prof.max() / exact.max() - 1)
    return (f"| {form} | {speed:g} | {mu:g} | {prof.max() * 1e6:.2f} µm ({rel:+.1f} %) "
            f"| {(prof > 0).sum() * cell:.0f}° / {(exact > 0).sum() * cell:.0f}° | {ptp:.1f} µm |")


def main() -> None:
    print("| formulation | Ω / Ω_ref | μ | deepest cut (vs the rigid closed form, 33.3 µm) | worn arc / rigid arc | "
          "fan disk peak-to-peak, second half |")
    print("|---|---|---|---|---|---|")
    for form, speed, mu in [("2D", 1.0, 0.0), ("2D", 1.0, 0.12), ("2D", 0.5, 0.0), ("2D", 0.5, 0.12),
                            ("3D", 1.0, 0.0), ("3D", 1.0, 0.12), ("3D", 0.5, 0.0), ("3D", 0.5, 0.12),
                            ("3D", 0.5, 0.3)]:
        print(case(form, speed, mu), flush=True)


if __name__ == "__main__":
    main()
