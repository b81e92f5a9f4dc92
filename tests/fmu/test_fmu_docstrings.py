"""The docstring examples of fmu_src run (those that need a built FMU say +SKIP)."""

from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULES = sorted(".".join(p.relative_to(ROOT).with_suffix("").parts) for p in (ROOT / "fmu_src").rglob("*.py")
                 if ">>>" in p.read_text() and "slave" not in p.name)


def test_there_are_examples():
    assert "fmu_src.fmi.variables" in MODULES and "fmu_src.fmi.csource" in MODULES


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, name
