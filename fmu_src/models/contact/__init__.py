"""RotorCasingContact: the blade-tip / casing contact FMU (native C FMI 2.0 and 3.0, pythonfmu)."""
