"""LPSpool: the speed of a turbofan's low-pressure spool (native C; pythonfmu, the example of a slave in Python)."""
