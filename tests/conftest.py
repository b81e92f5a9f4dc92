"""Shared fixtures of the verification suite (small and read-only)."""

from __future__ import annotations

import pytest

from rotorub_model.model import build_model
from rotorub_model.params import reference_parameters


@pytest.fixture(scope="session")
def ref_params():
    """The embedded reference parameters (frozen dataclasses: safe to share)."""
    return reference_parameters()


@pytest.fixture(scope="session")
def ref_model(ref_params):
    """The 38-dof reference model; tests must not modify its arrays."""
    return build_model(ref_params)
