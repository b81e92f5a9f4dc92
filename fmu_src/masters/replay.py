"""Replaying an FMU's own reference experiments (FMI-LS-REF, fmu_src/fmi/lsref.py) in a chosen importer:
``rotorub fmu-check FMU [--host fmpy|fmusim|libcosim|ecos]``, one line per experiment.

Each host is an importer nobody here wrote, driven as its users drive it: fmpy's ``simulate_fmu`` (FMI 2.0 and
3.0), fmusim 0.0.39 (the Modelica Association's reference importer, built from ../shared/hosts: fmusim_host.py),
OSP libcosim through libcosimpy (FMI 2.0) and ecos through ecospy (FMI 2.0 and 3.0 scalars: ecos_host.py). Every
host gets the experiment's parameters as start values, its stimuli as inputs held over each step, and records
the reference's outputs; :func:`fmu_src.fmi.lsref.compare` judges.

What a host cannot do is said, not failed: libcosim and ecos ignore enumerations (an experiment that sets one is
``not run``, with the reason), ecos reads no FMI 3.0 array (those columns are left out, with the reason).
``swap``: the host is handed two inputs the wrong way round (a mis-wired connection), to show that the
experiments see it.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..fmi import lsref
from ..fmi.description import enumerations, read_description
from .crosscheck import libcosim_table

HOSTS = ("fmpy", "fmusim", "libcosim", "ecos")
_ELEMENT = re.compile(r"^(.*)\[(\d+)\]$")


@dataclass
class Outcome:
    """One experiment in one host."""

    experiment: str
    verdict: str  # "passed", "FAILED", "not run"
    detail: str
    diffs: dict[str, float] = field(default_factory=dict)
    seconds: float = 0.0

    def line(self) -> str:
        return f"{self.experiment:<14} {self.verdict:<8} {self.detail}"


def host_version(host: str) -> str:
    """The importer's version (a folder name of the compatibility information): fmusim's source tag, the others'
    distribution's (libcosimpy and ecospy bundle the engine of their own release)."""
    from importlib.metadata import version

    from . import fmusim_host

    return fmusim_host.VERSION if host == "fmusim" else \
        version({"fmpy": "fmpy", "libcosim": "libcosimpy", "ecos": "ecospy"}[host])


def host_unavailable(host: str) -> str | None:
    """None when ``host`` can run here, else why not (one line)."""
    if host not in HOSTS:
        return f"host '{host}' unknown; accepted: {', '.join(HOSTS)}"
    if host == "fmusim":
        from . import fmusim_host

        return fmusim_host.available()
    if host == "ecos":
        from . import ecos_host

        return ecos_host.available()
    module = {"fmpy": "fmpy", "libcosim": "libcosimpy"}[host]
    try:
        __import__(module)
    except Exception as exc:  # an import that fails for any reason (a missing system library) means: not here
        return f"{module} cannot be imported ({exc.__class__.__name__}: {exc})"
    return None


def _start_values(variables: dict, root, e: lsref.RefExperiment, fmu_name: str) -> dict[str, float | int]:
    """The experiment's parameters as the FMU takes them (an enumeration's item name -> its value)."""
    enums = enumerations(root)
    out: dict[str, float | int] = {}
    for name, v in e.parameters.items():
        var = variables.get(name)
        if var is None:
            raise lsref.ExperimentError(f"experiment {e.name}: parameter '{name}' is not a variable of {fmu_name}")
        if isinstance(v, str):
            items = dict(enums.get(var.declared_type or "", []))
            if v not in items:
                raise lsref.ExperimentError(f"experiment {e.name}: {name} = '{v}' is not an item of "
                                            f"{var.declared_type}; accepted: {', '.join(items)}")
            out[name] = items[v]
        else:
            out[name] = v
    return out


def _run_fmpy(fmu: Path, start: dict, inputs: dict[str, np.ndarray], outputs: list[str], e) -> dict:
    from fmpy import simulate_fmu

    names = [c for c in inputs if c != "time"]
    table = np.array(list(zip(*(inputs[c] for c in ["time", *names]))),
                     dtype=[("time", "f8")] + [(c, "f8") for c in names])
    recorded = list(dict.fromkeys(_ELEMENT.match(o).group(1) if _ELEMENT.match(o) and o not in names else o
                                  for o in outputs))
    r = simulate_fmu(str(fmu), start_time=e.start, stop_time=e.stop, step_size=e.step, output_interval=e.step,
                     start_values=start, input=table, output=recorded, fmi_type="CoSimulation",
                     terminate=True, validate=False)
    out = {"time": np.asarray(r["time"], dtype=float)}
    for o in outputs:
        m = _ELEMENT.match(o)
        if o in r.dtype.names:
            out[o] = np.asarray(r[o], dtype=float)
        elif m and m.group(1) in r.dtype.names:
            out[o] = np.asarray(r[m.group(1)], dtype=float).reshape(len(r), -1)[:, int(m.group(2)) - 1]
    return out


def run_experiment(fmu: str | Path, e: lsref.RefExperiment, host: str,
                   swap: tuple[str, str] | None = None) -> Outcome:
    """Run one experiment in ``host`` and judge it."""
    fmu = Path(fmu)
    t0 = time.perf_counter()
    inputs = dict(e.inputs)
    if swap:
        a, b = swap
        missing = [s for s in swap if s not in inputs]
        if missing:
            raise lsref.ExperimentError(f"--swap-inputs: {', '.join(missing)} not an input of experiment {e.name}")
        inputs[a], inputs[b] = e.inputs[b], e.inputs[a]
    variables, _units, root = read_description(fmu)
    start = _start_values(variables, root, e, fmu.name)
    outputs = e.outputs
    note = ""
    if host == "libcosim" and root.get("fmiVersion", "").startswith("3"):
        return Outcome(e.name, "not run", "libcosim 0.0.6 imports FMI 2.0 only")
    if host in ("libcosim", "ecos"):
        # an enumeration the experiment leaves at the FMU's start value is harmless to a host that ignores them
        enum_set = [n for n in start if variables[n].type == "Enumeration" and start[n] != variables[n].start]
        if enum_set:
            return Outcome(e.name, "not run", f"{host} ignores enumerations, and this experiment sets "
                           f"{', '.join(f'{n} = {e.parameters[n]}' for n in enum_set)}")
        start = {n: v for n, v in start.items() if variables[n].type != "Enumeration"}
    if host == "ecos":
        from . import ecos_host

        refused = ecos_host.unsupported(fmu, outputs)
        if refused:
            outputs = [o for o in outputs if o not in refused]
            note = f" ({len(refused)} output(s) not readable in ecos: {', '.join(refused)})"
    try:
        if host == "fmpy":
            result = _run_fmpy(fmu, start, inputs, outputs, e)
        elif host == "fmusim":
            from . import fmusim_host

            r = fmusim_host.run(fmu, start, inputs, outputs, e.step, e.stop, e.start)
            if r.exit_code not in (0,):
                return Outcome(e.name, "FAILED", f"fmusim exit code {r.exit_code}: {r.log.strip()[-300:]}",
                               seconds=time.perf_counter() - t0)
            result = r.result
        elif host == "libcosim":
            result = libcosim_table(fmu, inputs, outputs, e.step, start, stop_on_failure=True)
        else:
            from . import ecos_host

            result = ecos_host.run(fmu, start, inputs, outputs, e.step)
    except Exception as exc:  # the host's own failure is the verdict of this experiment, not a crash of ours
        return Outcome(e.name, "FAILED", f"{host}: {exc.__class__.__name__}: {str(exc)[:300]}",
                       seconds=time.perf_counter() - t0)
    if host == "libcosim":  # its observer has no row after initialisation: compare from the first step on
        ref = {k: v[1:] for k, v in e.reference.items()}
        if "status" in ref and ref["status"][-1] == 1 and len(result["time"]) == len(ref["time"]) - 1:
            # a diverged run: libcosim ends the execution on the failed step and keeps no row of it
            ref = {k: v[:-1] for k, v in ref.items()}
            note += " (ended on the diverging step, as the FMU asked, without its row)"
        e = replace(e, reference=ref)
        note += " (from t1: libcosim records no row after initialisation)"
    if outputs != e.outputs:
        e = replace(e, reference={k: e.reference[k] for k in ("time", *outputs)})
    diffs = lsref.compare(e, result)
    worst = max(outputs, key=lambda c: diffs[c])
    ok = lsref.passed(e, diffs)
    rows = f"{int(diffs['rows'])}/{int(diffs['rows_reference'])} rows"
    detail = (f"{rows}, max rel. diff {diffs[worst]:.1e} ({worst}; tolerance {e.tolerance:g})" + note)
    return Outcome(e.name, "passed" if ok else "FAILED", detail, diffs, time.perf_counter() - t0)


def check(fmu: str | Path, host: str = "fmpy", swap: tuple[str, str] | None = None,
          only: list[str] | None = None) -> list[Outcome]:
    """Every reference experiment of ``fmu`` (or those named in ``only``) in ``host``."""
    why = host_unavailable(host)
    if why:
        raise lsref.ExperimentError(f"--host {host}: {why}")
    experiments = lsref.read(fmu)
    if only:
        unknown = sorted(set(only) - {e.name for e in experiments})
        if unknown:
            raise lsref.ExperimentError(f"--only: {', '.join(unknown)} not an experiment of {Path(fmu).name}; "
                                        f"accepted: {', '.join(e.name for e in experiments)}")
        experiments = [e for e in experiments if e.name in only]
    return [run_experiment(fmu, e, host, swap) for e in experiments]
