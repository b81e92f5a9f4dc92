"""RotorCasingContact: FMI 2.0 co-simulation slave around the rotorub library (pythonfmu).

This file is the pythonfmu script of the pythonfmu flavour of ``RotorCasingContact.fmu``
(built by ``rotorub build-fmu``, see builder.py and FMU.md next to it). It contains no
physics: every number it outputs comes from the copy of ``rotorub_model`` carried in the FMU's
resources folder (imported under a build-specific package name so it never collides with
another copy of the library, or another pythonfmu FMU, in the same interpreter):

* transient mode: :class:`CentralDifference`: one call of the compiled kernel per
  communication step does the substeps and writes every output straight into this slave's
  value buffer (``get_state``/``set_state`` for rollback);
* quasi-static mode: :func:`solve_static` (the kernel's Newton) warm-started from the previous
  step, and the largest real part of the eigenvalues by the kernel's eigen-solver, as the
  native FMU computes them.

Its variables, ranges and model description are variables.py's, shared with the native FMUs:
the build writes them into the manifest this slave reads (it imports nothing of fmu_src) and the
model description its ``to_xml`` hands to pythonfmu. pythonfmu turns a Python exception escaping a
callback into fmi2Fatal and can return only fmi2OK or fmi2Discard otherwise, so no callback here lets
an exception out: a
misuse is logged (status fmi2Error, cause in ``message``) and refused at the first call that
can refuse it, ``fmi2DoStep`` (fmi2Discard); FMU.md lists these limits.
"""

from __future__ import annotations

import importlib
import json
import math
import sys
import zlib
from pathlib import Path
from types import SimpleNamespace
from xml.etree.ElementTree import fromstring

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status

MANIFEST = "rotorub_fmu.json"
DESCRIPTION_FILE = "model_description.xml"  # written by the build (fmu_src/fmi/pythonfmu.py), read by to_xml
STATE_VERSION = 5
RE_TOL = 1e-6  # a real part below this is a neutral mode's round-off (rotorub_model.analyses.stability)

# submodules of the bundled library imported eagerly: a later lazy import must not
# depend on the folder it came from still existing (masters delete extracted FMUs)
_LIB_MODULES = ("errors", "writing", "plotting", "kernel.compiler", "kernel", "structure.params", "structure.frames",
                "structure.ritz", "structure.shaft", "structure.tips", "structure.blades", "structure.casing",
                "structure.model",
                "contact.geometry", "contact.point2d", "contact.chord3d", "contact.fe_tip", "contact.contact_model",
                "contact",
                "contact.liner",
                "analyses.linear", "analyses.transient", "analyses.static")


class _StepRefused(Exception):
    """A communication step this FMU refuses (fmi2Error), the instance left as it was."""


def _load(resources: Path) -> tuple[dict, object, SimpleNamespace]:
    """(manifest, namespace of the bundled library's modules, the constants of the interface)."""
    manifest = json.loads((resources / MANIFEST).read_text())
    if str(resources) not in sys.path:
        sys.path.insert(0, str(resources))
    pkg = manifest["library"]

    class Lib:
        pass

    lib = Lib()
    for name in _LIB_MODULES:
        setattr(lib, name.rpartition(".")[2], importlib.import_module(f"{pkg}.{name}"))
    # loaded now, from this instance's resources: the modules are shared by every instance of this build,
    # and a first instance whose configuration is refused (its folder then deleted by the master) would
    # otherwise leave the lazy load to find its sources gone
    lib.kernel.load()
    return manifest, lib, SimpleNamespace(**manifest["constants"])


class RotorCasingContact(Fmi2Slave):
    author = "rotorub developers"
    description = "Blade-tip / casing contact of a turbofan fan module (pythonfmu flavour)"
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._resources = Path(self.resources) if self.resources else Path(__file__).parent
        self._manifest, self._lib, self._if = _load(self._resources)
        self.version = self._manifest.get("library_version", "0")
        self.copyright = "rotorub developers"
        self._ref = self._lib.params.from_dict(self._manifest["parameter_values"])
        self._feedthrough = bool(self._manifest.get("feedthrough", False))
        # the FMI 2.0 view indexed by value reference; the numbering keeps the gaps of the other builds' variables
        # (the FMI 3.0 FMU's own before later additions): placeholders there, never registered
        declared = [SimpleNamespace(**v) for v in self._manifest["variables"]]
        self._vars = [SimpleNamespace(name=None, type="Gap", causality="gap", variability=None, start=None, min=None,
                                      max=None, vr=k) for k in range(max(v.vr for v in declared) + 1)]
        for v in declared:
            self._vars[v.vr] = v
        self.guid = self._manifest["guid"]  # derived from the model at build time, not pythonfmu's uuid1()
        n = len(self._vars)
        self._slot = {v.name: i for i, v in enumerate(self._vars) if v.name is not None}
        self._rv = np.zeros(n)
        self._iv = np.zeros(n, dtype=np.int64)
        self._sv = [""] * n
        self._is_real = np.array([v.type == "Real" for v in self._vars])
        self._is_int = np.array([v.type in ("Integer", "Enumeration") for v in self._vars])
        self._lobe_names = [(n, f"casing_lobe{n}.amplitude", f"casing_lobe{n}.phase") for n in (2, 3, 4)]
        self._real_inputs = frozenset(self._slot[k] for k in ("Omega", "imbalance", "g0", "clearance_closure",
                                                              "casing_offset.x", "casing_offset.y",
                                                              *(x for _, a, p in self._lobe_names for x in (a, p))))
        for i, v in enumerate(self._vars):
            if v.name is not None:
                self._register(i, v)
        self._set_starts()
        nb = self._ref.blades.count
        # where the kernel writes each output of a state (its layout -> this slave's value buffer);
        # n_contact lands in the Real buffer's unused slot of that Integer and is copied over
        kern = self._lib.kernel
        self._out_index = np.array([self._slot[f"blade[{j + 1}].{b}"] for b in kern.OUT_BLADE_NAMES
                                    for j in range(nb)] + [self._slot[g] for g in kern.OUT_GLOBAL_NAMES],
                                   dtype=np.intc)
        s = self._slot
        self._i_omega, self._i_me, self._i_g0 = s["Omega"], s["imbalance"], s["g0"]
        self._i_dt, self._i_nsub, self._i_nc = s["dt_internal"], s["n_substeps"], s["n_contact"]
        self._i_status, self._i_msg, self._i_maxre = s["status"], s["message"], s["max_real_eig"]
        self._i_gmin = s["gap_min"]
        self._i_closure, self._i_offx, self._i_offy = s["clearance_closure"], s["casing_offset.x"], s["casing_offset.y"]
        self._i_clear = s["clearance_effective"]
        self._i_lobes_in = [(n, s[a], s[p]) for n, a, p in self._lobe_names]
        # the kernel's summary, in its order (kernel.WEAR_NAMES: depth_max, ..., lobes, harmonic_1, ...)
        names = kern.WEAR_NAMES
        wear = [f"wear.harmonic[{n.rpartition('_')[2]}]" if n.startswith("harmonic_") else f"wear.{n}" for n in names]
        self._w_lobes, self._w_mean = names.index("lobes"), names.index("depth_mean")
        self._wear_index = np.array([s[k] for k in wear], dtype=np.intp)  # rr_surface_summary's order
        self._i_lobes = s["wear.lobes"]
        self._wear_out = np.zeros(len(wear))
        self._get_memo: tuple[list, np.ndarray] = ([], np.zeros(0, dtype=np.intp))
        self._phase = "instantiated"  # -> initialization -> step -> terminated
        self._t = 0.0  # the FMU's time: the end of the last step taken
        self._sim = None  # runtime objects, built at the end of initialization
        self._fatal_msg = None  # a configuration error: every step is refused until reset
        self._pending = None  # a refused fmi2Set*: the next step is refused with it
        self._stopped = None  # (time, reason): the model ended the run (a discarded step), until a rollback
        self._stale = False  # quasi-static feedthrough: an input changed since the outputs

    # ------------------------------------------------------------------ variables
    def _register(self, i: int, v) -> None:
        cls = {"Real": Real, "Integer": Integer, "Enumeration": Integer, "String": String}[v.type]
        store = {"Real": self._rv, "Integer": self._iv, "Enumeration": self._iv, "String": self._sv}[v.type]
        conv = {"Real": float, "Integer": int, "Enumeration": int, "String": str}[v.type]
        initial = Fmi2Initial.calculated if v.causality == "output" else None

        def getter(i=i, store=store, conv=conv):
            return conv(store[i])

        def setter(value, i=i, conv=conv):
            self._set_value(i, conv(value))

        var = cls(v.name, causality=Fmi2Causality[v.causality], variability=Fmi2Variability[v.variability],
                  description=v.description, initial=initial, getter=getter,
                  setter=None if v.causality == "output" else setter)
        # at the value reference the model description declares (pythonfmu would number in registration order)
        var.value_reference = i
        self.vars[i] = var

    def _set_starts(self) -> None:
        for i, v in enumerate(self._vars):
            if v.start is None:
                continue
            if v.type == "Real":
                self._rv[i] = v.start
            elif v.type == "String":
                self._sv[i] = v.start
            else:
                self._iv[i] = v.start

    def _log_error(self, msg: str) -> None:
        self._sv[self._i_msg] = msg
        self.log(f"RotorCasingContact: {msg}", Fmi2Status.error)

    def _refuse(self, msg: str) -> None:
        """A value the native FMU would refuse with fmi2Error at this call: pythonfmu can only log it;
        the value is not taken, and the next step is refused with the same message."""
        self._pending = msg
        self._log_error(msg)

    def _set_value(self, i: int, value) -> None:
        """Store a value set by the master if the FMI rules and the declared range allow it."""
        v = self._vars[i]
        if v.causality == "output":
            return self._refuse(f"{v.name} is an output and cannot be set (value ignored)")
        if self._phase == "terminated":
            return self._refuse(f"{v.name}: the instance is terminated (fmi2Reset or free it)")
        if self._stopped is not None:
            return self._refuse(f"{v.name}: the FMU ended this simulation (fmi2Terminated is true): "
                                f"{self._stopped[1]}; roll back with fmi2SetFMUstate first, or fmi2Terminate / "
                                "fmi2Reset")
        if self._phase == "step" and v.variability == "fixed":
            return self._refuse(f"{v.name} is a fixed parameter: it cannot change after initialisation (fmi2Reset "
                                "first); value ignored")
        if v.type in ("Real", "Integer", "Enumeration"):
            x = float(value)
            if not math.isfinite(x):
                return self._refuse(f"{v.name} = {x!r} is not finite; accepted range [{v.min!r}, {v.max!r}]")
            if v.min is not None and (x < v.min or x > v.max):
                return self._refuse(f"{v.name} = {x!r} out of range; accepted range [{v.min!r}, {v.max!r}]")
            if i == self._i_g0 and self._sim is not None and self._phase == "step":
                why = self._g0_rule(x, self._sim["config"]["max_penetration"])
                if why:
                    return self._refuse(why)
        if v.type == "Real":
            if self._rv[i] != value:
                self._stale = True
            self._rv[i] = value
        elif v.type == "String":
            self._sv[i] = value
        else:
            self._iv[i] = value

    # fast paths for the per-step traffic (same semantics as the registered getters and setters)
    def _readable(self, fn: str) -> None:
        """FMI 2.0 co-simulation: values are read from fmi2EnterInitializationMode on. The native FMU returns
        fmi2Error; a getter of pythonfmu 0.7 that raises makes fmi2Fatal, so this one logs the error and
        returns the start values (fmu_src/models/contact/FMU.md, 'What pythonfmu cannot honour')."""
        if self._phase == "instantiated":
            self._log_error(f"{fn}: the instance is instantiated: values are read from fmi2EnterInitializationMode "
                            "on (the start values are in modelDescription.xml)")

    def get_real(self, vrs):
        if self._phase == "instantiated":
            self._readable("fmi2GetReal")
        memo_vrs, idx = self._get_memo
        if vrs != memo_vrs:  # a master reads the same list every step: check and convert it once
            idx = np.asarray(vrs, dtype=np.intp)
            if not self._is_real[idx].all():
                raise TypeError(f"get_real: value reference(s) {idx[~self._is_real[idx]].tolist()} are not Real")
            self._get_memo = (list(vrs), idx)
        if self._phase == "initialization":
            self._initial_outputs()
        elif self._stale and self._feedthrough:
            self._refresh()
        return self._rv.take(idx).tolist()

    def get_integer(self, vrs):
        self._readable("fmi2GetInteger")
        idx = np.asarray(vrs, dtype=np.intp)
        if not self._is_int[idx].all():
            raise TypeError(f"get_integer: value reference(s) {idx[~self._is_int[idx]].tolist()} are not Integer")
        if self._phase == "initialization":
            self._initial_outputs()
        elif self._stale and self._feedthrough:
            self._refresh()
        return self._iv[idx].tolist()

    def set_real(self, vrs, values):
        rv, inputs = self._rv, self._real_inputs
        for vr, v in zip(vrs, values):
            if (vr in inputs and self._phase != "terminated" and self._stopped is None
                    and self._vars[vr].min <= v <= self._vars[vr].max
                    and (vr != self._i_g0 or self._sim is None or v >= -self._sim["config"]["max_penetration"])):
                if rv[vr] != v:  # the per-step traffic: Omega, imbalance, g0 (tunable), in range
                    self._stale = True
                rv[vr] = v
            elif not self._is_real[vr]:
                self._refuse(f"set_real: {self._vars[vr].name} (value reference {vr}) is not a Real")
            else:
                self._set_value(vr, float(v))

    def set_integer(self, vrs, values):
        for vr, v in zip(vrs, values):
            if not self._is_int[vr]:
                self._refuse(f"set_integer: {self._vars[vr].name} (value reference {vr}) is not an Integer")
            else:
                self._set_value(vr, int(v))

    def _r(self, name: str) -> float:
        return float(self._rv[self._slot[name]])

    def _i(self, name: str) -> int:
        return int(self._iv[self._slot[name]])

    # ------------------------------------------------------------------ model description
    def to_xml(self, model_options=None):
        """The model description the build wrote from variables.py (fmu_src/fmi/description.py: the native FMUs'
        writer); pythonfmu calls this at build time only."""
        return fromstring((self._resources / DESCRIPTION_FILE).read_bytes())

    # ------------------------------------------------------------------ FMI life cycle
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        self._t = float(start_time or 0.0)

    def enter_initialization_mode(self, *args):
        self._phase = "initialization"

    def _initial_outputs(self) -> None:
        """As the native FMU: in initialization mode the outputs are the initial state's, from a model built with
        the values set so far; a combination that does not hold yet is no error here (exit reports it). The model
        is not kept: exit builds it again with the final values."""
        try:
            self._build(provisional=True)
        except Exception:  # noqa: BLE001 - the master may still be setting values; exit reports it
            pass
        finally:
            self._sim = None

    def exit_initialization_mode(self, *args):
        self._phase = "step"
        try:
            self._build()
        except Exception as exc:  # noqa: BLE001 - reported, never raised (pythonfmu would go fatal)
            self._configuration_error(self._message(exc))

    def terminate(self):
        if self._phase != "step":  # logged, not raised: pythonfmu would make it fmi2Fatal
            self._log_error(f"fmi2Terminate: the instance is in {self._phase} mode (a simulation ends with "
                            "fmi2Terminate once it is initialised; fmi2Reset or fmi2FreeInstance end it in any state)")
            return
        self._phase = "terminated"

    def do_step(self, current_time, step_size):
        try:
            return self._do_step(float(current_time), float(step_size))
        except Exception as exc:  # noqa: BLE001 - last resort: report instead of dying
            self._report(self._if.STATUS_BAD_INPUT, f"internal error at t = {current_time:g} s: {self._message(exc)}")
            return False

    # ------------------------------------------------------------------ messages
    @staticmethod
    def _message(exc: Exception) -> str:
        return f"{type(exc).__name__}: {exc}" if not str(exc).strip() else str(exc)

    def _report(self, status: int, msg: str) -> None:
        self._iv[self._i_status] = status
        self._sv[self._i_msg] = msg
        self.log(f"RotorCasingContact: {msg}",
                 Fmi2Status.error if status == self._if.STATUS_BAD_INPUT else Fmi2Status.discard)

    @staticmethod
    def _g0_rule(g0: float, max_penetration: float) -> str | None:
        """The native FMU's rule between g0 and max_penetration (contact_model.c), or None."""
        if g0 < -max_penetration:
            return (f"g0 = {g0 * 1e3:.6g} mm: an interference deeper than max_penetration = "
                    f"{max_penetration * 1e3:.6g} mm is a divergence (accepted: g0 >= -max_penetration)")
        return None

    def _distortion(self) -> dict:
        """The casing's lobes from the engine's inputs, as the liner takes them (a lobe of amplitude 0 is round)."""
        rv = self._rv
        return {n: (float(rv[a]), float(rv[p])) for n, a, p in self._i_lobes_in if rv[a] != 0.0}

    def _configuration_error(self, msg: str) -> None:
        self._fatal_msg = msg
        self._sim = None
        self._report(self._if.STATUS_BAD_INPUT, msg + " (every step is refused until the FMU is reset)")

    # ------------------------------------------------------------------ building the model
    def _config(self) -> dict:
        enum = self._if.ENUMERATIONS
        return {"formulation": enum["Formulation"][self._i("formulation") - 1][0],
                "mode": enum["Mode"][self._i("mode") - 1][0],
                "param_file": self._sv[self._slot["param_file"]],
                **{k: self._r(k) for k in ("k_r", "mu", "theta", "chord", "dt_max", "max_penetration",
                                                     "slip_velocity", "yield_force", "hardening", "liner_thickness",
                                                     "knee", "stiffness_ratio")},
                "liner": enum["Liner"][self._i("liner") - 1][0], "n_sectors": self._i("n_sectors"),
                "law": enum["Law"][self._i("law") - 1][0]}

    def _build(self, config: dict | None = None, provisional: bool = False) -> None:
        """Build model, contact and solver from the parameters (raises with a message naming the cause);
        ``provisional``: for the outputs of initialization mode, nothing reported."""
        lib = self._lib
        cfg = config or self._config()
        self._fatal_msg = None
        self._sim = None
        if self._pending is not None:
            raise ValueError(self._pending)
        path = cfg["param_file"].strip()
        params = lib.params.load_parameters(path) if path else self._ref
        if params.blades.count != self._ref.blades.count:
            raise ValueError(f"param_file '{path}': blades.count = {params.blades.count}, but this FMU declares "
                             f"outputs for {self._ref.blades.count} blades; rebuild it with "
                             f"`rotorub build-fmu --params {path}`")
        g0 = self._r("g0")
        why = self._g0_rule(g0, cfg["max_penetration"])
        if why:
            raise ValueError(why + "; the run would diverge at t = 0")
        params = params.replace(contact={"g0": g0, "k_r": cfg["k_r"], "mu": cfg["mu"],
                                         "theta_deg": math.degrees(cfg["theta"]), "chord": cfg["chord"],
                                         "max_penetration": cfg["max_penetration"],
                                         "slip_velocity": cfg["slip_velocity"], "law": cfg["law"],
                                         "knee": cfg["knee"], "stiffness_ratio": cfg["stiffness_ratio"]})
        if path:
            try:  # assembling a model needs scipy (the shaft's component modes)
                model = lib.model.build_model(params)
            except ModuleNotFoundError as exc:
                raise ValueError(f"param_file '{path}': assembling a model needs {exc.name} (pip install "
                                 f"{exc.name}); the model built into the FMU (empty param_file) needs only numpy") \
                    from None
        else:  # the matrices baked at build time: no assembly, numpy only
            model = lib.model.load_model(self._resources / self._manifest["model"], params)
        contact = lib.contact.make_contact(model, cfg["formulation"], law=cfg["law"], knee=cfg["knee"],
                                           stiffness_ratio=cfg["stiffness_ratio"])
        sim = {"config": cfg, "model": model, "contact": contact, "g0": g0, "phi": 0.0, "q_static": None,
               "limit": (None, None), "plan": (None, None, 0), "transient": cfg["mode"] == "transient"}
        # the casing's surface: the liner (worn or rigid) and the engine's closure and offset; its cells' area
        # as the native FMU computes it (tip radius x cell angle x chord cos(stagger); an imported tip: its own
        # axial extent and footprint)
        tips = contact.geometry.tips
        band, area = ((tips.band, tips.tip_area) if tips is not None else
                      (cfg["chord"] * math.cos(math.radians(params.blades.stagger_deg)),
                       params.blades.thickness * cfg["chord"]))
        sim["liner"] = lib.liner.Liner(contact, cfg["yield_force"], cfg["hardening"], cfg["liner_thickness"],
                                       int(cfg["n_sectors"]), wears=cfg["liner"] == "abradable",
                                       radius=params.blades.tip_radius, band=band, tip_area=area)
        closure, offset = self._r("clearance_closure"), (self._r("casing_offset.x"), self._r("casing_offset.y"))
        sim["liner"].set_inputs(closure, offset, self._distortion())
        surface = not sim["liner"].is_neutral
        if sim["transient"]:
            sim["cd"] = lib.transient.CentralDifference(model, contact, dt=None, t_ramp=0.0,
                                                        max_penetration=cfg["max_penetration"],
                                                        omega_max_for_dt=self._r("Omega"), liner=sim["liner"])
            sim["cd"].bind_outputs(self._out_index, self._rv)
            sim["cd"].use_liner(surface)
            q = sim["cd"].q
        else:
            q = np.zeros(model.n_dofs)
        self._sim = sim
        self._iv[self._i_status] = self._if.STATUS_OK
        # the initial state against the casing as the engine's inputs place it (as the native FMU)
        self._write_outputs(q, self._r("Omega"), 0.0, max_real=0.0, liner=sim["liner"] if surface else None)
        self._write_wear()
        self._stale = False
        if not sim["transient"]:
            ok, msg = self._quasi_static(self._r("Omega"), self._r("imbalance"), 0.0)
            if not ok and not provisional:  # no balanced solution at the initial inputs: the first step says it again
                self._report(self._if.STATUS_DIVERGED, msg)

    # ------------------------------------------------------------------ stepping
    def _do_step(self, t: float, h: float) -> bool:
        if self._phase != "step":
            self._report(self._if.STATUS_BAD_INPUT, f"fmi2DoStep: the instance is in {self._phase} mode (steps are "
                         "taken after fmi2ExitInitializationMode and before fmi2Terminate)")
            return False
        if self._fatal_msg is not None:
            self._report(self._if.STATUS_BAD_INPUT, self._fatal_msg + " (every step is refused until the FMU is reset)")
            return False
        if self._stopped is not None:
            self._report(self._if.STATUS_BAD_INPUT, f"fmi2DoStep: the FMU ended this simulation at t = "
                         f"{self._stopped[0]!r} s (fmi2Terminated is true): {self._stopped[1]}; call fmi2Terminate, "
                         "or roll back with fmi2SetFMUstate to a state saved before, or fmi2Reset")
            return False
        if self._pending is not None:
            msg, self._pending = self._pending, None
            self._report(self._if.STATUS_BAD_INPUT, f"at t = {t:g} s: step refused: {msg}")
            return False
        if not (math.isfinite(h) and h > 0):
            self._report(self._if.STATUS_BAD_INPUT, f"communication step size {h!r} s: must be finite and > 0")
            return False
        if not math.isfinite(t) or abs(t - self._t) > 1e-9 * max(abs(self._t), h):
            self._report(self._if.STATUS_BAD_INPUT, f"currentCommunicationPoint = {t!r} does not match the FMU's "
                         f"time {self._t!r} (steps must follow each other; to go back, use fmi2SetFMUstate)")
            return False
        sim = self._sim
        rv = self._rv
        omega, me, g0 = float(rv[self._i_omega]), float(rv[self._i_me]), float(rv[self._i_g0])
        if g0 != sim["g0"]:
            sim["g0"] = g0
            self._apply_clearance(g0)
        t_model = sim["cd"].t if sim["transient"] else 0.0
        if sim["transient"]:
            ok = self._transient(omega, me, h)
        else:
            ok, msg = self._quasi_static(omega, me, h)
            if not ok:
                self._report(self._if.STATUS_DIVERGED, f"at t = {t:g} s: {msg}")
        self._stale = False
        if ok:
            self._t = self._t + h
            self._sv[self._i_msg] = ""
        elif self._iv[self._i_status] == self._if.STATUS_DIVERGED:  # the model cannot go on: the run ends
            reached = self._t + (sim["cd"].t - t_model if sim["transient"] else 0.0)
            self._stopped = (reached, self._sv[self._i_msg])
        return ok

    def _apply_clearance(self, g0: float) -> None:
        """One contact model per clearance, shared by the integrator and the outputs."""
        sim = self._sim
        if "cd" in sim:
            if sim["cd"].contact.g0 != g0:
                sim["cd"].set_clearance(g0)
            sim["contact"] = sim["cd"].contact
        else:
            sim["contact"] = sim["contact"].with_clearance(g0)

    def _substeps(self, omega: float, h: float) -> int:
        """n = ceil(h / cap), cap = min(dt_max, half the central-difference stability limit at omega
        rounded up to a whole rad/s): the internal step h/n depends only on dt_max, the limit and
        h, never on earlier steps. The limit is evaluated once per 1 rad/s band (an eigen-solve per
        band, not per step, in a run-up: it moves by far less than the factor 1/2 kept in hand)."""
        sim = self._sim
        band = math.ceil(omega)
        if sim["plan"][:2] != (h, band):
            w, lim = sim["limit"]
            if w != band:
                lim = self._lib.transient.critical_time_step(sim["model"], sim["contact"], float(band))
                sim["limit"] = (band, lim)
            cap = min(sim["config"]["dt_max"], 0.5 * lim)
            n = math.ceil(h / cap * (1 - 1e-9))
            if not n <= self._if.MAX_SUBSTEPS:
                top = self._if.MAX_SUBSTEPS * cap
                raise _StepRefused(f"communication step h = {h!r} s needs {float(n):.3g} substeps of at most {cap!r} s "
                                   f"(dt_max, or half the central-difference limit at {band:g} rad/s); at most "
                                   f"{self._if.MAX_SUBSTEPS} are taken in one step (h <= {top!r} s)")
            sim["plan"] = (h, band, max(1, n))
        return sim["plan"][2]

    def _transient(self, omega: float, me: float, h: float) -> bool:
        cd = self._sim["cd"]
        if cd.diverged:
            self._report(self._if.STATUS_DIVERGED, f"the run diverged at t = {cd.t:.6g} s (internal time)")
            return False
        try:
            n = self._substeps(omega, h)
            dt = h / n
            if dt != cd.dt:  # restart the two-step scheme at the same velocity (nothing changes if refused)
                cd.restart(dt, omega)
        except (_StepRefused, self._lib.errors.ParameterError) as exc:
            self._report(self._if.STATUS_BAD_INPUT, str(exc) if isinstance(exc, _StepRefused) else
                         f"the central-difference matrix is singular at {omega:g} rad/s, dt = {h / n:g} s")
            return False
        rv, iv = self._rv, self._iv
        liner = self._sim["liner"]
        closure, offset = float(rv[self._i_closure]), (float(rv[self._i_offx]), float(rv[self._i_offy]))
        distortion = self._distortion()
        if closure != liner.closure or offset != liner.offset or distortion != liner.distortion:
            liner.set_inputs(closure, offset, distortion)  # ctypes writes only when the engine moved
        # as the native FMU: the surface only when it adds something (worn or wearing, closure, offset, lobes)
        on = liner.wears or closure != 0.0 or offset != (0.0, 0.0) or bool(distortion)
        if on != cd.liner_on:
            cd.use_liner(on)
        done, _ = cd.advance(n, omega, me)  # the kernel writes the outputs into self._rv (bind_outputs)
        self._write_wear()
        iv[self._i_nc] = rv[self._i_nc]
        rv[self._i_dt] = dt
        iv[self._i_nsub] = done
        if done < n or cd.diverged:
            self._report(self._if.STATUS_DIVERGED, f"the run diverged at t = {cd.t:.6g} s (internal time): a blade "
                         f"penetrated the casing deeper than max_penetration = {cd.max_penetration * 1e3:g} mm (or "
                         "the state stopped being finite); the outputs are those of that state")
            return False
        iv[self._i_status] = self._if.STATUS_OK
        return True

    def _write_wear(self, fresh: bool = False) -> None:
        """The liner's summary (the kernel's; recomputed only when a cell was cut, as the native FMU does) and the
        clearance the engine keeps, into the outputs."""
        liner, out = self._sim["liner"], self._wear_out
        if fresh or liner.struct.changed or not self._sim.get("wear_valid"):
            liner.summary_into(out)
            liner.struct.changed = 0
            self._sim["wear_valid"] = True
            self._rv[self._wear_index] = out  # else the outputs hold these values already
            self._iv[self._i_lobes] = int(out[self._w_lobes])
        self._rv[self._i_clear] = self._sim["g0"] - self._rv[self._i_closure] + out[self._w_mean]

    def _quasi_static(self, omega: float, me: float, h: float) -> tuple[bool, str]:
        sim, lib = self._sim, self._lib
        # the engine's closure is uniform: a balanced solution still is, at the closed clearance
        closure = float(self._rv[self._i_closure])
        contact = sim["contact"] if closure == 0.0 else sim["contact"].with_clearance(sim["g0"] - closure)
        st = lib.static.solve_static(sim["model"], contact, omega, me=me, q0=sim["q_static"])
        if not st.converged:
            return False, (f"no balanced static solution at Omega = {omega:g} rad/s, imbalance = {me:g} kg.m, "
                           f"g0 = {sim['g0'] * 1e3:g} mm (relative residual {st.residual:.2e}); the outputs hold the "
                           "last solution")
        # the kernel's eigenvalues: the native FMU computes the same indicator with the same solver
        A = lib.linear.first_order(sim["model"], omega, *contact.jacobians(st.q, omega))
        max_real = float(lib.kernel.eigenvalues(A).real.max())
        sim["q_static"] = st.q
        phi = sim["phi"] + omega * h
        sim["phi"] = phi
        self._rv[self._i_dt] = 0.0
        self._iv[self._i_nsub] = 0
        self._write_outputs(st.q, omega, phi, max_real=max_real, contact=contact)
        self._write_wear()
        # the physical scale of a transient applies here too (as in the native FMU)
        gmin, max_pen = float(self._rv[self._i_gmin]), sim["config"]["max_penetration"]
        if gmin < -max_pen:
            return False, (f"the balanced solution at Omega = {omega:g} rad/s, imbalance = {me:g} kg.m, g0 = "
                           f"{sim['g0'] * 1e3:g} mm penetrates the casing by {-gmin * 1e3:.4g} mm, deeper than "
                           f"max_penetration = {max_pen * 1e3:g} mm: a divergence (the outputs are that solution's)")
        self._iv[self._i_status] = self._if.STATUS_UNSTABLE if max_real > RE_TOL else self._if.STATUS_OK
        return True, ""

    def _refresh(self) -> None:
        """Quasi-static feedthrough build: the outputs are the solution at the current inputs."""
        self._stale = False
        if self._sim is None or self._sim["transient"] or self._phase != "step":
            return
        sim = self._sim
        g0 = float(self._rv[self._i_g0])
        if g0 != sim["g0"]:
            sim["g0"] = g0
            self._apply_clearance(g0)
        ok, msg = self._quasi_static(float(self._rv[self._i_omega]), float(self._rv[self._i_me]), 0.0)
        if not ok:
            self._report(self._if.STATUS_DIVERGED, msg)

    def _write_outputs(self, q: np.ndarray, omega: float, phi: float, max_real: float, contact=None,
                       liner=None) -> None:
        """The outputs of state q at rest in the rotating frame (the kernel's, as in every library
        analysis) at spin omega, fixed frame at angle phi (against ``liner``'s surface when given)."""
        (contact or self._sim["contact"]).write_outputs(q, None, omega, phi, self._out_index, self._rv, liner=liner)
        self._iv[self._i_nc] = int(self._rv[self._i_nc])
        self._rv[self._i_maxre] = max_real

    # ------------------------------------------------------------------ FMU state (rollback)
    def _get_fmu_state(self):
        """Everything a rollback needs: variable values, phase, solver state, warm start, outputs."""
        sim = self._sim
        state = {
            "version": STATE_VERSION, "guid": str(self.guid),
            "rv": self._rv.copy(), "iv": self._iv.copy(), "sv": list(self._sv),
            "phase": self._phase, "t": self._t, "fatal": self._fatal_msg, "sim": None,
            "stopped": None if self._stopped is None else list(self._stopped),
        }
        if sim is not None:
            s = {"config": dict(sim["config"]), "g0": sim["g0"], "phi": sim["phi"],
                 "q_static": None if sim["q_static"] is None else sim["q_static"].copy()}
            if "cd" in sim:
                t, steps, phi, q, q_prev, div, dt, g0, ls = sim["cd"].get_state()
                s["cd"] = {"t": t, "steps": steps, "phi": phi, "q": q, "q_prev": q_prev, "diverged": div,
                           "dt": dt, "g0": g0, "liner": {"depth": ls[0], "phi": ls[1], "plastic_work": ls[2],
                                                         "cut_inputs": list(ls[6])}}
            state["sim"] = s
        return state

    def _set_fmu_state(self, state):
        try:
            self._check_state(state)
        except Exception as exc:  # noqa: BLE001 - refused: the instance keeps its own state
            # pythonfmu cannot return fmi2Error here: the state is refused, logged, and the next step too
            self._refuse(f"fmi2SetFMUstate: not a state of this FMU ({self._message(exc)}); nothing restored")
            return
        try:
            self._restore(state)
        except Exception as exc:  # noqa: BLE001
            self._configuration_error(f"fmi2SetFMUstate: the state could not be restored ({self._message(exc)})")

    def _check_state(self, state) -> None:
        """Everything _restore relies on, checked before anything changes."""
        if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
            raise ValueError(state.get("error", "wrong version") if isinstance(state, dict) else "not a state")
        if state.get("guid") != str(self.guid):
            raise ValueError("saved by another FMU or build (its GUID is not this FMU's)")
        n = len(self._vars)
        rv, iv = np.asarray(state["rv"], dtype=float), np.asarray(state["iv"], dtype=np.int64)
        if rv.shape != (n,) or iv.shape != (n,) or len(state["sv"]) != n:
            raise ValueError("saved by an FMU with another variable set")
        if state["phase"] not in ("instantiated", "initialization", "step", "terminated"):
            raise ValueError(f"phase {state['phase']!r}")
        if not math.isfinite(float(state["t"])):
            raise ValueError("time is not finite")
        for i, v in enumerate(self._vars):
            x = rv[i] if v.type == "Real" else iv[i] if v.type != "String" else None
            if x is not None and v.causality != "output" and v.min is not None and not (v.min <= x <= v.max):
                raise ValueError(f"{v.name} = {x!r} out of range")
        s = state["sim"]
        if s is not None:
            n_dofs = int(self._manifest["n_dofs"])
            if "cd" in s:
                c = s["cd"]
                for key in ("q", "q_prev"):
                    arr = np.asarray(c[key], dtype=float)
                    if arr.shape != (n_dofs,) or not np.all(np.isfinite(arr)):
                        raise ValueError(f"integrator state '{key}' is not {n_dofs} finite values")
                if not (float(c["dt"]) > 0 and math.isfinite(float(c["t"])) and math.isfinite(float(c["phi"]))):
                    raise ValueError("integrator time, step or angle invalid")
                ls = c["liner"]
                depth = np.asarray(ls["depth"], dtype=float)
                cells = (2 if s["config"]["formulation"] == "3D" else 1, int(s["config"]["n_sectors"]))
                if depth.shape != cells or not np.all(np.isfinite(depth)) or np.any(depth < 0):
                    raise ValueError(f"liner depths are not {cells} finite values >= 0")
                if not (math.isfinite(float(ls["phi"])) and float(ls["plastic_work"]) >= 0):
                    raise ValueError("liner angle or plastic work invalid")
                if len(ls["cut_inputs"]) != 3 + 2 * (self._lib.kernel.MAX_LOBES + 1):
                    raise ValueError("liner inputs last cut at: wrong count")

    def _restore(self, state) -> None:
        rv, iv = np.asarray(state["rv"], dtype=float), np.asarray(state["iv"], dtype=np.int64)
        self._rv[:] = rv
        self._iv[:] = iv
        self._sv[:] = list(state["sv"])
        self._phase, self._t, self._fatal_msg = state["phase"], float(state["t"]), state["fatal"]
        self._pending, self._stale = None, False
        self._stopped = None if state.get("stopped") is None else (float(state["stopped"][0]), str(state["stopped"][1]))
        s = state["sim"]
        if s is None:
            self._sim = None
            return
        if self._sim is None or self._sim["config"] != s["config"]:
            g0 = self._r("g0")
            self._rv[self._slot["g0"]] = s["g0"]
            self._build(dict(s["config"]))
            self._rv[self._slot["g0"]] = g0
            self._rv[:] = rv
            self._iv[:] = iv
        sim = self._sim
        sim["phi"] = float(s["phi"])
        sim["q_static"] = None if s["q_static"] is None else np.array(s["q_static"], dtype=float)
        if "cd" in s:
            c = s["cd"]  # set_state restores the integrator's clearance too
            ls = c["liner"]
            liner = sim["liner"]
            sim["cd"].set_state((c["t"], c["steps"], c["phi"], np.asarray(c["q"], dtype=float),
                                 np.asarray(c["q_prev"], dtype=float), c["diverged"], c["dt"], c["g0"],
                                 (np.asarray(ls["depth"], dtype=float), float(ls["phi"]), float(ls["plastic_work"]),
                                  liner.closure, liner.offset, liner.distortion,
                                  [float(v) for v in ls["cut_inputs"]])))
            self._write_wear(fresh=True)
        if s["g0"] != sim["g0"]:
            sim["g0"] = s["g0"]
            self._apply_clearance(s["g0"])

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        # pythonfmu calls this without an instance, so the bundled library's writing.plain
        # is out of reach here; this is its NumPy-to-JSON conversion for the state's types
        def plain(x):
            if isinstance(x, np.ndarray):
                return x.tolist()
            if isinstance(x, dict):
                return {k: plain(v) for k, v in x.items()}
            if isinstance(x, list | tuple):
                return [plain(v) for v in x]
            if isinstance(x, np.generic):
                return x.item()
            return x

        payload = json.dumps(plain(state)).encode("utf-8")  # floats round-trip exactly (shortest repr)
        return payload + b"#%08x" % zlib.crc32(payload)  # a byte changed anywhere is found (CRC-32)

    @staticmethod
    def _fmu_state_from_bytes(data: bytes):
        data = bytes(data)
        payload, _, tail = data.rpartition(b"#")
        if len(tail) != 8 or tail != b"%08x" % zlib.crc32(payload):
            return {"version": None, "error": f"corrupt state: its checksum does not match its {len(data)} bytes "
                                              "(changed after it was serialized, or cut short)"}
        try:
            return json.loads(payload.decode("utf-8"))
        except Exception as exc:  # noqa: BLE001 - surfaced by _set_fmu_state
            return {"version": None, "error": f"serialized state is not valid ({exc})"}
