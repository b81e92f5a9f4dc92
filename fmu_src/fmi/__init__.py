"""Building the FMUs: the pythonfmu flavour, the native C flavour, the binaries' checks, the cross-check kit
and the ``build-fmu`` command."""
