"""Parameter files: the reference, round trips, and one clear error per kind of bad input.

Files are written by the suite's own tiny TOML writer (``write_params`` in conftest.py).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from rotorub_model.errors import ParameterError
from rotorub_model.structure.params import Parameters, load_parameters, reference_parameters, to_dict


def load_error(write_params, data: dict) -> str:
    path = write_params(data)
    with pytest.raises(ParameterError) as info:
        load_parameters(path)
    msg = str(info.value)
    assert "\n" not in msg, f"error message must be one line: {msg!r}"
    assert str(path) in msg, f"error message must name the file: {msg!r}"
    return msg


# ---------------------------------------------------------------------------
# the reference
# ---------------------------------------------------------------------------


def test_reference_loads_and_matches_the_paper_layout():
    p = load_parameters(None)
    assert isinstance(p, Parameters)
    assert p == reference_parameters()
    # the paper's 38 dofs: 2 x 5 shaft, 10 blades x 2, casing 2 translations + 2 tilts + ring n = 2, 3
    assert p.shaft.n_ritz == 5 and p.blades.count == 10 and p.blades.n_ritz == 2
    assert p.casing.modes == (2, 3)
    n_dofs = 2 * p.shaft.n_ritz + p.blades.count * p.blades.n_ritz + 4 + 2 * len(p.casing.modes)
    assert n_dofs == 38
    assert len(p.disks) >= 2 and p.fan_disk.name == p.imbalance.disk
    # documented derived values (MODEL-NOTES section 6): tip radius 1.0 m, 5.8 kg per blade,
    # first flap at rest about 25 Hz (beta_1 L = 1.8751041)
    b = p.blades
    assert b.tip_radius == pytest.approx(1.0, rel=1e-12)
    assert b.mass == pytest.approx(4430.0 * 0.2 * 0.011 * 0.6, rel=1e-12)
    assert 5.7 < b.mass < 5.9
    f1 = 1.8751041**2 * np.sqrt(b.E * b.second_moment / (b.rho * b.area * b.length**4)) / (2 * np.pi)
    assert 24.0 < f1 < 26.0, f1


def test_shaft_section_properties():
    s = reference_parameters().shaft
    assert s.area == pytest.approx(np.pi / 4 * (0.136**2 - 0.1065**2), rel=1e-14)
    assert s.second_moment == pytest.approx(np.pi / 64 * (0.136**4 - 0.1065**4), rel=1e-14)


# ---------------------------------------------------------------------------
# round trips
# ---------------------------------------------------------------------------


def test_reference_round_trips_through_a_user_file(write_params):
    p = reference_parameters()
    path = write_params(to_dict(p))
    assert load_parameters(path) == p
    assert load_parameters(str(path)) == p


def test_modified_parameters_round_trip(write_params):
    p = reference_parameters().replace(
        shaft={"n_ritz": 7},
        blades={"count": 12, "stagger_deg": 90.0, "n_ritz": 4},
        casing={"modes": [2, 3, 4], "z_cg": -0.35},
        contact={"g0": -2.5e-4},
        imbalance={"disk": "lpt", "angle_deg": -90.0},
    )
    q = load_parameters(write_params(to_dict(p)))
    assert q == p
    assert q.casing.modes == (2, 3, 4) and q.contact.g0 == -2.5e-4 and q.fan_disk.name == "lpt"


def test_integral_float_accepted_for_integer_field(write_params):
    data = to_dict(reference_parameters())
    data["shaft"]["n_ritz"] = 6.0
    p = load_parameters(write_params(data))
    assert p.shaft.n_ritz == 6 and isinstance(p.shaft.n_ritz, int)


# ---------------------------------------------------------------------------
# errors: one ParameterError naming the field and the accepted range / values
# ---------------------------------------------------------------------------


def _set(path: tuple, value):
    def mutate(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value

    return mutate


def _delete(path: tuple):
    def mutate(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        del target[path[-1]]

    return mutate


ERROR_CASES = {
    # name: (mutation, substrings the message must contain)
    "missing field": (_delete(("shaft", "E")), ["shaft.E", "missing"]),
    "missing section": (_delete(("casing",)), ["casing", "missing"]),
    "missing list": (_delete(("bearings",)), ["bearings", "missing"]),
    "unknown field": (_set(("blades", "colour"), "red"), ["blades.colour", "unknown field", "accepted fields"]),
    "unknown list field": (_set(("disks", 0, "radius"), 0.3), ["disks[0].radius", "unknown field"]),
    "unknown section": (_set(("rotor",), {"speed": 1.0}), ["rotor", "unknown section", "accepted", "shaft"]),
    "nan": (_set(("shaft", "E"), math.nan), ["shaft.E", "not finite", "range", "(0, inf)"]),
    "inf": (_set(("bearings", 0, "k"), math.inf), ["bearings[0].k", "not finite", "range"]),
    "minus inf": (_set(("casing", "z_cg"), -math.inf), ["casing.z_cg", "not finite"]),
    "nan integer": (_set(("blades", "count"), math.nan), ["blades.count", "[3, 200]"]),
    "negative length": (_set(("blades", "length"), -0.6), ["blades.length", "out of range", "range (0, inf)"]),
    "zero density": (_set(("shaft", "rho"), 0.0), ["shaft.rho", "out of range", "(0, inf)"]),
    "negative damping": (_set(("bearings", 1, "c"), -1.0), ["bearings[1].c", "out of range", "[0, inf)"]),
    "too large": (_set(("blades", "stagger_deg"), 95.0), ["blades.stagger_deg", "out of range", "[0, 90]"]),
    "inner >= outer": (_set(("shaft", "inner_diameter"), 0.136), ["shaft.inner_diameter", "shaft.outer_diameter"]),
    "blade count 2": (_set(("blades", "count"), 2), ["blades.count", "out of range", "[3, 200]"]),
    "coincident bearings": (_set(("bearings", 1, "z"), 0.52), ["bearings", "position of its own"]),
    "n_ritz 2.5": (_set(("blades", "n_ritz"), 2.5), ["blades.n_ritz", "integer", "[1, 12]"]),
    "n_ritz too many": (_set(("shaft", "n_ritz"), 15), ["shaft.n_ritz", "range", "[2, 14]"]),
    "string number": (_set(("shaft", "length"), "2.66"), ["shaft.length", "expected a number"]),
    "bool number": (_set(("blades", "count"), True), ["blades.count", "expected a number"]),
    "ring mode 1": (_set(("casing", "modes"), [1, 2]), ["casing.modes", "accepted", ">= 2"]),
    "repeated ring mode": (_set(("casing", "modes"), [2, 2]), ["casing.modes", "repeated"]),
    "unknown imbalance disk": (_set(("imbalance", "disk"), "hp"), ["imbalance.disk", "accepted", "fan", "lpt"]),
    "bearing beyond shaft": (_set(("bearings", 1, "z"), 3.0), ["bearings[1].z", "out of range", "shaft.length"]),
    "one bearing": (lambda d: d["bearings"].pop(), ["bearings", "two or more"]),
    "inertia triangle": (_set(("disks", 0, "Ip"), 20.0), ["Ip", "range", "2*Id"]),
    "thickness > width": (_set(("blades", "thickness"), 0.3), ["blades.thickness", "blades.width"]),
    "chord too long": (_set(("contact", "chord"), 2.5), ["contact.chord", "range"]),
    "interference too deep": (_set(("contact", "g0"), -0.4), ["contact.g0", "range"]),
    "g0 in mm": (_set(("contact", "g0"), 0.5), ["contact.g0", "0.5 m out of range", "0.1] m", "0.5e-3"]),
}


@pytest.mark.parametrize("case", list(ERROR_CASES))
def test_bad_value_raises_parameter_error_naming_the_field(write_params, case):
    mutate, expected = ERROR_CASES[case]
    data = copy.deepcopy(to_dict(reference_parameters()))
    mutate(data)
    msg = load_error(write_params, data)
    for text in expected:
        assert text in msg, f"{case}: {text!r} not in {msg!r}"


def test_unreadable_file(tmp_path):
    missing = tmp_path / "does-not-exist.toml"
    with pytest.raises(ParameterError, match="does-not-exist.toml.*cannot be read"):
        load_parameters(missing)
    with pytest.raises(ParameterError, match="cannot be read"):
        load_parameters(tmp_path)  # a directory


def test_invalid_toml(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[shaft]\nE = = 2.1e11\n")
    with pytest.raises(ParameterError, match="broken.toml.*not valid TOML") as info:
        load_parameters(path)
    assert "\n" not in str(info.value)


def test_replace_validates_again():
    p = reference_parameters()
    with pytest.raises(ParameterError, match="shaft.E.*range"):
        p.replace(shaft={"E": -1.0})
    with pytest.raises(ParameterError, match="unknown section 'rotor'"):
        p.replace(rotor={"E": 1.0})
    with pytest.raises(ParameterError, match="blades.chord_len: unknown field"):
        p.replace(blades={"chord_len": 0.2})
    assert p.replace(contact={"g0": 2e-3}).contact.g0 == 2e-3
    assert reference_parameters().contact.g0 == 1e-3, "replace must not modify the reference"
