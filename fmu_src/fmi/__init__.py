"""The FMI layer, which knows no model: one variable record for FMI 2.0 and 3.0 (variables.py), one model-description
writer (description.py), the generated C tables (csource.py), packaging and GUIDs (package.py, pythonfmu.py),
compilation and cross-compilation (compile.py), what a binary exports (binaries.py), and the C wrappers over the
shared core (c/)."""
