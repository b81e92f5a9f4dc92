"""Reference experiments inside an FMU, as the FMI layered standard FMI-LS-REF lays them out, whatever the model.

In ``extra/org.fmi-standard.fmi-ls-ref/`` of the FMU:

* ``fmi-ls-manifest.xml``: the layered standard's manifest (FMI-LS-REF v1.0.0-beta.1, root ``fmiReferences``), one
  ``Related`` entry per file below with its role: the experiments file (``experiment/validation``), each
  experiment's parameter set (``parameter``), stimuli (``testcase``) and reference results (``result``);
* ``experiments.xml``: the experiments (``Experiments``, the format of FMI-LS-REF v1.0.0-alpha.1's appendix: beta.1
  moved it to a separate draft, MA-HS-Experiments, with no version yet): per experiment its start, stop and step,
  its tolerance, and the three files;
* ``<name>.ssv``: the parameters the experiment sets (an SSP 1.0 parameter set; enumerations by item name);
* ``<name>_in.csv``: every input of the FMU, one row per communication point (held over the step that starts
  there; an importer that interpolates between rows reads the same value at the points);
* ``<name>_ref.csv``: the reference outputs at the same points (at most ten variables; FMI 3.0 array elements as
  ``name[k]``).

Our reading of ``tolerance`` (the schema leaves it to the tool): the largest difference of each reference column,
over the rows both runs have, relative to the column's largest absolute value; a run must also end where the
reference ends (a diverging run: at the same step). An empty cell (NaN) is not compared: the row exists, its value
is not a reference (the state a diverged run stopped in, inside its last step).
"""

from __future__ import annotations

import math
import shutil
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from .crosscheck import csv_text, parse_csv

FOLDER = "extra/org.fmi-standard.fmi-ls-ref/"
MANIFEST = FOLDER + "fmi-ls-manifest.xml"
EXPERIMENTS = FOLDER + "experiments.xml"
LS_NAME = "org.fmi-standard.fmi-ls-ref"
LS_VERSION = "1.0.0-beta.1"
LS_DESCRIPTION = "Layered Standard providing information on related files included in an FMU."
LS_NS = "http://fmi-standard.org/fmi-ls-manifest"
SSV_NS = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
ET.register_namespace("fmi-ls", LS_NS)
ET.register_namespace("ssv", SSV_NS)


class ExperimentError(ValueError):
    """An FMU's reference experiments cannot be read (missing, damaged): the message names the file."""


@dataclass(frozen=True)
class RefExperiment:
    """One reference experiment as it travels inside an FMU."""

    name: str
    description: str
    parameters: dict[str, float | int | str]  # FMI names -> values (an enumeration: its item name)
    inputs: dict[str, np.ndarray]  # "time" and one column per input
    reference: dict[str, np.ndarray]  # "time" and one column per output compared
    step: float
    tolerance: float

    @property
    def start(self) -> float:
        return float(self.inputs["time"][0])

    @property
    def stop(self) -> float:
        return float(self.inputs["time"][-1])

    @property
    def outputs(self) -> list[str]:
        return [c for c in self.reference if c != "time"]


def _read_csv(data: bytes, where: str) -> dict[str, np.ndarray]:
    try:
        table = parse_csv(data.decode())
    except (ValueError, UnicodeDecodeError) as exc:
        raise ExperimentError(f"{where}: not a table of numbers ({exc})") from None
    if next(iter(table), None) != "time" or len(table["time"]) < 2:
        raise ExperimentError(f"{where}: expected a header starting with 'time' and at least two rows")
    return table


def _ssv(name: str, values: dict[str, float | int | str]) -> bytes:
    root = ET.Element(f"{{{SSV_NS}}}ParameterSet", version="1.0", name=name)
    params = ET.SubElement(root, f"{{{SSV_NS}}}Parameters")
    for pname, v in values.items():
        p = ET.SubElement(params, f"{{{SSV_NS}}}Parameter", name=pname)
        kind = "Enumeration" if isinstance(v, str) else "Integer" if isinstance(v, int) else "Real"
        ET.SubElement(p, f"{{{SSV_NS}}}{kind}", value=v if isinstance(v, str) else repr(v) if kind == "Real"
                      else str(v))
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _read_ssv(data: bytes, where: str) -> dict[str, float | int | str]:
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        raise ExperimentError(f"{where}: not XML ({exc})") from None
    out: dict[str, float | int | str] = {}
    for p in root.iter(f"{{{SSV_NS}}}Parameter"):
        v = next(iter(p))
        kind, text = v.tag.split("}")[-1], v.get("value", "")
        out[p.get("name")] = text if kind in ("Enumeration", "String") else int(text) if kind == "Integer" \
            else float(text)
    return out


def manifest_xml(files: list[tuple[str, str, str, str]]) -> bytes:
    """The FMI-LS-REF manifest of ``files``: (source, role, MIME type, description)."""
    root = ET.Element("fmiReferences", {f"{{{LS_NS}}}fmi-ls-name": LS_NAME, f"{{{LS_NS}}}fmi-ls-version": LS_VERSION,
                                        f"{{{LS_NS}}}fmi-ls-description": LS_DESCRIPTION})
    for source, role, mime, description in files:
        ET.SubElement(root, "Related", type=mime, source=source, role=role, description=description)
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def experiments_xml(model: str, experiments: list[RefExperiment]) -> bytes:
    root = ET.Element("Experiments", name=f"{model} reference experiments",
                      description="Replay each in any importer and compare: rotorub fmu-check FMU --host ...; "
                                  "tolerance: the largest difference of each reference column relative to its "
                                  "largest absolute value (rows both runs have; a run ends where the reference ends)")
    for e in experiments:
        x = ET.SubElement(root, "Experiment", name=e.name, description=e.description, startTime=repr(e.start),
                          stopTime=repr(e.stop), tolerance=repr(e.tolerance), stepSize=repr(e.step))
        ET.SubElement(x, "Parameters", type="application/x-ssp-parameter-set", source=f"{e.name}.ssv")
        ET.SubElement(x, "Stimuli", type="text/csv", source=f"{e.name}_in.csv")
        ET.SubElement(x, "References", type="text/csv", source=f"{e.name}_ref.csv")
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def files_of(model: str, experiments: list[RefExperiment]) -> dict[str, bytes]:
    """Every file of the layered standard's folder, by its path in the FMU."""
    if not experiments:
        raise ValueError(f"{model}: no reference experiment to write")
    names = [e.name for e in experiments]
    if len(set(names)) != len(names) or any(not n.replace("_", "").isalnum() for n in names):
        raise ValueError(f"{model}: experiment names must be distinct words (letters, digits, _): {names}")
    out = {EXPERIMENTS: experiments_xml(model, experiments)}
    related = [("experiments.xml", "experiment/validation", "application/xml",
                f"{len(experiments)} reference experiments of {model}: " + ", ".join(names))]
    for e in experiments:
        if len(e.outputs) > 10:
            raise ValueError(f"{model}: experiment {e.name} compares {len(e.outputs)} outputs (at most 10)")
        out[FOLDER + f"{e.name}.ssv"] = _ssv(e.name, e.parameters)
        out[FOLDER + f"{e.name}_in.csv"] = csv_text(e.inputs).encode()
        out[FOLDER + f"{e.name}_ref.csv"] = csv_text(e.reference).encode()
        related += [(f"{e.name}.ssv", "parameter", "application/x-ssp-parameter-set", f"{e.name}: parameters"),
                    (f"{e.name}_in.csv", "testcase", "text/csv", f"{e.name}: stimuli, every input"),
                    (f"{e.name}_ref.csv", "result", "text/csv", f"{e.name}: reference results")]
    out[MANIFEST] = manifest_xml(related)
    return out


def embed(fmu: str | Path, model: str, experiments: list[RefExperiment]) -> list[str]:
    """Add (or replace) the reference experiments in ``fmu``; the FMU is rewritten whole, atomically (no
    half-written FMU is ever left). Returns the paths written in the FMU."""
    fmu = Path(fmu)
    files = files_of(model, experiments)
    with tempfile.NamedTemporaryFile(dir=fmu.parent, suffix=".fmu", delete=False) as tmp:
        tmp_path = Path(tmp.name)
    try:
        with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp_path, "w", zipfile.ZIP_DEFLATED) as dst:
            for item in src.infolist():
                if not item.filename.startswith(FOLDER):
                    dst.writestr(item, src.read(item.filename))
            for path, data in files.items():
                dst.writestr(path, data)
        shutil.copymode(fmu, tmp_path)
        tmp_path.replace(fmu)
    finally:
        tmp_path.unlink(missing_ok=True)
    return sorted(files)


def read(fmu: str | Path) -> list[RefExperiment]:
    """The reference experiments an FMU carries (a clear error naming the file when they are missing or damaged)."""
    fmu = Path(fmu)
    try:
        z = zipfile.ZipFile(fmu)
    except (OSError, zipfile.BadZipFile) as exc:
        raise ExperimentError(f"{fmu}: not an FMU (a zip archive) ({exc})") from None
    with z:
        names = set(z.namelist())
        if EXPERIMENTS not in names:
            raise ExperimentError(f"{fmu}: carries no reference experiments ({EXPERIMENTS} missing; FMI-LS-REF)")

        def get(name: str) -> bytes:
            if FOLDER + name not in names:
                raise ExperimentError(f"{fmu}: {FOLDER + name} missing (named by {EXPERIMENTS})")
            return z.read(FOLDER + name)

        try:
            root = ET.fromstring(z.read(EXPERIMENTS))
        except ET.ParseError as exc:
            raise ExperimentError(f"{fmu}: {EXPERIMENTS} is not XML ({exc})") from None
        out = []
        for x in root.findall("Experiment"):
            name = x.get("name", "?")
            try:
                step, tol = float(x.get("stepSize")), float(x.get("tolerance"))
            except (TypeError, ValueError):
                raise ExperimentError(f"{fmu}: experiment {name}: stepSize and tolerance must be numbers") from None
            src = {k: x.find(k).get("source") for k in ("Parameters", "Stimuli", "References")
                   if x.find(k) is not None}
            if len(src) != 3:
                raise ExperimentError(f"{fmu}: experiment {name}: Parameters, Stimuli and References expected")
            out.append(RefExperiment(name, x.get("description", ""), _read_ssv(get(src["Parameters"]), name),
                                     _read_csv(get(src["Stimuli"]), src["Stimuli"]),
                                     _read_csv(get(src["References"]), src["References"]), step, tol))
    return out


def compare(e: RefExperiment, result: dict[str, np.ndarray]) -> dict[str, float]:
    """Per output: the largest difference over the rows both have, relative to the reference column's largest
    absolute value (NaN cells skipped); ``rows`` and ``rows_reference``: how many rows each run has."""
    ref = e.reference
    n = min(len(result.get("time", ())), len(ref["time"]))
    out: dict[str, float] = {"rows": float(len(result.get("time", ()))), "rows_reference": float(len(ref["time"]))}
    for c in e.outputs:
        r = np.asarray(result[c][:n], dtype=float) if c in result else np.full(n, np.nan)
        scale = float(np.nanmax(np.abs(ref[c]))) if np.any(np.isfinite(ref[c])) else 0.0
        d = np.abs(r - ref[c][:n])
        known = np.isfinite(ref[c][:n])
        if c not in result or np.any(~np.isfinite(d[known])):
            out[c] = math.inf
        else:
            out[c] = float(d[known].max() / max(scale, 1e-300)) if known.any() else 0.0
    return out


def passed(e: RefExperiment, diffs: dict[str, float]) -> bool:
    return diffs["rows"] == diffs["rows_reference"] and all(diffs[c] <= e.tolerance for c in e.outputs)
