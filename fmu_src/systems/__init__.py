"""The engine system: the LP spool FMU, the coupled system's names and connections, its SSP package and a
fixed-step fmpy master."""
