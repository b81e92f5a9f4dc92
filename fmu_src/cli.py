"""The FMU side's entry points for the ``rotorub`` CLI, found through entry points (the library never imports this
package): ``build-fmu`` (group ``rotorub.commands``) and the FMU half of ``reproduce`` (group ``rotorub.reproduce``,
reproduce.py next to this file)."""

from __future__ import annotations

import argparse
from pathlib import Path


def _add_build_args(sp: argparse.ArgumentParser) -> None:
    sp.add_argument("--native", action="store_true",
                    help="the native C FMU (no Python on the host) instead of the pythonfmu one")
    sp.add_argument("--fmi3", action="store_true",
                    help="with --native: the FMI 3.0 co-simulation FMU (fmus/native-fmi3/: arrays per blade, early "
                         "return at a first contact) instead of the FMI 2.0 one")
    sp.add_argument("--mode", default="transient", choices=["transient", "quasi_static"],
                    help="default of the mode parameter, and the output dependencies the FMU declares")
    from .fmi.compile import ALL_PLATFORMS  # light: the builder itself is imported only to build

    # no --out: the FMUs go where the harnesses and the README look for them (fmus/, fmus/native/, ...); a --out
    # given, even the other commands' "out/build-fmu", is taken as it is
    sp.set_defaults(out=None)

    sp.add_argument("--platforms", nargs="+", default=None,
                    help=f"platforms to build (native: {' '.join(ALL_PLATFORMS)}; pythonfmu kernel: linux64 win64, "
                         "the platforms pythonfmu 0.7 has a binary for); default: all of them when ziglang is "
                         "installed, else this machine's")


def _run_build(ns: argparse.Namespace) -> dict:
    from rotorub_model.errors import ParameterError
    from rotorub_model.kernel.compiler import CompilerError

    from .fmi.compile import NativeBuildError
    from .fmi.pythonfmu import BuildError
    from .models.contact.builder import build_with_kit

    default = Path("fmus") / (("native-fmi3" if ns.fmi3 else "native") if ns.native else "")
    dest = default if ns.out is None else Path(ns.out)
    try:
        r = build_with_kit(dest, ns.params, ns.native, ns.mode, tuple(ns.platforms) if ns.platforms else None,
                           ns.fmi3)
    except (BuildError, NativeBuildError, CompilerError) as exc:
        raise ParameterError(f"build-fmu: {exc}") from None
    plats = r.get("platforms") or r.get("kernel_platforms") or []
    flavour = ("native C, FMI 3.0" if ns.fmi3 else "native C, FMI 2.0") if ns.native else "pythonfmu, FMI 2.0"
    from rotorub_model.structure.params import load_parameters

    # which model is built in: the same file name holds the reference or a user's fan, and a build from
    # `--params` replaced fmus/native/ without a word
    blades = load_parameters(ns.params).blades.count
    r["verdict"] = [f"Built {r['fmu']} ({flavour} co-simulation, mode {ns.mode}"
                    + (f", {r['variables']} variables" if "variables" in r else "")
                    + (f", binaries for {', '.join(plats)}" if plats else "") + ") with the model of "
                    + (f"{ns.params}" if ns.params else "the embedded reference") + f" built in ({blades} blades).",
                    f"cross-check kit next to it: {', '.join(Path(k).name for k in r.get('crosscheck_kit', []))}",
                    f"reference experiments inside it (FMI-LS-REF): {', '.join(r.get('reference_experiments', []))}; "
                    f"replay them in an importer: rotorub fmu-check {r['fmu']} --host fmusim"]
    return r


def reproduce_fmu_part(model, out: str | Path, summary: dict, quick: bool, fmu_dir: str | Path = "fmus",
                       params_file: str | Path | None = None, progress: bool = True, builds=None) -> dict:
    """The FMU half of ``rotorub reproduce`` (reproduce.py): returns ``{"summary": ..., "markdown": ...,
    "verdict": ...}``, the additions to the summary, the report's section about them and the verdict's lines;
    ``builds``: what :func:`start_fmu_builds` returned, when the FMUs were started before the library's analyses."""
    from .reproduce import run_fmu_part

    return run_fmu_part(model, out, summary, quick, fmu_dir=fmu_dir, params_file=params_file, progress=progress,
                        builds=builds)


def start_fmu_builds(fmu_dir: str | Path = "fmus", params_file: str | Path | None = None):
    """Start building the main job's FMUs in the background (entry point ``rotorub.reproduce: fmu-builds``): the
    compilations run beside the library's analyses. Returns the handle :func:`reproduce_fmu_part` takes."""
    from .reproduce import start_builds

    return start_builds(fmu_dir, params_file)


# (name, help, add_arguments, run): what rotorub_model.app.cli registers for each entry point
BUILD_FMU = ("build-fmu", "package the contact model as an FMI 2.0 co-simulation FMU: fmus/RotorCasingContact.fmu "
             "(pythonfmu) or, with --native, fmus/native/RotorCasingContact.fmu (C, no Python on the host); with "
             "--native --fmi3, the FMI 3.0 one in fmus/native-fmi3/",
             _add_build_args, _run_build)


def _add_check_args(sp: argparse.ArgumentParser) -> None:
    from .masters.replay import HOSTS

    sp.add_argument("fmu", help="an FMU carrying reference experiments (FMI-LS-REF: every FMU rotorub builds)")
    sp.add_argument("--host", default="fmpy", choices=HOSTS, help="the importer to replay them in (default fmpy)")
    sp.add_argument("--only", nargs="+", default=None, metavar="NAME", help="only these experiments")
    sp.add_argument("--swap-inputs", nargs=2, default=None, metavar=("A", "B"),
                    help="hand the host inputs A and B the wrong way round (a mis-wired connection: the experiments "
                         "must fail)")
    sp.add_argument("--record", default=None, metavar="DIR",
                    help="write the compatibility information (the FMI cross-check layout) under DIR: "
                         "DIR/<fmi>/cs/<platform>/<importer>/<version>/rotorub/<version>/<FMU>/ with the verdict "
                         "and what the importer produced")
    sp.set_defaults(out=None)


def _run_check(ns: argparse.Namespace) -> dict:
    from rotorub_model.errors import ParameterError

    from .fmi.lsref import ExperimentError
    from .masters import compatibility, replay

    if not Path(ns.fmu).is_file():
        raise ParameterError(f"fmu-check: FMU '{ns.fmu}' not found (give the path of a .fmu file)")
    try:
        outcomes = replay.check(ns.fmu, ns.host, tuple(ns.swap_inputs) if ns.swap_inputs else None, ns.only)
    except ExperimentError as exc:
        raise ParameterError(f"fmu-check: {exc}") from None
    version = replay.host_version(ns.host)
    failed = [o for o in outcomes if o.verdict == "FAILED"]
    ran = [o for o in outcomes if o.verdict != "not run"]
    lines = [f"{Path(ns.fmu).name} in {ns.host} {version}"
             + (f" (inputs {ns.swap_inputs[0]} and {ns.swap_inputs[1]} swapped)" if ns.swap_inputs else "") + ":"]
    lines += ["  " + o.line() for o in outcomes]
    summary = {"fmu": str(ns.fmu), "host": ns.host, "host_version": version,
               "swapped_inputs": ns.swap_inputs, "experiments": [o.__dict__ for o in outcomes]}
    if ns.record and not ns.swap_inputs and ran:  # an importer that cannot run one of them: nothing to record
        summary["recorded"] = str(compatibility.record(ns.fmu, ns.host, version, outcomes, ns.record))
    lines.append(("FAILED: " + ", ".join(o.experiment for o in failed) + f" ({len(failed)} of {len(ran)} run)")
                 if failed else f"All {len(ran)} experiments run passed" + (
                     f" ({len(outcomes) - len(ran)} not run: the importer cannot)" if len(ran) < len(outcomes)
                     else "") + ".")
    if summary.get("recorded"):
        lines.append(f"compatibility information written to {summary['recorded']}")
    summary["verdict"] = lines
    summary["exit_code"] = 1 if failed or not ran else 0
    return summary


FMU_CHECK = ("fmu-check", "replay an FMU's own reference experiments (FMI-LS-REF, inside every FMU rotorub builds) "
             "in an importer (fmpy, fmusim, libcosim, ecos) and print one line per experiment; exit 1 if one fails",
             _add_check_args, _run_check)
