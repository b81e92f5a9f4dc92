"""Shared fixtures of the verification suite (small and read-only)."""

from __future__ import annotations

import json
import math

import pytest

from rotorub_model.structure.model import build_model
from rotorub_model.structure.params import reference_parameters


@pytest.fixture(scope="session")
def undamped():
    """Reference model with every damper removed (for energy and time-step checks)."""
    p = reference_parameters()
    bearings = [{"name": b.name, "z": b.z, "k": b.k, "c": 0.0} for b in p.bearings]
    p = p.replace(bearings=bearings, blades={"damping_ratio": 0.0}, casing={"damping_ratio": 0.0},
                  suspension={"c_translation": 0.0, "c_rotation": 0.0})
    return build_model(p)


@pytest.fixture(scope="session")
def ref_params():
    """The embedded reference parameters (frozen dataclasses: safe to share)."""
    return reference_parameters()


@pytest.fixture(scope="session")
def ref_model(ref_params):
    """The 38-dof reference model; tests must not modify its arrays."""
    return build_model(ref_params)


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)  # shortest round-tripping form, valid TOML (1e-09, 2.1e+11, 0.5)
    if isinstance(v, str):
        return json.dumps(v)  # a TOML basic string
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {v!r} as TOML")


def to_toml(data: dict) -> str:
    """A tiny TOML writer for the nested dicts of ``rotorub_model.structure.params.to_dict``."""
    lines: list[str] = []
    for sec, val in data.items():
        for table in val if isinstance(val, list) else [val]:
            lines.append(f"[[{sec}]]" if isinstance(val, list) else f"[{sec}]")
            lines += [f"{k} = {_toml_value(x)}" for k, x in table.items()]
            lines.append("")
    return "\n".join(lines)


@pytest.fixture
def write_params(tmp_path):
    """write_params(data, name="params.toml") -> path of a TOML file holding ``data``."""

    def write(data: dict, name: str = "params.toml"):
        path = tmp_path / name
        path.write_text(to_toml(data))
        return path

    return write
