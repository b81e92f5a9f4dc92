"""Command-line interface: a thin layer over the library's run_* functions.

Every command takes ``--params FILE`` (default: the embedded reference) and
``--out DIR``, writes PNG + JSON there, and ends with a one-line error and exit
code 2 on bad input.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path

from .errors import RotorubError
from .params import load_parameters

COMMANDS: dict[str, tuple[str, Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], dict]]] = {}


def command(name: str, help_text: str):
    def deco(fn):
        def add_args(sp: argparse.ArgumentParser) -> None:
            for args, kwargs in getattr(fn, "_args", []):
                sp.add_argument(*args, **kwargs)

        COMMANDS[name] = (help_text, add_args, fn)
        return fn

    return deco


def arg(*args, **kwargs):
    def deco(fn):
        fn._args = [(args, kwargs)] + getattr(fn, "_args", [])
        return fn

    return deco


def _model(ns: argparse.Namespace):
    from .model import build_model

    return build_model(load_parameters(ns.params))


@command("response", "imbalance response at the fan disk and critical speeds")
@arg("--speed-min", type=float, default=0.05, help="lowest normalised speed")
@arg("--speed-max", type=float, default=10.0, help="highest normalised speed")
@arg("--n-speeds", type=int, default=2000, help="number of speeds on the grid")
def cmd_response(ns: argparse.Namespace) -> dict:
    from .linear import run_response

    return run_response(_model(ns), ns.speed_min, ns.speed_max, ns.n_speeds).save(ns.out)


@command("modes", "eigenvalues at one speed, labelled in the fixed frame")
@arg("--speed", type=float, default=3.5, help="normalised spin speed")
def cmd_modes(ns: argparse.Namespace) -> dict:
    from .linear import run_modes

    return run_modes(_model(ns), ns.speed).save(ns.out)


@command("campbell", "Campbell diagram (fixed-frame frequencies)")
@arg("--speed-max", type=float, default=10.0, help="highest normalised speed")
@arg("--n-speeds", type=int, default=60, help="number of speeds")
def cmd_campbell(ns: argparse.Namespace) -> dict:
    from .linear import run_campbell

    r = run_campbell(_model(ns), ns.speed_max, ns.n_speeds)
    r.save(ns.out)
    return {"n_speeds": len(r.speeds), "written": str(Path(ns.out) / "campbell.png")}


@command("reproduce", "main job: every analysis of the paper on one configuration, with a summary")
@arg("--quick", action="store_true", help="coarse grids: a few minutes on 2 cores")
def cmd_reproduce(ns: argparse.Namespace) -> dict:
    from .reproduce import run_reproduce

    s = run_reproduce(_model(ns), ns.out, quick=ns.quick)
    return {"paper_facts": s["paper_facts"], "written": str(Path(ns.out) / "summary.json")}


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="rotorub", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    for name, (help_text, add_args, _) in COMMANDS.items():
        sp = sub.add_parser(name, help=help_text)
        sp.add_argument("--params", default=None, help="parameter file (TOML); default: embedded reference")
        sp.add_argument("--out", default=f"out/{name}", help="output folder")
        add_args(sp)
    return ap




def main(argv: list[str] | None = None) -> int:
    ap = build_parser()
    ns = ap.parse_args(argv)
    fn = COMMANDS[ns.command][2]
    try:
        result = fn(ns)
    except RotorubError as exc:
        print(f"rotorub {ns.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"rotorub {ns.command}: interrupted", file=sys.stderr)
        return 130
    print(json.dumps(result, default=float, indent=1)[:4000] if isinstance(result, dict) else result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
