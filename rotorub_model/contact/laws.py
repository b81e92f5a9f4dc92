"""The normal contact laws, as named data with one dispatch (the kernel's ``rr_laws.c``).

A law is a name, the kernel's id and the names of its parameters (fields of ``[contact]`` in the parameter file,
whose ranges are declared once in :mod:`rotorub_model.structure.params`). Everything derived from a law — the
force, the moment and their derivatives along the chord, the potential the energy checks use, the largest slope
that sets the explicit scheme's step, the liner's return map — is computed by the kernel, for the library and
both FMUs. Adding a law: its id and its ramps in ``rr_laws.c`` (and, if it is not piecewise linear, its return map
in ``rr_liner.c``), a row here, its parameters in ``ContactParams``.

>>> from rotorub_model.structure.params import reference_parameters
>>> law_params(reference_parameters().contact)
()
>>> law_params(reference_parameters().replace(contact={"law": "bilinear"}).contact)
(0.0005, 4.0)
"""

from __future__ import annotations

from typing import Any

from .. import kernel

# name -> the ``[contact]`` fields that are its parameters, in the kernel's order (rotorub_kernel.h)
LAWS: dict[str, tuple[str, ...]] = {
    "penalty": (),                              # F = k_r delta: the paper's
    "bilinear": ("knee", "stiffness_ratio"),    # F = k_r delta + (ratio - 1) k_r (delta - knee)_+
}
assert set(LAWS) == set(kernel.LAW_IDS)


def law_params(contact: Any) -> tuple[float, ...]:
    """The parameters of ``contact.law`` (a ContactParams, or anything with those fields) in the kernel's order."""
    return tuple(float(getattr(contact, name)) for name in LAWS[contact.law])


def law_record(name: str, params: tuple[float, ...]) -> kernel.RRLaw:
    """The kernel's record of law ``name``, checked by the kernel."""
    rec = kernel.make_law(name, params)
    if kernel.load().rr_law_check(rec) != 0:
        raise ValueError(f"law {name}: parameters {params} refused by the kernel")
    return rec


def max_slope(name: str, params: tuple[float, ...]) -> float:
    """The law's largest slope over its penetrations, per unit k_r (what the explicit step must assume)."""
    import ctypes

    return float(kernel.load().rr_law_max_slope(ctypes.byref(law_record(name, params))))


def knee_note(contact: Any, deepest_penetration: float) -> str:
    """A sentence when a law's change of slope was never reached, so the results are those of its first branch
    (the penalty law's) and a reader should not take them for the law's effect; "" otherwise (or for a law without
    a knee). ``contact``: the ``[contact]`` parameters; ``deepest_penetration`` [m]: the largest -gap of the run.

    >>> from rotorub_model.structure.params import reference_parameters
    >>> c = reference_parameters().replace(contact={"law": "bilinear", "knee": 3e-4}).contact
    >>> for part in knee_note(c, 27e-6).split(": "):
    ...     print(part)
    the bilinear law's knee (0.3 mm) was never reached (deepest penetration 0.027 mm)
    these are the penalty law's results
    >>> knee_note(c, 4e-4)
    ''
    >>> knee_note(c, -0.0)
    "the bilinear law's knee (0.3 mm) was never reached: no blade touched the casing, the contact law played no part"
    """
    if "knee" not in LAWS[contact.law] or deepest_penetration >= contact.knee:
        return ""
    if deepest_penetration <= 0.0:
        # no penetration at all: "deepest penetration -0 mm" (a clamped -0.0) read as a number gone wrong, and
        # "the penalty law's results" as if the contact had acted
        return (f"the {contact.law} law's knee ({contact.knee * 1e3:.3g} mm) was never reached: no blade touched "
                "the casing, the contact law played no part")
    return (f"the {contact.law} law's knee ({contact.knee * 1e3:.3g} mm) was never reached (deepest penetration "
            f"{deepest_penetration * 1e3:.3g} mm): these are the penalty law's results")
