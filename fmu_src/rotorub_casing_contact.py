"""RotorCasingContact: FMI 2.0 co-simulation slave around the rotorub library.

This file is the pythonfmu script of ``fmus/RotorCasingContact.fmu`` (built by
``rotorub build-fmu``, see fmu_src/build.py and docs/FMU.md). It contains no
physics: every number it outputs comes from the copy of ``rotorub_model`` carried
in the FMU's resources folder (imported under a build-specific package name so it
never collides with another copy of the library, or with another pythonfmu FMU,
in the same interpreter):

* transient mode: :class:`CentralDifference`: one call of the compiled kernel per
  communication step does the substeps and writes every output straight into this
  slave's value buffer (``get_state``/``set_state`` for rollback);
* quasi-static mode: :func:`solve_static` warm-started from the previous step and
  :func:`stability_of` for the largest real part of the eigenvalues.

pythonfmu turns any Python exception escaping a callback into fmi2Fatal and
destroys the Python instance. So no callback here lets an exception out: bad
input is reported by ``do_step`` returning False (fmi2Discard) after logging a
message (status fmi2Error) that names the cause, and the instance stays usable.
"""

from __future__ import annotations

import importlib
import json
import math
import sys
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status

MANIFEST = "rotorub_fmu.json"
MODES = ("transient", "quasi_static")
FORMULATIONS = ("2D", "3D")
STATUS_OK, STATUS_DIVERGED, STATUS_ERROR = 0, 1, 2
STATE_VERSION = 1

# FMI 2.0 unit definitions: name -> SI base-unit exponents
UNITS = {
    "rad/s": {"rad": 1, "s": -1},
    "kg.m": {"kg": 1, "m": 1},
    "m": {"m": 1},
    "N/m": {"kg": 1, "s": -2},
    "rad": {"rad": 1},
    "s": {"s": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "1/s": {"s": -1},
    "1": {},
}

# submodules of the bundled library imported eagerly: a later lazy import must not
# depend on the folder it came from still existing (masters delete extracted FMUs)
_LIB_MODULES = ("errors", "results", "kernel.compiler", "kernel", "structure.params", "structure.frames",
                "structure.ritz", "structure.shaft", "structure.blades", "structure.casing", "structure.model",
                "contact.geometry", "contact.point2d", "contact.chord3d", "contact.contact_model", "contact",
                "analyses.linear", "analyses.transient", "analyses.static", "analyses.stability")


def _load_library(resources: Path) -> tuple[dict, object]:
    """(manifest, namespace of the bundled library's modules)."""
    manifest = json.loads((resources / MANIFEST).read_text())
    if str(resources) not in sys.path:
        sys.path.insert(0, str(resources))
    pkg = manifest["library"]

    class Lib:
        pass

    lib = Lib()
    for name in _LIB_MODULES:
        setattr(lib, name.rpartition(".")[2], importlib.import_module(f"{pkg}.{name}"))
    return manifest, lib


class RotorCasingContact(Fmi2Slave):
    author = "rotorub developers"
    description = (
        "Blade-tip / casing contact of a turbofan fan module (Parent, Thouverez & Chevillot, EURODYN 2014): "
        "38-dof bladed rotor and flexible casing in the rotating frame, 2D or 3D contact. Spin speed and "
        "imbalance in, contact forces and gaps out. Wraps the rotorub_model library carried in resources/."
    )
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self._resources = Path(self.resources) if self.resources else Path(__file__).parent
        self._manifest, self._lib = _load_library(self._resources)
        self.version = self._manifest.get("library_version", "0")
        self.copyright = "rotorub developers"
        ref = self._lib.params.load_parameters(self._resources / self._manifest["parameters"])
        self._ref = ref
        self._n_blades = int(self._manifest["n_blades"])
        c = ref.contact
        self._specs = []
        self._declare_variables(ref)
        n = len(self._specs)
        self._rv = np.zeros(n)
        self._iv = np.zeros(n, dtype=np.int64)
        self._sv = [""] * n
        self._kind = [s[1] for s in self._specs]
        self._slot = {s[0]: i for i, s in enumerate(self._specs)}
        self._is_real = np.array([k == "Real" for k in self._kind])
        self._is_int = np.array([k == "Integer" for k in self._kind])
        self._settable = np.array([s[2] in ("input", "parameter") for s in self._specs])
        self._real_inputs = frozenset(self._slot[k] for k in ("Omega", "imbalance", "g0"))
        starts = {
            "Omega": 0.0, "imbalance": ref.imbalance.me, "g0": c.g0, "k_r": c.k_r, "mu": c.mu,
            "theta": math.radians(c.theta_deg), "chord": c.chord, "dt_max": 1e-3,
            "formulation": "3D", "mode": "transient", "param_file": "",
        }
        for name, v in starts.items():
            i = self._slot[name]
            if self._kind[i] == "String":
                self._sv[i] = v
            else:
                self._rv[i] = v
        for i, spec in enumerate(self._specs):
            self._register(i, spec)
        nb = self._n_blades
        # where the kernel writes each output of a state (its layout -> this slave's value buffer);
        # n_contact lands in the Real buffer's unused slot of that Integer and is copied over
        kern = self._lib.kernel
        self._out_index = np.array([self._slot[f"blade[{j + 1}].{b}"] for b in kern.OUT_BLADE_NAMES
                                    for j in range(nb)] + [self._slot[g] for g in kern.OUT_GLOBAL_NAMES],
                                   dtype=np.intc)
        self._n_contact_slot = self._slot["n_contact"]
        self._i_omega, self._i_me, self._i_g0 = self._slot["Omega"], self._slot["imbalance"], self._slot["g0"]
        self._i_dt, self._i_nsub = self._slot["dt_internal"], self._slot["n_substeps"]
        self._get_memo: tuple[list, np.ndarray] = ([], np.zeros(0, dtype=np.intp))
        self._phase = "instantiated"  # -> initialization -> step
        self._t = 0.0  # current communication point
        self._sim = None  # runtime objects, built at the end of initialization
        self._fatal_msg = None  # a configuration error: every step is refused until reset
        self._warned_fixed = set()

    # ------------------------------------------------------------------ variables
    def _declare_variables(self, ref) -> None:
        S = self._specs.append
        S(("Omega", "Real", "input", "continuous", "rad/s",
           "Spin speed of the rotor; held constant over each communication step (zero-order hold), >= 0"))
        S(("imbalance", "Real", "input", "continuous", "kg.m",
           "Imbalance m*e on the fan disk (angle and disk from the parameter file); held over each step, >= 0"))
        S(("formulation", "String", "parameter", "fixed", None, "Contact formulation: '2D' (tip point) or '3D' "
           "(conical casing, LE and TE points, chord law)"))
        S(("mode", "String", "parameter", "fixed", None, "Analysis mode: 'transient' (central differences, "
           "substeps inside each communication step) or 'quasi_static' (balanced static solution at the "
           "current inputs, warm-started from the last one, with its stability indicator)"))
        S(("param_file", "String", "parameter", "fixed", None, "Optional path to a rotorub TOML parameter file "
           "(empty: the reference file carried in the FMU); g0, k_r, mu, theta, chord below override its "
           "[contact] section"))
        S(("g0", "Real", "parameter", "tunable", "m", "Nominal blade-tip clearance (negative = interference); "
           "tunable between communication steps"))
        S(("k_r", "Real", "parameter", "fixed", "N/m", "Normal penalty stiffness of one whole blade tip"))
        S(("mu", "Real", "parameter", "fixed", "1", "Coulomb friction coefficient"))
        S(("theta", "Real", "parameter", "fixed", "rad", "Inclination of the conical casing inner surface (3D)"))
        S(("chord", "Real", "parameter", "fixed", "m", "Blade-tip chord length l_c (3D)"))
        S(("dt_max", "Real", "parameter", "fixed", "s", "Upper limit of the internal time step (transient mode); "
           "the step actually used is h/n with n = ceil(h / min(dt_max, half the central-difference "
           "stability limit)), h the communication step; must be > 0"))
        for j in range(1, self._n_blades + 1):
            b = f"blade[{j}]"
            S((f"{b}.F_N", "Real", "output", "continuous", "N", f"Normal contact force on blade {j}"))
            S((f"{b}.F_T", "Real", "output", "continuous", "N",
               f"Tangential (friction) contact force on blade {j}, mu*F_N, opposing the spin"))
            S((f"{b}.gap_LE", "Real", "output", "continuous", "m",
               f"Gap at the leading edge of blade {j} (3D; 2D: the tip gap); negative = penetration"))
            S((f"{b}.gap_TE", "Real", "output", "continuous", "m",
               f"Gap at the trailing edge of blade {j} (3D; 2D: the tip gap); negative = penetration"))
            S((f"{b}.gap_tip", "Real", "output", "continuous", "m",
               f"Tip gap of blade {j} (2D); 3D: the smaller of the LE and TE gaps (the gap is linear "
               "along the chord)"))
            S((f"{b}.contact_fraction", "Real", "output", "continuous", "1",
               f"Fraction of the chord of blade {j} in contact (2D: 0 or 1)"))
        S(("n_contact", "Integer", "output", "discrete", None, "Number of blades in contact (F_N > 0)"))
        for ax in "xyz":
            S((f"casing_force.{ax}", "Real", "output", "continuous", "N",
               f"Resultant contact force on the casing, fixed frame, {ax} component (z: axial)"))
        S(("friction_torque", "Real", "output", "continuous", "N.m",
           "Axial torque of the contact forces on the rotor (negative: brakes the spin)"))
        for ax in "xy":
            S((f"disk_displacement.{ax}", "Real", "output", "continuous", "m",
               f"Fan-disk centre displacement, fixed frame, {ax} component"))
        S(("gap_min", "Real", "output", "continuous", "m", "Smallest gap over all blades and contact points"))
        S(("max_real_eig", "Real", "output", "continuous", "1/s",
           "Largest real part of the eigenvalues linearised about the static solution (quasi_static mode; "
           "> 0: unstable); 0 in transient mode (not computed)"))
        S(("status", "Integer", "output", "discrete", None,
           "0 = ok, 1 = diverged (transient: penetration beyond 10 mm or non-finite state; quasi_static: "
           "no balanced solution found), 2 = bad input or configuration (message in the log and in 'message')"))
        S(("message", "String", "output", "discrete", None,
           "Cause of the last refused step (the text also sent to the FMI logger); empty after a step that "
           "succeeded. pythonfmu forwards log messages only when the master enables logging, this output "
           "does not depend on it"))
        S(("dt_internal", "Real", "output", "discrete", "s",
           "Internal time step used in the last communication step (transient mode; 0 in quasi_static)"))
        S(("n_substeps", "Integer", "output", "discrete", None,
           "Number of internal steps taken in the last communication step (transient mode)"))

    def _register(self, i: int, spec) -> None:
        name, kind, causality, variability, _unit, desc = spec
        caus = Fmi2Causality[causality]
        var = Fmi2Variability[variability]
        initial = Fmi2Initial.calculated if causality == "output" else None
        store, conv, cls = {"Real": (self._rv, float, Real), "Integer": (self._iv, int, Integer),
                            "String": (self._sv, str, String)}[kind]

        def getter(i=i, store=store, conv=conv):
            return conv(store[i])

        def setter(v, i=i, conv=conv):
            self._set_value(i, conv(v))

        v = cls(name, causality=caus, variability=var, description=desc, initial=initial, getter=getter,
                setter=setter)
        self.register_variable(v, nested=False)
        assert v.value_reference == i

    def _set_value(self, i: int, value) -> None:
        """Store a value set by the master; never raises (checks happen in do_step)."""
        name, kind, causality, variability = self._specs[i][:4]
        if not self._settable[i]:
            self.log(f"{name}: is an output and cannot be set; value ignored", Fmi2Status.error)
            return
        if self._phase == "step" and variability == "fixed":
            if name not in self._warned_fixed:
                self._warned_fixed.add(name)
                self.log(f"{name}: fixed parameter, cannot change after initialization (reset first); "
                         "new value ignored", Fmi2Status.warning)
            return
        if kind == "Real":
            self._rv[i] = value
        elif kind == "Integer":
            self._iv[i] = value
        else:
            self._sv[i] = value

    # fast paths for the per-step traffic (same semantics as pythonfmu's)
    def get_real(self, vrs):
        memo_vrs, idx = self._get_memo
        if vrs != memo_vrs:  # a master reads the same list every step: check and convert it once
            idx = np.asarray(vrs, dtype=np.intp)
            if not self._is_real[idx].all():
                raise TypeError(f"get_real: value reference(s) {idx[~self._is_real[idx]].tolist()} are not Real")
            self._get_memo = (list(vrs), idx)
        return self._rv.take(idx).tolist()

    def get_integer(self, vrs):
        idx = np.asarray(vrs, dtype=np.intp)
        if not self._is_int[idx].all():
            raise TypeError(f"get_integer: value reference(s) {idx[~self._is_int[idx]].tolist()} are not Integer")
        return self._iv[idx].tolist()

    def set_real(self, vrs, values):
        rv, inputs = self._rv, self._real_inputs
        for vr, v in zip(vrs, values):
            if vr in inputs:  # the per-step traffic: Omega, imbalance, g0 (tunable)
                rv[vr] = v
            elif self._kind[vr] != "Real":
                self.log(f"set_real: value reference {vr} is not Real; ignored", Fmi2Status.error)
            else:
                self._set_value(vr, float(v))

    def _r(self, name: str) -> float:
        return float(self._rv[self._slot[name]])

    def _s(self, name: str) -> str:
        return self._sv[self._slot[name]]

    # ------------------------------------------------------------------ model description
    def to_xml(self, model_options=None):
        """pythonfmu's description plus what it lacks: units, InitialUnknowns, a default experiment."""
        root = super().to_xml(model_options or {})
        children = list(root)
        units = Element("UnitDefinitions")
        for name, base in UNITS.items():
            u = SubElement(units, "Unit", name=name)
            if base:
                SubElement(u, "BaseUnit", {k: str(v) for k, v in base.items()})
        cs_pos = next(i for i, el in enumerate(children) if el.tag == "CoSimulation")
        root.insert(cs_pos + 1, units)
        if root.find("DefaultExperiment") is None:
            de = Element("DefaultExperiment", startTime="0", stopTime="1.5", stepSize="0.001")
            mv_pos = list(root).index(root.find("ModelVariables"))
            root.insert(mv_pos, de)
        for sv, spec in zip(root.find("ModelVariables"), self._specs):
            unit = spec[4]
            if unit is not None:
                sv.find("Real").set("unit", unit)
        ms = root.find("ModelStructure")
        outs = ms.find("Outputs")
        if outs is not None:
            init = SubElement(ms, "InitialUnknowns")
            for u in outs:
                SubElement(init, "Unknown", index=u.get("index"))
        return root

    # ------------------------------------------------------------------ FMI life cycle
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        self._t = float(start_time or 0.0)

    def enter_initialization_mode(self, *args):
        self._phase = "initialization"

    def exit_initialization_mode(self, *args):
        self._phase = "step"
        try:
            self._build()
        except Exception as exc:  # noqa: BLE001 - reported, never raised (pythonfmu would go fatal)
            self._configuration_error(self._message(exc))

    def terminate(self):
        self._phase = "terminated"

    def do_step(self, current_time, step_size):
        try:
            return self._do_step(float(current_time), float(step_size))
        except Exception as exc:  # noqa: BLE001 - last resort: report instead of dying
            self._report(STATUS_ERROR, f"internal error at t = {current_time:g} s: {self._message(exc)}")
            return False

    # ------------------------------------------------------------------ messages
    @staticmethod
    def _message(exc: Exception) -> str:
        return f"{type(exc).__name__}: {exc}" if not str(exc).strip() else str(exc)

    def _report(self, status: int, msg: str) -> None:
        self._iv[self._slot["status"]] = status
        self._sv[self._slot["message"]] = msg
        self.log(f"RotorCasingContact: {msg}", Fmi2Status.error if status == STATUS_ERROR else Fmi2Status.discard)

    def _configuration_error(self, msg: str) -> None:
        self._fatal_msg = msg
        self._sim = None
        self._report(STATUS_ERROR, msg + " (every step is refused until the FMU is reset)")

    # ------------------------------------------------------------------ building the model
    def _config(self) -> dict:
        return {k: (self._s(k) if self._kind[self._slot[k]] == "String" else self._r(k))
                for k in ("formulation", "mode", "param_file", "k_r", "mu", "theta", "chord", "dt_max")}

    def _build(self, config: dict | None = None) -> None:
        """Check the parameters and build model, contact and solver (raises with a message naming the cause)."""
        lib = self._lib
        cfg = config or self._config()
        self._fatal_msg = None
        self._sim = None
        if cfg["mode"] not in MODES:
            raise ValueError(f"mode: '{cfg['mode']}' unknown; accepted: {', '.join(MODES)}")
        if cfg["formulation"] not in FORMULATIONS:
            raise ValueError(f"formulation: '{cfg['formulation']}' unknown; accepted: {', '.join(FORMULATIONS)}")
        dt_max = cfg["dt_max"]
        if not (math.isfinite(dt_max) and dt_max > 0):
            raise ValueError(f"dt_max: {dt_max:g} s out of range; the internal time step limit must be finite "
                             "and > 0; accepted range (0, inf) s")
        path = cfg["param_file"].strip()
        params = lib.params.load_parameters(path) if path else self._ref
        if params.blades.count != self._n_blades:
            raise ValueError(f"param_file '{path}': blades.count = {params.blades.count}, but this FMU declares "
                             f"outputs for {self._n_blades} blades; rebuild it with "
                             f"`rotorub build-fmu --params {path}`")
        g0 = self._r("g0")
        params = params.replace(contact={"g0": g0, "k_r": cfg["k_r"], "mu": cfg["mu"],
                                         "theta_deg": math.degrees(cfg["theta"]), "chord": cfg["chord"]})
        if path:
            try:  # assembling a model needs scipy (the shaft's component modes)
                model = lib.model.build_model(params)
            except ModuleNotFoundError as exc:
                raise ValueError(f"param_file '{path}': assembling a model needs {exc.name} (pip install "
                                 f"{exc.name}); the model built into the FMU (empty param_file) needs only numpy") \
                    from None
        else:  # the matrices baked at build time: no assembly, numpy only
            model = lib.model.load_model(self._resources / self._manifest["model"], params)
        contact = lib.contact.make_contact(model, cfg["formulation"])
        sim = {"config": cfg, "model": model, "contact": contact, "g0": g0, "phi": 0.0, "q_static": None,
               "limit": (None, None), "plan": (None, None, 0), "transient": cfg["mode"] == "transient"}
        if cfg["mode"] == "transient":
            omega0 = self._r("Omega")
            w = omega0 if math.isfinite(omega0) and omega0 >= 0 else 0.0
            sim["cd"] = lib.transient.CentralDifference(model, contact, dt=None, t_ramp=0.0, omega_max_for_dt=w)
            sim["cd"].bind_outputs(self._out_index, self._rv)
            q = sim["cd"].q
        else:
            q = np.zeros(model.n_dofs)
        self._sim = sim
        self._iv[self._slot["status"]] = STATUS_OK
        self._write_outputs(q, 0.0, max_real=0.0)
        if cfg["mode"] == "quasi_static":
            err = self._check_inputs()
            if err is None:  # balanced solution at the initial inputs (else reported by the first step)
                ok, msg = self._quasi_static(self._r("Omega"), self._r("imbalance"), 0.0)
                if not ok:
                    self._report(STATUS_DIVERGED, msg)

    # ------------------------------------------------------------------ stepping
    def _check_inputs(self) -> str | None:
        rv = self._rv
        om, me, g0 = float(rv[self._i_omega]), float(rv[self._i_me]), float(rv[self._i_g0])
        if not math.isfinite(om) or om < 0:
            return f"Omega: {om!r} rad/s is not a valid spin speed; accepted range [0, inf) rad/s (finite)"
        if not math.isfinite(me) or me < 0:
            return f"imbalance: {me!r} kg.m out of range; accepted range [0, inf) kg.m (finite)"
        lb = self._sim["model"].params.blades.length if self._sim else math.inf
        if not math.isfinite(g0) or g0 <= -0.5 * lb:
            return f"g0: {g0!r} m out of range; accepted range (-blades.length/2 = {-0.5 * lb:g}, inf) m"
        return None

    def _do_step(self, t: float, h: float) -> bool:
        if self._fatal_msg is not None:
            self._report(STATUS_ERROR, self._fatal_msg + " (every step is refused until the FMU is reset)")
            return False
        if self._sim is None:
            self._configuration_error("do_step called before the end of initialization "
                                      "(fmi2ExitInitializationMode)")
            return False
        if not (math.isfinite(h) and h > 0):
            self._report(STATUS_ERROR, f"communication step size {h!r} s: must be finite and > 0")
            return False
        err = self._check_inputs()
        if err is not None:
            self._report(STATUS_ERROR, f"at t = {t:g} s: {err}; step refused, state unchanged")
            return False
        sim = self._sim
        rv = self._rv
        omega, me, g0 = float(rv[self._i_omega]), float(rv[self._i_me]), float(rv[self._i_g0])
        if g0 != sim["g0"]:
            sim["g0"] = g0
            self._apply_clearance(g0)
        if sim["transient"]:
            ok = self._transient(omega, me, h)
        else:
            ok, msg = self._quasi_static(omega, me, h)
            if not ok:
                self._report(STATUS_DIVERGED, f"at t = {t:g} s: {msg}")
        if ok:
            self._t = t + h
            self._iv[self._slot["status"]] = STATUS_OK
            self._sv[self._slot["message"]] = ""
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
            sim["plan"] = (h, band, max(1, math.ceil(h / cap * (1 - 1e-9))))
        return sim["plan"][2]

    def _transient(self, omega: float, me: float, h: float) -> bool:
        cd = self._sim["cd"]
        if cd.diverged:
            self._report(STATUS_DIVERGED, f"the run diverged at t = {cd.t:.6g} s (internal time); roll back "
                         "with fmi2SetFMUstate or reset the FMU")
            return False
        n = self._substeps(omega, h)
        dt = h / n
        if dt != cd.dt:  # restart the two-step scheme at the same velocity
            v = cd.velocity()
            cd.dt = dt
            cd.q_prev[:] = cd.q - dt * v
        done, _ = cd.advance(n, omega, me)  # the kernel writes the outputs into self._rv (bind_outputs)
        rv = self._rv
        self._iv[self._n_contact_slot] = rv[self._n_contact_slot]
        rv[self._i_dt] = dt
        self._iv[self._i_nsub] = done
        if done < n:
            pen = cd.max_penetration
            self._report(STATUS_DIVERGED, f"the run diverged at t = {cd.t:.6g} s (internal time): a gap fell "
                         f"below -{pen * 1e3:g} mm (blade through the casing liner, penalty contact meaningless) "
                         "or the state stopped being finite; outputs hold the last good step")
            return False
        return True

    def _quasi_static(self, omega: float, me: float, h: float) -> tuple[bool, str]:
        sim, lib = self._sim, self._lib
        st = lib.static.solve_static(sim["model"], sim["contact"], omega, me=me, q0=sim["q_static"])
        if not st.converged:
            return False, (f"no balanced static solution at Omega = {omega:g} rad/s, imbalance = {me:g} kg.m, "
                           f"g0 = {sim['g0']:g} m (relative residual {st.residual:.2e}); outputs hold the last "
                           "solution")
        stab = lib.stability.stability_of(sim["model"], sim["contact"], omega, st.q)
        sim["q_static"] = st.q
        sim["phi"] += omega * h
        self._rv[self._slot["dt_internal"]] = 0.0
        self._iv[self._slot["n_substeps"]] = 0
        self._write_outputs(st.q, sim["phi"], max_real=stab.max_real)
        return True, ""

    def _write_outputs(self, q: np.ndarray, phi: float, max_real: float) -> None:
        """The outputs of state q (the kernel's, as in every library analysis), fixed frame at angle phi."""
        self._sim["contact"].write_outputs(q, phi, self._out_index, self._rv)
        self._iv[self._n_contact_slot] = int(self._rv[self._n_contact_slot])
        self._rv[self._slot["max_real_eig"]] = max_real

    # ------------------------------------------------------------------ FMU state (rollback)
    def _get_fmu_state(self):
        """Everything a rollback needs: variable values, phase, solver state, warm start, outputs."""
        sim = self._sim
        state = {
            "version": STATE_VERSION,
            "rv": self._rv.copy(), "iv": self._iv.copy(), "sv": list(self._sv),
            "phase": self._phase, "t": self._t, "fatal": self._fatal_msg, "sim": None,
        }
        if sim is not None:
            s = {"config": dict(sim["config"]), "g0": sim["g0"], "phi": sim["phi"],
                 "q_static": None if sim["q_static"] is None else sim["q_static"].copy()}
            if "cd" in sim:
                t, steps, phi, q, q_prev, div, dt, g0 = sim["cd"].get_state()
                s["cd"] = {"t": t, "steps": steps, "phi": phi, "q": q, "q_prev": q_prev, "diverged": div,
                           "dt": dt, "g0": g0}
            state["sim"] = s
        return state

    def _set_fmu_state(self, state):
        try:
            self._restore(state)
        except Exception as exc:  # noqa: BLE001
            self._configuration_error(f"fmi2SetFMUstate: the state could not be restored ({self._message(exc)})")

    def _restore(self, state) -> None:
        if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
            raise ValueError(state.get("error", "not a RotorCasingContact state of this version")
                             if isinstance(state, dict) else "not a RotorCasingContact state")
        rv, iv = np.asarray(state["rv"], dtype=float), np.asarray(state["iv"], dtype=np.int64)
        if rv.shape != self._rv.shape:
            raise ValueError("the state was saved by an FMU with another variable set")
        self._rv[:] = rv
        self._iv[:] = iv
        self._sv[:] = list(state["sv"])
        self._phase, self._t, self._fatal_msg = state["phase"], float(state["t"]), state["fatal"]
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
            sim["cd"].set_state((c["t"], c["steps"], c["phi"], np.asarray(c["q"], dtype=float),
                                 np.asarray(c["q_prev"], dtype=float), c["diverged"], c["dt"], c["g0"]))
        if s["g0"] != sim["g0"]:
            sim["g0"] = s["g0"]
            self._apply_clearance(s["g0"])

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        # pythonfmu calls this without an instance, so the bundled library's results.plain
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

        return json.dumps(plain(state)).encode("utf-8")  # floats round-trip exactly (shortest repr)

    @staticmethod
    def _fmu_state_from_bytes(data: bytes):
        try:
            return json.loads(bytes(data).decode("utf-8"))
        except Exception as exc:  # noqa: BLE001 - surfaced by _set_fmu_state
            return {"version": None, "error": f"serialized state is not valid ({exc})"}
