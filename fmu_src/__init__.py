"""FMI side of rotorub: the pythonfmu slaves, what builds them, and the fmpy harnesses.

Kept apart from ``rotorub_model`` (which has no FMI dependency); needs the ``fmu`` extra.
"""
