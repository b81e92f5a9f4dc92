"""LPSpool: FMI 2.0 co-simulation slave for the speed of the low-pressure spool, written with pythonfmu.

This file is the pythonfmu script of the pythonfmu ``LPSpool.fmu`` (built by
:func:`fmu_src.models.spool.builder.build_spool_fmu`, which stages it under a hashed module name,
``lpspool_<hash>``: every pythonfmu FMU in a process shares one ``sys.modules``). It is the example of
a slave in Python; the engine system uses the native spool (model.c next to this file), which has
the same variables, value references, ranges and numbers to round-off. Both take their variables from
variables.py: the build writes them, and the model description, into this slave's resources (it imports
nothing of fmu_src). numpy is not even needed.

Model: one rigid spool of polar inertia J,

    J dOmega/dt = tau_drive(t) - c_w Omega^2 + tau_ext,

``tau_ext`` the input ``friction_torque`` (the axial torque of the blade-tip contact
forces on the rotor, negative when it brakes), ``c_w Omega^2`` the windage. The drive
torque is a schedule in time, designed so that the rub-free spool follows the speed
schedule

    Omega_s(t) = Omega0 + (Omega1 - Omega0) (1 - cos(pi x)) / 2,   x = clip((t - t_ramp_start) / t_ramp, 0, 1),

exactly: tau_drive(t) = J dOmega_s/dt + c_w Omega_s(t)^2 (feed-forward, open loop: the
drive does not react to the rub). The speed is C1 and the drive torque continuous.

Integration: the state is the deviation e = Omega - Omega_s(t) from the schedule,

    J de/dt = tau_ext - c_w e (2 Omega_s(t) + e),

advanced over each communication step [t, t + h] by classical RK4 in n equal
substeps, n = ceil(h / dt_max), with tau_ext held (zero-order hold, as a master sets
it). With tau_ext = 0 and e(0) = 0 every RK4 stage is exactly 0, so the rub-free
spool reproduces Omega_s(t) to the last bit; with rub the scheme's error is
O(dt^4) on e, a small quantity. Omega = Omega_s(t) + e is the output.

pythonfmu turns an exception escaping a callback into fmi2Fatal and destroys the
Python instance, so no callback lets one out: bad parameters or inputs make
``do_step`` return False (fmi2Discard) after logging a message (status fmi2Error)
that names the variable, and the instance stays usable (corrected inputs,
fmi2SetFMUstate or fmi2Reset).
"""

from __future__ import annotations

import json
import math
import zlib
from pathlib import Path
from types import SimpleNamespace
from xml.etree.ElementTree import fromstring

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real, String
from pythonfmu.enums import Fmi2Status

MANIFEST = "lpspool.json"  # the variables (start values included), the constants, the GUID
DESCRIPTION_FILE = "model_description.xml"  # written by the build (fmu_src/fmi/pythonfmu.py), read by to_xml
STATUS_OK, STATUS_STOPPED, STATUS_ERROR = 0, 1, 2
STATE_VERSION = 3


class LPSpool(Fmi2Slave):
    author = "rotorub developers"
    description = "Speed of the low-pressure spool of a turbofan (pythonfmu flavour)"
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.version = "1.0"
        self.copyright = "rotorub developers"
        self._here = here = Path(self.resources) if self.resources else Path(__file__).parent
        manifest = json.loads((here / MANIFEST).read_text())
        self._if = itf = SimpleNamespace(**manifest["constants"])
        self.guid = manifest["guid"]  # derived from the variables and the script at build time
        self.description = itf.DESCRIPTION
        self._vars = [SimpleNamespace(**v) for v in manifest["variables"]]  # value-reference order
        n = len(self._vars)
        self._values: list = [0.0] * n
        self._slot = {v.name: i for i, v in enumerate(self._vars)}
        for v in self._vars:
            if v.start is not None:
                self._values[v.vr] = float(v.start)
        self._values[self._slot["status"]] = STATUS_OK
        self._values[self._slot["message"]] = ""
        self._stopped = None  # (time, reason) once a step was refused because the spool stopped
        for i, v in enumerate(self._vars):
            self._register(i, v)
        self._phase = "instantiated"  # -> initialization -> step -> terminated
        self._t = 0.0  # current communication point
        self._e = 0.0  # state: Omega - Omega_schedule
        self._cfg = None  # checked parameters (dict), set at the end of initialization
        self._fatal_msg = None  # configuration error: every step is refused until reset
        self._pending = None  # a value refused at its set: the next step is refused with it
        self._warned_fixed = set()
        self._update_outputs()

    # ------------------------------------------------------------------ variables
    def _register(self, i: int, v) -> None:
        name, causality, variability, desc = v.name, v.causality, v.variability, v.description
        cls, conv = {"Real": (Real, float), "Integer": (Integer, int), "String": (String, str)}[v.type]
        initial = Fmi2Initial.calculated if causality == "output" else None

        def getter(i=i, conv=conv):
            return conv(self._values[i])

        def setter(v, i=i, conv=conv):
            self._set_value(i, conv(v))

        var = cls(name, causality=Fmi2Causality[causality], variability=Fmi2Variability[variability],
                  description=desc, initial=initial, getter=getter, setter=setter)
        self.register_variable(var, nested=False)
        assert var.value_reference == i

    def _set_value(self, i: int, value) -> None:
        """Store a value set by the master; never raises (checks happen in initialization and do_step)."""
        v = self._vars[i]
        name, causality, variability = v.name, v.causality, v.variability
        rng = None if v.min is None else (v.min, v.max)
        if causality == "output":
            self.log(f"{name}: is an output and cannot be set; value ignored", Fmi2Status.error)
            return
        if variability == "fixed" and self._phase in ("step", "terminated"):
            if name not in self._warned_fixed:
                self._warned_fixed.add(name)
                self.log(f"{name}: fixed parameter, cannot change after initialization (reset first); new value "
                         "ignored", Fmi2Status.warning)
            return
        if rng is not None and not (math.isfinite(value) and rng[0] <= value <= rng[1]):
            self.log(f"{name} = {value!r} out of range; accepted range [{rng[0]!r}, {rng[1]!r}]; value ignored "
                     "(the next step is refused)", Fmi2Status.error)
            self._pending = f"{name} = {value!r} out of range; accepted range [{rng[0]!r}, {rng[1]!r}]"
            return
        self._values[i] = value

    def _v(self, name: str) -> float:
        return self._values[self._slot[name]]

    def _set_out(self, name: str, value) -> None:
        self._values[self._slot[name]] = value

    # ------------------------------------------------------------------ model description
    def to_xml(self, model_options=None):
        """The model description the build wrote from variables.py (fmu_src/fmi/description.py: the native spool's
        writer); pythonfmu calls this at build time only."""
        return fromstring((self._here / DESCRIPTION_FILE).read_bytes())

    # ------------------------------------------------------------------ FMI life cycle
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        t0 = float(start_time or 0.0)
        self._t = t0 if math.isfinite(t0) else 0.0
        self._update_outputs()

    def enter_initialization_mode(self, *args):
        self._phase = "initialization"

    def exit_initialization_mode(self, *args):
        self._phase = "step"
        try:
            self._cfg = self._check_parameters()
            self._fatal_msg = None
            self._e = 0.0
            self._set_out("status", STATUS_OK)
        except ValueError as exc:
            self._configuration_error(str(exc))
        except Exception as exc:  # noqa: BLE001 - reported, never raised (pythonfmu would go fatal)
            self._configuration_error(f"{type(exc).__name__}: {exc}")
        self._update_outputs()

    def terminate(self):
        self._phase = "terminated"

    def do_step(self, current_time, step_size):
        try:
            return self._do_step(float(current_time), float(step_size))
        except Exception as exc:  # noqa: BLE001 - last resort: report instead of dying
            self._report(STATUS_ERROR, f"internal error at t = {current_time!r} s: {type(exc).__name__}: {exc}; "
                         "step refused")
            return False

    # ------------------------------------------------------------------ messages
    def _report(self, status: int, msg: str) -> None:
        self._set_out("status", status)
        self._set_out("message", msg)
        self.log(f"LPSpool: {msg}", Fmi2Status.error if status == STATUS_ERROR else Fmi2Status.discard)

    def _configuration_error(self, msg: str) -> None:
        self._fatal_msg = msg
        self._cfg = None
        self._report(STATUS_ERROR, msg + " (every step is refused until the FMU is reset)")

    # ------------------------------------------------------------------ physics
    def _check_parameters(self) -> dict:
        """The parameters, checked against their declared ranges (raises ValueError naming the first bad one)."""
        out = {}
        for v in self._vars:
            if v.causality != "parameter":
                continue
            x = float(self._v(v.name))
            if not (math.isfinite(x) and v.min <= x <= v.max):
                raise ValueError(f"{v.name} = {x!r} {v.unit} out of range; accepted range [{v.min!r}, {v.max!r}]")
            out[v.name] = x
        return out

    def _schedule(self, t: float) -> tuple[float, float]:
        """(Omega_s(t), dOmega_s/dt) of the speed schedule."""
        cfg = self._cfg if self._cfg is not None else {k: float(self._v(k)) for k in self._if.DEFAULTS}
        x = (t - cfg["t_ramp_start"]) / cfg["t_ramp"]
        if not x > 0.0:  # also NaN: before the start
            return cfg["Omega0"], 0.0
        if x >= 1.0:
            return cfg["Omega1"], 0.0
        d = cfg["Omega1"] - cfg["Omega0"]
        return cfg["Omega0"] + 0.5 * d * (1.0 - math.cos(math.pi * x)), 0.5 * d * math.pi / cfg["t_ramp"] * math.sin(
            math.pi * x)

    def _update_outputs(self) -> None:
        """Outputs at the current communication point from (t, e)."""
        try:
            ws, wsd = self._schedule(self._t)
            cfg = self._cfg if self._cfg is not None else {k: float(self._v(k)) for k in self._if.DEFAULTS}
            w = ws + self._e
            self._set_out("Omega", w)
            self._set_out("Omega_schedule", ws)
            self._set_out("drive_torque", cfg["J"] * wsd + cfg["c_w"] * ws * ws)
            self._set_out("windage_torque", cfg["c_w"] * w * w)
        except Exception as exc:  # noqa: BLE001 - e.g. t_ramp = 0 before initialization: outputs stay as they are
            self.log(f"LPSpool: outputs not updated ({type(exc).__name__}: {exc})", Fmi2Status.warning)

    def _rk4(self, t: float, h: float, e: float, tau: float) -> float:
        """e(t + h) by RK4 in n = ceil(h / dt_max) substeps at the held external torque tau."""
        cfg = self._cfg
        J, cw = cfg["J"], cfg["c_w"]
        n = max(1, math.ceil(h / cfg["dt_max"] * (1.0 - 1e-12)))
        ds = h / n

        def f(s, e):
            return (tau - cw * e * (2.0 * self._schedule(s)[0] + e)) / J

        for i in range(n):
            s = t + i * ds
            k1 = f(s, e)
            k2 = f(s + 0.5 * ds, e + 0.5 * ds * k1)
            k3 = f(s + 0.5 * ds, e + 0.5 * ds * k2)
            k4 = f(s + ds, e + ds * k3)
            e = e + ds / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        return e

    def _do_step(self, t: float, h: float) -> bool:
        if self._fatal_msg is not None:
            self._report(STATUS_ERROR, self._fatal_msg + " (every step is refused until the FMU is reset)")
            return False
        if self._cfg is None:
            self._report(STATUS_ERROR, "do_step called before the end of initialization (fmi2ExitInitializationMode)")
            return False
        if self._stopped is not None:
            self._report(STATUS_ERROR, f"fmi2DoStep: the FMU ended this simulation at t = {self._stopped[0]!r} s "
                         f"(fmi2Terminated is true): {self._stopped[1]}; call fmi2Terminate, or roll back with "
                         "fmi2SetFMUstate to a state saved before, or fmi2Reset")
            return False
        if self._pending is not None:
            msg, self._pending = self._pending, None
            self._report(STATUS_ERROR, f"at t = {t:g} s: step refused: {msg}")
            return False
        if not (math.isfinite(h) and h > 0):
            self._report(STATUS_ERROR, f"communication step size {h!r} s: must be finite and > 0; step refused")
            return False
        if not math.isfinite(t) or abs(t - self._t) > 1e-9 * max(abs(self._t), h):
            self._report(STATUS_ERROR, f"currentCommunicationPoint = {t!r} does not match the FMU's time {self._t!r} "
                         "(steps must follow each other; to go back, use fmi2SetFMUstate)")
            return False
        n = math.ceil(h / self._cfg["dt_max"] * (1.0 - 1e-12))
        if not n <= self._if.MAX_SUBSTEPS:
            dt_max = self._cfg["dt_max"]
            self._report(STATUS_ERROR, f"communication step h = {h!r} s needs {float(n):.3g} substeps of at most "
                         f"dt_max = {dt_max!r} s; at most {self._if.MAX_SUBSTEPS} are taken in one step (h <= "
                         f"{self._if.MAX_SUBSTEPS * dt_max!r} s); step refused, state unchanged")
            return False
        tau = float(self._v("friction_torque"))
        e = self._rk4(t, h, self._e, tau)
        w = self._schedule(t + h)[0] + e
        if not (math.isfinite(w) and w >= 0):
            msg = (f"the spool would stop (Omega = {w!r} rad/s at the end of the step, friction_torque = {tau:g} N.m); "
                   "step refused, state unchanged")
            self._stopped = (t, msg)
            self._report(STATUS_STOPPED, f"at t = {t:g} s: {msg}")
            return False
        self._e = e
        self._t = t + h
        self._set_out("status", STATUS_OK)
        self._set_out("message", "")
        self._update_outputs()
        return True

    # ------------------------------------------------------------------ FMU state (rollback)
    def _get_fmu_state(self):
        return {"version": STATE_VERSION, "guid": str(self.guid), "values": list(self._values), "phase": self._phase,
                "t": self._t, "e": self._e, "cfg": None if self._cfg is None else dict(self._cfg),
                "fatal": self._fatal_msg, "stopped": None if self._stopped is None else list(self._stopped)}

    def _set_fmu_state(self, state):
        try:  # everything checked before anything changes: a refused state leaves the instance as it was
            if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
                why = state.get("error") if isinstance(state, dict) else None
                raise ValueError(why or "not an LPSpool state of this version")
            if state.get("guid") != str(self.guid):
                raise ValueError("saved by another FMU or build (its GUID is not this FMU's)")
            values = list(state["values"])
            if len(values) != len(self._values):
                raise ValueError("the state was saved by an FMU with another variable set")
            phase, t, e = state["phase"], float(state["t"]), float(state["e"])
            if phase not in ("instantiated", "initialization", "step", "terminated") or not (
                    math.isfinite(t) and math.isfinite(e)):
                raise ValueError("phase, time or state invalid")
            cfg = None if state["cfg"] is None else dict(state["cfg"])
            stopped = None if state.get("stopped") is None else (float(state["stopped"][0]), str(state["stopped"][1]))
        except Exception as exc:  # noqa: BLE001 - pythonfmu cannot return fmi2Error: logged, the next step refused
            msg = f"fmi2SetFMUstate: not a state of this FMU ({type(exc).__name__}: {exc}); nothing restored"
            self._pending = msg
            self._set_out("message", msg)
            self.log(f"LPSpool: {msg}", Fmi2Status.error)
            return
        self._values[:] = values
        self._phase, self._t, self._e, self._cfg = phase, t, e, cfg
        self._fatal_msg = state["fatal"]
        self._stopped = stopped
        self._pending = None

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        payload = json.dumps(state).encode("utf-8")  # floats round-trip exactly (shortest repr)
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
