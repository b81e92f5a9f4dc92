"""fmpy harnesses: a thin master over fmpy (fmi_run.py), the paper's analyses redone through the FMU
(analyses.py) and the FMU part of ``rotorub reproduce`` (reproduce.py)."""
