"""The FMU side of rotorub: the contact model, the LP spool and the clearance closure as FMI co-simulation FMUs
(native C FMI 2.0 and 3.0, pythonfmu), the masters that drive them, and the engine systems built of them.

Layers, each importing only those below it (docs/FMU-layout.md; held by tests/fmu/test_layout.py):
``fmi/`` (knows no model) < ``models/`` and ``masters/`` (never each other) < ``systems/`` < ``cli.py`` and
``reproduce.py``. Kept apart from ``rotorub_model``, which never imports it; needs the ``fmu`` extra.
"""
