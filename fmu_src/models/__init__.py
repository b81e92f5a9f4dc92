"""One folder per FMU model (over fmu_src/fmi/ and the library), with the same file names in each: variables.py
(its one list of variables), model.c and model.h (the model in C), builder.py, crosscheck.py (its FMI cross-check
kit), FMU.md (its manual), and slave.py where it has a pythonfmu flavour."""
