"""Command-line interface: a thin layer over the library's run_* functions.

Every command takes ``--params FILE`` (default: the embedded reference) and ``--out DIR``, writes PNG + JSON
there, and ends with a short verdict a person reads (what was computed, the key numbers, where the files are) on
stdout; ``--json`` prints the command's whole summary as JSON instead (for scripts: stdout holds that alone, every
progress line goes to stderr). Bad input ends with a one-line error and exit code 2. Lengths are metres (SI, as in
the parameter file); a length option also takes a unit: ``--g0 0.3mm``, ``300um``, ``3e-4``.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ..errors import RotorubError
from ..structure.params import load_parameters

COMMANDS: dict[str, tuple[str, Callable[[argparse.ArgumentParser], None], Callable[[argparse.Namespace], object]]] = {}


@dataclass
class Done:
    """What a command ends with: its whole summary (``--json`` prints it) and the verdict a person reads."""

    summary: dict
    verdict: list[str]


_UNITS_M = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6}
LENGTH_HELP = "[m]; a unit may follow: 0.3mm, 300um"


def length(text: str) -> float:
    """A length option's value in metres: a bare number is metres (SI, as in the parameter file); a number with a
    unit (m, mm, um or µm) is converted: ``0.3mm`` -> 3e-4. (argparse reports a value it cannot read.)"""
    m = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf))\s*(m|mm|um|µm|μm)?\s*",
                     text, flags=re.IGNORECASE)
    if not m:
        raise argparse.ArgumentTypeError(f"{text!r} is not a length (a number of metres, or with a unit: 0.3mm, "
                                         "300um)")
    return float(m.group(1)) * _UNITS_M[(m.group(2) or "m").lower()]


def files_line(out: str | Path, names: list[str] | None = None) -> str:
    """'files: DIR/ (a.png, b.json, ...)': what a command wrote, for its verdict."""
    out = Path(out)
    if names is None:
        names = sorted(p.name for p in out.iterdir() if p.is_file() and p.suffix in (".png", ".json", ".md", ".npz",
                                                                                    ".fmu", ".ssp")) \
            if out.is_dir() else []
        names += sorted(f"{p.name}/" for p in out.iterdir() if p.is_dir() and p.name not in ("work", "unzipped")) \
            if out.is_dir() else []
    shown = ", ".join(names[:8]) + (f", ... ({len(names)} in all)" if len(names) > 8 else "")
    return f"files: {out}/" + (f" ({shown})" if shown else "")


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


from .studies import QUICK_GRID  # noqa: E402 - the quick grid's size, as the help states it

SPEED_MAX_HELP = ("highest normalised speed (default: the paper's 10, or the model's validity, normalisation.speed_max "
                  "of the parameter file, when that is lower)")


def resolve_defaults(ns: argparse.Namespace, p) -> None:
    """The defaults that come from the configuration, filled in before the checks: the speed range's top from its
    validity; modes and static at its own first critical speed, static at its own clearance (contact.g0)."""
    if hasattr(ns, "speed_max") and ns.speed_max is None:
        ns.speed_max = min(10.0, p.normalisation.speed_max)
    if ns.command in ("modes", "static") and getattr(ns, "speed", None) is None:
        from ..structure.model import build_model
        from .studies import first_critical

        ns.speed = first_critical(build_model(p))[0]
    if ns.command == "static" and ns.g0 is None:
        ns.g0 = p.contact.g0
        ns.g0_from_file = True  # a refusal then names the file's field, not a flag the user never gave


def check_arguments(ns: argparse.Namespace, p) -> None:
    """Every numeric argument against the model's validity, before any work (one-line ParameterError).

    Speeds are normalised and valid in [0, normalisation.speed_max] of the parameter file; counts of
    speeds or clearances are at least 2; times and clearances finite (a clearance down to an interference
    as deep as contact.max_penetration)."""
    import math

    from ..errors import ParameterError

    smax = p.normalisation.speed_max

    def bad(flag: str, value, accepted: str):
        raise ParameterError(f"--{flag}: {value!r} out of range; accepted {accepted}")

    for name in ("speed", "speed_min", "speed_max"):
        v = getattr(ns, name, None)
        if v is not None and not (math.isfinite(v) and 0.0 <= v <= smax):
            bad(name.replace("_", "-"), v, f"[0, {smax:g}] (normalised speed; the model's validity ends at "
                f"normalisation.speed_max = {smax:g} of the parameter file)")
    lo, hi = getattr(ns, "speed_min", None), getattr(ns, "speed_max", None)
    if lo is not None and hi is not None and not lo < hi:
        bad("speed-min", lo, f"below --speed-max = {hi!r}")
    for name in ("n_speeds", "n_g0"):
        v = getattr(ns, name, None)
        if v is not None and v < 2:
            bad(name.replace("_", "-"), v, "[2, inf) (a grid needs two points)")
    v = getattr(ns, "t_end", None)
    if v is not None and not (math.isfinite(v) and v > 0):
        bad("t-end", v, "(0, inf) s")
    from ..structure.params import accepted_range

    g0_max = accepted_range("g0_max")[1]
    v = getattr(ns, "g0", None)
    if v is not None and not (math.isfinite(v) and -p.contact.max_penetration <= v <= g0_max):
        accepted = (f"[{-p.contact.max_penetration:g}, {g0_max:g}] m (down to an interference as deep as "
                    "contact.max_penetration)")
        if getattr(ns, "g0_from_file", False):
            raise ParameterError(f"contact.g0 of the parameter file (the default of --g0): {v!r} m out of range; "
                                 f"accepted {accepted}")
        bad("g0", v, accepted)
    for name, declared in (("closure", "clearance_closure"), ("offset_x", "casing_offset"),
                           ("offset_y", "casing_offset")):
        v = getattr(ns, name, None)
        lo, hi = accepted_range(declared)
        if v is not None and not (math.isfinite(v) and lo <= v <= hi):
            bad(name.replace("_", "-"), v, f"[{lo:g}, {hi:g}] m (an engine's closure or casing offset)")
    v = getattr(ns, "yield_force", None)
    lo, hi = accepted_range("abradable.yield_force")
    if v is not None and not (math.isfinite(v) and lo <= v <= hi):
        bad("yield-force", v, f"[{lo:g}, {hi:g}] N")
    v = getattr(ns, "formulation", None)
    if v is not None and v not in ("2D", "3D"):
        bad("formulation", v, "2D or 3D")
    v = getattr(ns, "maps", None)
    if v is not None and not all((Path(v) / f"stability_{f}.npz").is_file() for f in ("2D", "3D")):
        raise ParameterError(f"--maps: {v!r} is not a stability study's folder (accepted: the --out DIR of rotorub "
                             "stability, with stability_2D.npz and stability_3D.npz in it)")


def _model(ns: argparse.Namespace):
    from ..structure.model import build_model

    return build_model(load_parameters(ns.params))


@command("response", "imbalance response at the fan disk and critical speeds")
@arg("--speed-min", type=float, default=0.05, help="lowest normalised speed")
@arg("--speed-max", type=float, default=None, help=SPEED_MAX_HELP)
@arg("--n-speeds", type=int, default=2000, help="number of speeds on the grid")
def cmd_response(ns: argparse.Namespace) -> Done:
    from ..analyses.linear import run_response

    s = run_response(_model(ns), ns.speed_min, ns.speed_max, ns.n_speeds).save(ns.out)
    crit = ", ".join(f"{c:.4g} ({a * 1e3:.3g} mm)" for c, a in zip(s["critical_speeds"], s["peak_amplitudes_m"]))
    lines = [f"Imbalance response at the fan disk over Ω/Ω_ref {s['speed_range'][0]:g}-{s['speed_range'][1]:g} "
             f"({ns.n_speeds} speeds): critical speeds (peak fan-disk displacement) " + (crit or "none") + ".",
             *([s["note"]] if s["note"] else []), *([f"warning: {s['warning']}"] if s["warning"] else []),
             files_line(ns.out)]
    return Done(s, lines)


@command("modes", "eigenvalues at one speed, labelled in the fixed frame")
@arg("--speed", type=float, default=None, help="normalised spin speed (default: this configuration's first critical)")
def cmd_modes(ns: argparse.Namespace) -> Done:
    from ..analyses.linear import run_modes

    r = run_modes(_model(ns), ns.speed)
    s = r.save(ns.out)
    z = r.damping_ratio
    k = int(min(range(len(z)), key=lambda i: z[i])) if len(z) else 0
    lines = [f"Modes at Ω = {ns.speed:.4g} Ω_ref: {len(z)} modes, "
             + ("all damped" if (z > 0).all() else f"{int((z <= 0).sum())} NOT damped")
             + (f"; least damped: {r.fixed_frame_hz[k]:.4g} Hz in the fixed frame, nodal diameter "
                f"{int(r.harmonic[k]):+d}, ζ = {z[k]:.3g}" if len(z) else "") + ".",
             files_line(ns.out)]
    return Done(s, lines)


@command("campbell", "Campbell diagram (fixed-frame frequencies)")
@arg("--speed-max", type=float, default=None, help=SPEED_MAX_HELP)
@arg("--n-speeds", type=int, default=400, help="number of speeds (one batched eigen-solve per cyclic block: "
     "400 take ~0.3 s)")
def cmd_campbell(ns: argparse.Namespace) -> Done:
    from ..analyses.linear import run_campbell

    r = run_campbell(_model(ns), ns.speed_max, ns.n_speeds)
    s = r.save(ns.out)
    lines = [f"Campbell diagram, fixed frame: {r.fixed_frame_hz.shape[1]} modes at {len(r.speeds)} speeds, "
             f"Ω/Ω_ref 0-{r.speeds[-1]:g}.", files_line(ns.out)]
    return Done(s, lines)


def _executor(ns: argparse.Namespace):
    if ns.executor == "serial":
        return "serial"
    if ns.executor == "dask":
        try:
            from dask.distributed import Client
        except ImportError:
            from ..errors import ParameterError

            raise ParameterError(
                "--executor dask: dask.distributed is not installed (pip install 'rotorub[dask]')"
            ) from None
        try:
            return Client(ns.dask_address).get_executor() if ns.dask_address else Client().get_executor()
        except (OSError, TimeoutError) as exc:
            from ..errors import ParameterError

            raise ParameterError(f"--dask-address: {ns.dask_address or 'a local cluster'}: no scheduler answers "
                                 f"({exc})") from None
    return None


@command("static", "balanced static solution with contact at one point, and its stability")
@arg("--speed", type=float, default=None, help="normalised spin speed (default: this configuration's first "
     "critical)")
@arg("--g0", type=length, default=None, help=f"nominal clearance {LENGTH_HELP} (default: contact.g0 of the parameter "
     "file)")
@arg("--formulation", default="3D", help="2D or 3D")
def cmd_static(ns: argparse.Namespace) -> Done:
    from ..analyses.static import run_static
    from ..contact import make_contact

    m = _model(ns)
    st = run_static(m, make_contact(m, ns.formulation, g0=ns.g0), ns.speed * m.params.normalisation.omega_ref)
    s = {**st.save(ns.out, "static"), "speed": ns.speed}  # the speed as given (omega / omega_ref rounds)
    from ..writing import write_json

    write_json(Path(ns.out) / "summary.json", s)
    from ..contact.laws import knee_note

    note = knee_note(m.params.contact, float(-st.gaps.min(initial=0.0))) if st.converged else ""
    lines = [f"{ns.formulation} static solution at Ω = {ns.speed:.4g} Ω_ref, g0 = {ns.g0 * 1e3:.4g} mm: "
             f"{st.verdict()}." + (f" Note: {note}." if note else ""), files_line(ns.out)]
    return Done(s, lines)


def _sweep_args(fn):
    for a, k in (
        (("--executor",), {"default": "process", "choices": ["process", "serial", "dask"],
                           "help": "process pool on all cores, serial, or a Dask cluster"}),
        (("--dask-address",), {"default": None, "help": "scheduler address (default: a local Dask cluster)"}),
        (("--quick",), {"action": "store_true", "help": f"coarse grid ({QUICK_GRID[0]} speeds x {QUICK_GRID[1]} "
                        "clearances, denser at small g0) instead of 100 x 100"}),
    ):
        fn = arg(*a, **k)(fn)
    return fn


@command("stability", "static-solution and stability maps over (speed, g0), 2D and 3D")
@_sweep_args
def cmd_stability(ns: argparse.Namespace) -> Done:
    from .studies import run_stability_study

    s = run_stability_study(_model(ns), ns.out, quick=ns.quick, executor=_executor(ns))
    g = s["grid"]
    lines = [f"Static and stability maps, {g['speeds'][2]} speeds (Ω/Ω_ref {g['speeds'][0]:.3g}-{g['speeds'][1]:.3g}) "
             f"x {g['g0_mm'][2]} clearances (0-{g['g0_mm'][1]:.3g} mm): the static solution is unstable over "
             f"{s['unstable_fraction_2d']:.0%} of the 2D contact area and {s['unstable_fraction_3d']:.0%} of the 3D "
             f"one; stable strip around the 3D unstable area: {'yes' if s['stable_strip_3d'] else 'no'}; at most "
             f"{s['max_blades_in_contact_2d']} (2D) and {s['max_blades_in_contact_3d']} (3D) blades in contact.",
             files_line(ns.out)]
    return Done(s, lines)


@command("transient", "2D and 3D central-difference transients (paper Fig. 12)")
@arg("--speed", type=float, default=None, help="normalised spin speed (default: picked from this configuration's "
     "stability maps: 2D unstable, 3D stable)")
@arg("--g0", type=length, default=None, help=f"nominal clearance {LENGTH_HELP} (default: picked with the speed)")
@arg("--t-end", type=float, default=20.0, help="simulated time [s] (imbalance ramped over the first second)")
@arg("--maps", default=None, help="a stability study's folder (rotorub stability --out DIR) to pick the point from; "
     "default: the quick maps are computed")
def cmd_transient(ns: argparse.Namespace) -> Done:
    from .studies import run_transient_study

    s = run_transient_study(_model(ns), ns.out, ns.speed, ns.g0, t_end=ns.t_end, stab_dir=ns.maps)
    src = s["point"]["source"]
    lines = [f"2D and 3D transients at Ω = {s['speed']:.4g} Ω_ref, g0 = {s['g0_mm']:.4g} mm ({src}), {ns.t_end:g} s:"]
    for f in ("2D", "3D"):
        extra = ""
        if f == "3D" and s["settled_3d"]:
            extra = "; settled on its static solution"
        lines.append(f"  {f}: {s['verdicts'][f]}; penetration limit hit: "
                     f"{'yes' if s['penetration_limit_hit'][f] else 'no'}{extra}.")
    if s["verdict_note"]:
        lines.append(s["verdict_note"])
    lines.append(files_line(ns.out))
    return Done(s, lines)


@command("wear", "2D and 3D transients against an abradable liner: wear map, worn profile, volume, plastic work, "
         "lobes, the clearance left")
@arg("--speed", type=float, default=None, help="normalised spin speed (default: the transient study's point)")
@arg("--g0", type=length, default=None, help=f"nominal clearance {LENGTH_HELP} (default: picked with the speed)")
@arg("--t-end", type=float, default=20.0, help="simulated time [s] (imbalance ramped over the first second)")
@arg("--closure", type=length, default=0.0, help=f"uniform clearance closure from the engine {LENGTH_HELP} (> 0 "
     "closes)")
@arg("--offset-x", type=length, default=0.0, help=f"casing centre offset, fixed frame, x {LENGTH_HELP}")
@arg("--offset-y", type=length, default=0.0, help=f"casing centre offset, fixed frame, y {LENGTH_HELP}")
@arg("--yield-force", type=float, default=None, help="liner yield force [N] (default: abradable.yield_force)")
@arg("--maps", default=None, help="a stability study's folder to pick the point from")
def cmd_wear(ns: argparse.Namespace) -> Done:
    """The wear analysis wears the parameter file's liner whatever abradable.enabled says (that switch is whether the
    other analyses see a liner); with it off, the command says so first, and in its summary and verdict."""
    from ..progress import say
    from .studies import run_wear_study

    m = _model(ns)
    note = ""
    if not m.params.abradable.enabled:
        note = ("abradable.enabled = false in the parameter file: the wear analysis lines the casing anyway, with the "
                "file's [abradable] values (the switch only decides whether the other analyses see a liner)")
        say(f"wear: {note}")
    liner = {} if ns.yield_force is None else {"yield_force": ns.yield_force}
    s = run_wear_study(m, ns.out, ns.speed, ns.g0, t_end=ns.t_end, closure=ns.closure,
                       offset=(ns.offset_x, ns.offset_y), stab_dir=ns.maps, **liner)
    if note:
        s["liner_note"] = note
        from ..writing import write_json

        write_json(Path(ns.out) / "summary.json", s)
    lines = [f"Wear of the abradable liner at Ω = {s['speed']:.4g} Ω_ref, g0 = {s['g0_mm']:.4g} mm, {ns.t_end:g} s"
             + (f" ({note})" if note else "") + ":"]
    for f in ("2D", "3D"):
        w = s[f]
        if w["depth_max_mm"] <= 0:  # nothing cut: say why (the forces stayed below the liner's yield)
            lines.append(f"  {f}: no wear: the largest normal force, {w['max_normal_force_N']:.4g} N, stays below the "
                         f"liner's yield force {w['liner']['yield_force_N']:.4g} N; clearance "
                         f"{w['clearance_before_mm']:.4g} mm kept.")
            continue
        lines.append(f"  {f}: deepest {w['depth_max_mm'] * 1e3:.4g} µm, {w['removed_volume_mm3']:.4g} mm³ removed, "
                     f"plastic work {w['plastic_work_J']:.4g} J; {w['lobes_verdict']}; clearance "
                     f"{w['clearance_before_mm']:.4g} -> {w['clearance_effective_mm']:.4g} mm.")
    lines.append(files_line(ns.out))
    return Done(s, lines)


@command("detect", "contact detection maps over (speed, g0): 2D, 3D, degraded 3D, theta and chord sweeps")
@arg("--speed-min", type=float, default=0.05, help="lowest normalised speed")
@arg("--speed-max", type=float, default=None, help=SPEED_MAX_HELP)
@arg("--n-speeds", type=int, default=400, help="uniform speeds (critical speeds and a dense cluster added)")
@arg("--n-g0", type=int, default=400, help="clearances on the map's g0 axis")
@arg("--g0-max", type=length, default=None, help=f"top of the g0 axis {LENGTH_HELP} (default: 1.05 x the largest "
     "closure)")
@arg("--g0-max-mm", type=float, default=None, help="the same in millimetres (kept for older scripts)")
def cmd_detect(ns: argparse.Namespace) -> Done:
    from ..analyses.detection import run_detection
    from ..errors import ParameterError

    if ns.g0_max is not None and ns.g0_max_mm is not None:
        raise ParameterError("--g0-max-mm: give --g0-max or --g0-max-mm, not both (the same length)")
    g0_max = ns.g0_max if ns.g0_max_mm is None else ns.g0_max_mm * 1e-3
    r = run_detection(_model(ns), speed_min=ns.speed_min, speed_max=ns.speed_max, n_speeds=ns.n_speeds,
                      g0_max=g0_max, n_g0=ns.n_g0)
    s = r.save(ns.out)
    at = s["speed_of_max_closure"]
    lines = [f"Contact detection over Ω/Ω_ref {s['speed_range'][0]:.3g}-{s['speed_range'][1]:.3g} ({s['n_speeds']} "
             f"speeds): largest closure {s['closure_2d_max_mm']:.4g} mm (2D, at Ω = {at['2D']:.4g}) and "
             f"{s['closure_3d_max_mm']:.4g} mm (3D, at {at['3D']:.4g}); 3D contains 2D: "
             f"{'yes' if s['map_3d_contains_2d'] else 'no'}; degraded 3D differ from 2D by at most "
             f"{s['closure_diff_kinematics_only_mm']:.3g} mm (kinematics only) and "
             f"{s['closure_diff_geometry_only_mm']:.3g} mm (geometry only).", files_line(ns.out)]
    return Done(s, lines)


@command("continuation", "static branches with their Hopf, fold and switch points, the periodic orbits past "
         "them, and the stability boundary as curves over the (speed, g0) maps")
@arg("--speed", type=float, default=None, help="normalised speed of the g0 branches and orbits (default: the "
     "paper's 3.3 when it lies on this configuration's map grid, else the configuration's first critical speed)")
@arg("--maps", default=None, help="a stability study's folder (rotorub stability --out DIR) to draw the curves over "
     "and check them against; default: the quick maps are computed")
@arg("--quick", action="store_true", help="fewer periodic orbits per branch")
def cmd_continuation(ns: argparse.Namespace) -> Done:
    from .studies import run_continuation_study

    s = run_continuation_study(_model(ns), ns.out, speed=ns.speed, maps_dir=ns.maps, quick=ns.quick)
    lines = [f"Continuation at Ω = {s['speed']:.4g} Ω_ref ({s['speed_source']}):"]
    for f in ("2D", "3D"):
        if f not in s:
            continue
        sp = "; ".join(f"{x['kind']} at g0 = {x['g0_m'] * 1e3:.4g} mm" for x in s[f]["specials"]) or "no special point"
        b = s[f]["boundary"]
        n = b.get("curves") or 0
        lines.append(f"  {f}: {sp}; {sum(s[f]['orbits'])} periodic orbits ({s[f]['orbit_note']}); stability "
                     f"boundary: {n} curve{'s' if n != 1 else ''}, {b.get('contradicting_beyond_one_cell', '?')} grid "
                     "cells contradict them beyond one cell.")
    lines.append(files_line(ns.out))
    return Done(s, lines)


@command("forced-response", "forced rub response of a distorted casing over speed: harmonic balance with continuation "
         "and stability, transients beside it, the interaction map")
@arg("--speeds", type=float, nargs=2, required=True, metavar=("A", "B"), help="normalised speed range")
@arg("--formulation", default="2D", help="2D or 3D")
@arg("--g0", type=length, default=None, help=f"nominal clearance {LENGTH_HELP} (default: contact.g0 of the parameter "
     "file)")
@arg("--lobe", type=int, default=None, help="lobe count n >= 2 of the casing's out-of-roundness (1 is the offset)")
@arg("--amplitude", type=length, default=None, help=f"the lobe's amplitude a_n {LENGTH_HELP} (> 0 opens the gap at its "
     "maxima)")
@arg("--phase", type=float, default=0.0, help="fixed-frame angle of a lobe maximum [deg]")
@arg("--offset-x", type=length, default=None, help=f"casing centre offset, fixed frame, x {LENGTH_HELP} (the n = 1 "
     "term)")
@arg("--offset-y", type=length, default=None, help=f"casing centre offset, fixed frame, y {LENGTH_HELP}")
@arg("--harmonics", type=int, default=10, help="harmonics of the spin speed kept (default 10)")
@arg("--transients", type=int, default=0, help="transients at this many speeds beside the HB (0: none)")
@arg("--executor", default="process", choices=["process", "serial"], help="where the transients run")
def cmd_forced_response(ns: argparse.Namespace) -> Done:
    from .forced_response import forcing_from_args, run_forced_response

    m = _model(ns)
    g0 = m.params.contact.g0 if ns.g0 is None else ns.g0
    offset = None if ns.offset_x is None and ns.offset_y is None else (ns.offset_x or 0.0, ns.offset_y or 0.0)
    f = forcing_from_args(g0, ns.lobe, ns.amplitude, ns.phase, offset)
    s = run_forced_response(m, ns.out, tuple(ns.speeds), ns.formulation, g0, f, ns.harmonics, ns.transients,
                            executor="serial" if ns.executor == "serial" else None)
    lines = [f"Forced rub response over Ω/Ω_ref {ns.speeds[0]:g}-{ns.speeds[1]:g}: {s['verdict']}.",
             files_line(ns.out)]
    return Done(s, lines)


@command("uq", "will it rub? an uncertainty study from a study file (TOML): rub probability with its interval, "
         "Sobol'/Morris indices, small probabilities (FORM, subset), mistuned disks")
@arg("study", help="the study file (rotorub_model/data/study_example.toml is a commented example)")
@arg("--executor", default="process", choices=["process", "serial", "dask"],
     help="process pool on all cores, serial, or a Dask cluster")
@arg("--dask-address", default=None, help="scheduler address (default: a local Dask cluster)")
@arg("--quick", action="store_true", help="an eighth of the study's points (a quarter for morris, subset)")
def cmd_uq(ns: argparse.Namespace) -> Done:
    from ..uncertainty.cli import run_uq_command

    s = run_uq_command(ns, lambda: _executor(ns))
    lines = [f"Uncertainty study '{s['study']}' ({s['method']}, {s['points']} evaluations, {s['wall_s']:.3g} s): "
             f"{s['verdict']}", files_line(ns.out)]
    return Done(s, lines)


@command("reproduce", "main job: every analysis of the paper on one configuration, with a summary")
@arg("--quick", action="store_true", help="coarse grids: a few minutes on 2 cores")
@arg("--no-fmu", action="store_true", help="library analyses only (no FMU build, harnesses or coupled run)")
@arg("--fmu-dir", default="fmus", help="where the FMUs are built (default: fmus)")
def cmd_reproduce(ns: argparse.Namespace) -> Done:
    from .reproduce import main_job_verdict, run_reproduce

    model = _model(ns)
    builds = None
    if not ns.no_fmu:
        from ..errors import ParameterError

        try:  # the FMU half found (or refused) before any work
            run_fmu_part = _entry_point("rotorub.reproduce", "fmu")
        except (LookupError, ImportError) as exc:
            raise ParameterError(f"reproduce: the FMU part needs the fmu extra ({exc}); "
                                 "pip install -e '.[fmu]', or run with --no-fmu") from None
        try:  # its compilations beside the library's analyses (an older FMU side builds them afterwards)
            builds = _entry_point("rotorub.reproduce", "fmu-builds")(ns.fmu_dir, ns.params)
        except (LookupError, ImportError):
            builds = None
    s = run_reproduce(model, ns.out, quick=ns.quick, params_file=ns.params, progress=True)
    fmu_lines: list[str] = []
    if not ns.no_fmu:
        kw = {"builds": builds} if builds is not None else {}
        part = run_fmu_part(model, ns.out, s, quick=ns.quick, fmu_dir=ns.fmu_dir, params_file=ns.params, **kw)
        s.update(part["summary"])
        from ..writing import write_json
        from .report import write_report

        write_json(Path(ns.out) / "summary.json", s)
        write_report(ns.out, s, sections=[part["markdown"]])
        fmu_lines = list(part.get("verdict", []))
    return Done(s, main_job_verdict(s, ns.out, fmu_lines, fmu=not ns.no_fmu))


@command("import-blade", "read a finite-element blade (CalculiX, Matrix Market, NASTRAN OP4/DMIG), reduce it once, "
         "check it against the FE code and write the superelement a parameter file names")
@arg("--fe", nargs="+", required=True, help="CalculiX jobs (one a speed, the first at rest), or a Matrix Market mass "
     "then stiffness files, or an .op4 / DMIG .pch file with --matrices")
@arg("--units", required=True, help="the files' unit system, e.g. SI, N-mm-t-s, mN-mm-kg-s, kN-mm-kg-ms, lbf-in-s")
@arg("--tip-nodes", nargs="+", required=True, help="ids of the contact nodes along the tip, or a file of ids")
@arg("--coordinates", default=None, help="node coordinates: .inp, .msh, NASTRAN GRIDs, or 'id x y z' table")
@arg("--speeds", nargs="+", type=float, default=None, help="spin speed of each stiffness [rad per time unit] "
     "(CalculiX jobs: read from their decks)")
@arg("--dofs", default=None, help="dof map of the stiffness rows (Matrix Market, OP4)")
@arg("--mass-dofs", default=None, help="dof map of the mass rows when it has more (the root's, constrained dofs)")
@arg("--matrices", nargs="+", default=None, help="OP4/DMIG matrix names: the mass, then one stiffness a speed")
@arg("--mass-free", default=None, help="CalculiX job of the unclamped blade (its mass rows hold the root's)")
@arg("--cutoff-hz", type=float, default=1500.0, help="keep the blade modes below this frequency")
@arg("--basis", default="condensed", help="condensed (default), modal or two-speed")
@arg("--axis-origin", nargs=3, type=float, default=(0.0, 0.0, 0.0), help="a point of the spin axis at the fan "
     "disk's station (file units)")
@arg("--axis-direction", nargs=3, type=float, default=(0.0, 0.0, 1.0), help="the spin axis (file axes)")
@arg("--compare-reductions", action="store_true", default=None, help="measure every reduction (step, accuracy, "
     "cost) even above 20 000 dofs")
def cmd_import_blade(ns: argparse.Namespace) -> dict:
    from ..fe.import_blade import import_blade_command

    p = load_parameters(ns.params)
    return import_blade_command(
        ns.fe, ns.units, ns.tip_nodes, ns.out, coordinates=ns.coordinates, speeds=ns.speeds, dofs=ns.dofs,
        mass_dofs=ns.mass_dofs, matrices=ns.matrices, mass_free=ns.mass_free, cutoff_hz=ns.cutoff_hz,
        basis=ns.basis, axis_origin=ns.axis_origin, axis_direction=ns.axis_direction, k_r=p.contact.k_r,
        damping_ratio=p.blades.damping_ratio, variants=ns.compare_reductions)


class _OneLineParser(argparse.ArgumentParser):
    """argparse that reports a bad argument on one line (no usage dump)."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message}\n")


def _entry_point(group: str, name: str):
    """An object another installed package offers the CLI (the FMU side registers its commands so;
    the library itself never imports it)."""
    from importlib.metadata import entry_points

    for ep in entry_points(group=group):
        if ep.name == name:
            return ep.load()
    raise LookupError(f"no '{name}' in the entry points '{group}'")


def _plugin_commands() -> None:
    """Commands registered by installed packages (group rotorub.commands: (name, help, add_args, run))."""
    from importlib.metadata import entry_points

    for ep in entry_points(group="rotorub.commands"):
        try:
            name, help_text, add_args, run = ep.load()
        except ImportError:  # the extra that provides it is not installed: the command is simply absent
            continue
        COMMANDS.setdefault(name, (help_text, add_args, run))


def build_parser() -> argparse.ArgumentParser:
    ap = _OneLineParser(prog="rotorub", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    _plugin_commands()
    for name, (help_text, add_args, _) in COMMANDS.items():
        sp = sub.add_parser(name, help=help_text, description=help_text)
        sp.add_argument("--params", default=None, help="parameter file (TOML); default: embedded reference")
        sp.add_argument("--out", default=f"out/{name}", help="output folder")
        sp.add_argument("--json", action="store_true", help="print the whole summary as JSON (for scripts) instead of "
                        "the verdict; progress still goes to stderr")
        add_args(sp)
    return ap


def _done(ns: argparse.Namespace, result: object) -> Done:
    """A command's result as a Done: a plugin command (build-fmu, from the FMU side) returns a dict, with its
    ``verdict`` line(s) when it has them."""
    if isinstance(result, Done):
        return result
    summary = result if isinstance(result, dict) else {"result": result}
    v = summary.get("verdict") if isinstance(summary, dict) else None
    lines = ([v] if isinstance(v, str) else list(v)) if v else [f"rotorub {ns.command}: done."]
    return Done(summary, [*lines, files_line(getattr(ns, "out", "."), [])] if not v else lines)



def main(argv: list[str] | None = None) -> int:
    ap = build_parser()
    ns = ap.parse_args(argv)
    fn = COMMANDS[ns.command][2]
    try:
        p = load_parameters(ns.params)
        check_arguments(ns, p)  # what was given, before the defaults that cost a response (the first critical)
        resolve_defaults(ns, p)
        check_arguments(ns, p)
        result = fn(ns)
    except RotorubError as exc:
        print(f"rotorub {ns.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # the output folder (or a file in it) cannot be written, a file cannot be read
        print(f"rotorub {ns.command}: error: {exc.filename or ''}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"rotorub {ns.command}: interrupted", file=sys.stderr)
        return 130
    from ..writing import dumps

    done = _done(ns, result)
    sys.stdout.write((dumps(done.summary) if ns.json else "\n".join(done.verdict)) + "\n")
    sys.stdout.flush()
    # a command whose verdict is a failure (fmu-check: an experiment failed) says so in its exit code too
    return int(done.summary.get("exit_code", 0)) if isinstance(done.summary, dict) else 0


if __name__ == "__main__":
    sys.exit(main())
