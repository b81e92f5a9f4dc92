"""Masters that drive any FMU (over fmu_src/fmi/ only): fmpy FMI 2.0 (fmi2.py) and FMI 3.0 (fmi3.py) instances
addressed by name, the C hosts (hosts/, native_host.py), the cross-check kit's runs (crosscheck.py) and the
paper's analyses redone through an FMU (analyses.py)."""
