"""The engine system (over fmu_src/models/ and fmu_src/masters/): the coupled scenarios of the LP spool, the clearance
closure and the contact FMUs, their SSP packages, and a fixed-step fmpy master loop."""
