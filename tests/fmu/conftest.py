"""Fixtures of the FMU tests: the contact FMUs built once from the working tree (read-only). The library's shared
fixtures (ref_params, ref_model, ...) come from tests/conftest.py."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def contact_fmu(tmp_path_factory):
    """RotorCasingContact.fmu built once from the working tree for every FMU test (read-only)."""
    pytest.importorskip("pythonfmu", reason="building the FMU needs pythonfmu (pip install -e '.[fmu]')")
    from fmu_src.models.contact.builder import build_fmu

    return build_fmu(tmp_path_factory.mktemp("contact_fmu"), platforms=("linux64",))["fmu"]


@pytest.fixture(scope="session")
def native_fmu(tmp_path_factory):
    """The native (C) RotorCasingContact.fmu built once from the working tree, linux64 only."""
    pytest.importorskip("fmpy", reason="the native build takes the FMI headers from fmpy (pip install -e '.[fmu]')")
    from fmu_src.models.contact.builder import build_native_fmu

    return build_native_fmu(tmp_path_factory.mktemp("native_fmu"), platforms=("linux64",))["fmu"]


@pytest.fixture(scope="session", params=["pythonfmu", "native"])
def any_fmu(request):
    """Each flavour of RotorCasingContact.fmu in turn (same interface, same numbers)."""
    return request.getfixturevalue("contact_fmu" if request.param == "pythonfmu" else "native_fmu")
