"""The study file (TOML, next to the parameter file): what is uncertain, what is asked, by which method.

Schema (``rotorub_model/data/study_example.toml`` is a commented example; docs/THEORY.md section 10):

``[study]``
    ``name``; ``model`` ("rotorub", or "ishigami": the analytic test function that checks the pipeline);
    ``params`` (a parameter file, relative to the study file; default: the CLI's ``--params`` or the
    reference); ``method`` ("montecarlo", "sobol", "morris", "form", "subset"); ``sampler`` (montecarlo:
    "qmc", randomised Sobol' points in ``replicates`` independent scramblings, or "mc", plain pseudo-random);
    ``n`` (montecarlo: points per replicate, a power of 2 for qmc; sobol: the base sample N, a power of 2;
    morris: trajectories; subset: points per step); ``replicates``; ``levels`` (morris grid); ``seed``;
    ``confidence`` (0.95); ``quantiles``; ``quantities`` (quantities.QUANTITIES); ``events`` (probabilities
    reported; form and subset take the first, a threshold on a value quantity); ``chunk`` (evaluations per
    task, default by analysis level).
``[operating]``
    ``speed`` (normalised, or "first_critical": the parameter file's own first critical speed) or
    ``speeds = [low, high]`` (a run-up through the range: detection quantities only, the worst speed);
    ``formulation`` ("3D" or "2D"); ``t_end``, ``t_ramp`` [s] of the transients.
``[inputs.NAME]``
    ``parameter`` (``section.field``, ``bearings.<name>.field``, ``engine.closure``, ``engine.offset``),
    ``distribution`` and its parameters (distributions.KINDS).
``[mistuning]``
    ``kind``, ``sd``, ``distribution``, ``truncate``, ``correlation`` (mistuning.py).
``[clearance_curve]``
    ``low``, ``high`` [m], ``n``: the build clearances of the rub-probability curve (default: where the rub
    probability goes from 0.1 % to 99.9 %).

Every check runs when the file is read, before any work: one :class:`ParameterError` line naming the key.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

from ..errors import ParameterError
from ..structure.params import Parameters, load_parameters, to_dict
from .distributions import Distribution, make_distribution
from .mistuning import MistuningSpec
from .quantities import LEVELS, NEEDS_MISTUNING, QUANTITIES, Event, Quantity, check_quantities, parse_event
from .targets import Target, check_support, resolve_target

METHODS = ("montecarlo", "sobol", "morris", "form", "subset")
MODELS = ("rotorub", "ishigami")
SAMPLERS = ("qmc", "mc")
STUDY_KEYS = ("name", "model", "params", "method", "sampler", "n", "replicates", "levels", "seed", "confidence",
              "quantiles", "quantities", "events", "chunk", "bootstrap")
OPERATING_KEYS = ("speed", "speeds", "formulation", "t_end", "t_ramp")
INPUT_KEYS = ("parameter", "distribution", "mean", "sd", "low", "high", "mode", "value")
CURVE_KEYS = ("low", "high", "n")
SECTIONS = ("study", "operating", "inputs", "mistuning", "clearance_curve")
SOBOL_MIN_N = 64  # base sample of the Saltelli design below which SALib's bootstrap intervals mean little
MORRIS_MIN_TRAJECTORIES = 4  # SALib's bootstrap of mu* resamples the trajectories


@dataclass(frozen=True)
class Input:
    name: str
    target: Target
    distribution: Distribution


@dataclass
class Study:
    name: str
    model: str
    method: str
    sampler: str
    n: int
    replicates: int
    levels: int
    seed: int
    confidence: float
    quantiles: tuple[float, ...]
    quantities: list[Quantity]
    events: list[Event]
    inputs: list[Input]
    mistuning: MistuningSpec | None
    params: Parameters | None
    params_file: str | None
    speed: float | str | None
    speeds: tuple[float, float] | None
    formulation: str
    t_end: float
    t_ramp: float
    curve: dict | None
    chunk: int
    bootstrap: int
    source: str = ""
    raw: dict = field(default_factory=dict)

    @property
    def dims(self) -> int:
        """Coordinates of the unit cube the samplers draw: one per input, one per blade when mistuned."""
        return len(self.inputs) + (self.mistuning.n_blades if self.mistuning else 0)

    @property
    def levels_needed(self) -> list[str]:
        return [lv for lv in LEVELS if lv in {q.level for q in self.quantities}]

    def quick(self) -> Study:
        """The same study on a smaller sample (the main job's and --quick's): a quarter to an eighth."""
        import dataclasses

        n = self.n
        if self.method == "montecarlo":
            n = max(64, _pow2_floor(n // 8)) if self.sampler == "qmc" else max(100, n // 8)
            n = min(n, self.n)
        elif self.method == "sobol":
            n = min(self.n, max(SOBOL_MIN_N, _pow2_floor(self.n // 8)))
        elif self.method == "morris":
            n = min(self.n, max(MORRIS_MIN_TRAJECTORIES, self.n // 4))
        elif self.method == "subset":
            n = min(self.n, max(500, self.n // 4))
        q = dataclasses.replace(self, n=n)
        try:
            check_method(q)  # the smaller sample must still carry the intervals asked for
        except ParameterError as exc:
            raise ParameterError(f"--quick: {exc}") from None
        return q

    def summary(self) -> dict:
        return {
            "name": self.name, "model": self.model, "method": self.method, "sampler": self.sampler, "n": self.n,
            "replicates": self.replicates if self.method == "montecarlo" and self.sampler == "qmc" else None,
            "seed": self.seed, "confidence": self.confidence, "params_file": self.params_file,
            "operating": {"speed": self.speed, "speeds": self.speeds, "formulation": self.formulation,
                          "t_end_s": self.t_end, "t_ramp_s": self.t_ramp},
            "quantities": {q.name: {"analysis": q.level, "unit": q.unit, "kind": q.kind, "definition": q.doc}
                           for q in self.quantities},
            "events": [e.text for e in self.events],
            "inputs": {i.name: {"parameter": i.target.name, "distribution": i.distribution.describe(),
                                "accepted_range": i.target.range_text()} for i in self.inputs},
            "mistuning": self.mistuning.summary() if self.mistuning else None,
            "source": self.source,
        }


def _pow2_floor(n: int) -> int:
    return 1 << max(int(n).bit_length() - 1, 0)


def _is_pow2(n: int) -> bool:
    return n > 0 and n & (n - 1) == 0


def _number(where: str, v: Any, lo: float, hi: float, rng: str, integer: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v) or (integer and v != int(v)):
        raise ParameterError(f"{where}: expected {'an integer' if integer else 'a number'} in {rng}, got {v!r}")
    if not lo <= v <= hi:
        raise ParameterError(f"{where}: {v!r} out of range; accepted range {rng}")
    return int(v) if integer else float(v)


def _unknown(where: str, table: dict, keys: tuple[str, ...]) -> None:
    bad = sorted(set(table) - set(keys))
    if bad:
        raise ParameterError(f"{where}.{bad[0]}: unknown key; accepted: {', '.join(keys)}")


def load_study(path: str | Path, params: Parameters | str | Path | None = None) -> Study:
    """Read and check a study file. ``params``: the parameters (or a parameter file) to use instead of the
    study's own ``params`` key (the CLI's --params)."""
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParameterError(f"study file '{path}': cannot be read ({exc.strerror or exc})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"study file '{path}': not valid TOML ({exc})") from None
    try:
        return study_from_dict(data, params=params, base=path.parent, source=str(path))
    except ParameterError as exc:
        raise ParameterError(f"{path.name}: {exc}") from None


def study_from_dict(data: dict, params: Parameters | str | Path | None = None, base: Path | None = None,
                    source: str = "") -> Study:
    """A checked :class:`Study` from a nested dict (the TOML file's tables)."""
    if not isinstance(data, dict):
        raise ParameterError("study: expected tables [study], [operating], [inputs.*], [mistuning]")
    _unknown("study file", {k: 1 for k in data}, SECTIONS)
    st = data.get("study")
    if not isinstance(st, dict):
        raise ParameterError("study: missing table [study] (method, n, quantities)")
    _unknown("study", st, STUDY_KEYS)
    model = st.get("model", "rotorub")
    if model not in MODELS:
        raise ParameterError(f"study.model: {model!r} unknown; accepted: {', '.join(MODELS)}")
    method = st.get("method", "montecarlo")
    if method not in METHODS:
        raise ParameterError(f"study.method: {method!r} unknown; accepted: {', '.join(METHODS)}")
    sampler = st.get("sampler", "qmc")
    if sampler not in SAMPLERS:
        raise ParameterError(f"study.sampler: {sampler!r} unknown; accepted: {', '.join(SAMPLERS)}")

    # the parameters: given, or the study's own file, or the reference
    params_file = None
    if isinstance(params, Parameters):
        p = params
    elif params is not None:
        params_file = str(params)
        p = load_parameters(params)
    elif model == "rotorub" and "params" in st:
        if not isinstance(st["params"], str):
            raise ParameterError(f"study.params: expected a file name, got {st['params']!r}")
        f = Path(st["params"])
        f = f if f.is_absolute() or base is None else base / f
        params_file = str(f)
        p = load_parameters(f)
    else:
        p = load_parameters(None) if model == "rotorub" else None

    quantities = check_quantities(st.get("quantities", ["y"] if model == "ishigami" else ["margin", "rub"]))
    if model == "ishigami" and any(q.level != "analytic" for q in quantities):
        raise ParameterError("study.quantities: the ishigami model answers 'y' only")
    if model == "rotorub" and any(q.level == "analytic" for q in quantities):
        raise ParameterError("study.quantities: 'y' is the ishigami test function's; accepted for rotorub: "
                             + ", ".join(k for k, q in QUANTITIES.items() if q.level != "analytic"))
    ev = st.get("events", [q.name for q in quantities if q.kind == "event"])
    if isinstance(ev, str) or not isinstance(ev, list):
        raise ParameterError(f"study.events: expected a list, got {ev!r}")
    events = [parse_event(e) for e in ev]
    for e in events:  # an event asks for its quantity (a threshold's value quantity, or the event itself)
        if e.quantity not in [q.name for q in quantities]:
            quantities.append(QUANTITIES[e.quantity])
        ls = e.limit_state
        if method in ("form", "subset") and ls and ls[0] not in [q.name for q in quantities]:
            quantities.append(QUANTITIES[ls[0]])  # FORM and subset sampling follow the limit state's value

    conf = _number("study.confidence", st.get("confidence", 0.95), 0.5, 0.999, "[0.5, 0.999]")
    qs = st.get("quantiles", [0.05, 0.5, 0.95])
    if isinstance(qs, str) or not isinstance(qs, list):
        raise ParameterError(f"study.quantiles: expected a list of levels in (0, 1), got {qs!r}")
    quantiles = tuple(_number("study.quantiles", q, 1e-6, 1 - 1e-6, "(0, 1)") for q in qs)
    seed = _number("study.seed", st.get("seed", 2026), 0, 2**32 - 1, "[0, 2^32)", integer=True)
    default_n = {"montecarlo": 1024, "sobol": 1024, "morris": 20, "form": 1, "subset": 2000}[method]
    n = _number("study.n", st.get("n", default_n), 1, 10**8, "[1, 1e8]", integer=True)
    reps = _number("study.replicates", st.get("replicates", 8), 1, 1000, "[2, 1000]", integer=True)
    levels = _number("study.levels", st.get("levels", 4), 2, 20, "[2, 20] (even)", integer=True)
    chunk = _number("study.chunk", st.get("chunk", 0), 0, 10**6, "[0, 1e6] (0: by analysis level)", integer=True)
    boot = _number("study.bootstrap", st.get("bootstrap", 1000), 100, 100000, "[100, 100000]", integer=True)

    # operating point
    op = data.get("operating", {})
    if not isinstance(op, dict):
        raise ParameterError("operating: expected a table")
    _unknown("operating", op, OPERATING_KEYS)
    formulation = op.get("formulation", "3D")
    if formulation not in ("2D", "3D"):
        raise ParameterError(f"operating.formulation: {formulation!r} unknown; accepted: 2D, 3D")
    speed, speeds = op.get("speed"), op.get("speeds")
    smax = p.normalisation.speed_max if p is not None else math.inf
    if model == "rotorub":
        if (speed is None) == (speeds is None):
            raise ParameterError("operating: give one of speed (normalised, or \"first_critical\") and "
                                 "speeds = [low, high] (a run-up)")
        if speed is not None and speed != "first_critical":
            speed = _number("operating.speed", speed, 1e-6, smax,
                            f"(0, {smax:g}] (normalised; normalisation.speed_max), or \"first_critical\"")
        if speeds is not None:
            if not isinstance(speeds, list) or len(speeds) != 2:
                raise ParameterError(f"operating.speeds: expected [low, high], got {speeds!r}")
            lo, hi = (_number("operating.speeds", s, 1e-3, smax, f"(0, {smax:g}] (normalised)") for s in speeds)
            if not lo < hi:
                raise ParameterError(f"operating.speeds: low {lo:g} must be below high {hi:g}")
            speeds = (lo, hi)
            slow = [q.name for q in quantities if q.level not in ("detection",)]
            if slow:
                raise ParameterError(f"operating.speeds: a run-up range answers detection quantities only; "
                                     f"'{slow[0]}' needs one operating point (operating.speed)")
    t_end = _number("operating.t_end", op.get("t_end", 4.0), 1e-3, 600.0, "(0, 600] s")
    t_ramp = _number("operating.t_ramp", op.get("t_ramp", 1.0), 0.0, t_end, f"[0, t_end = {t_end:g}] s")

    # inputs
    ins = data.get("inputs", {})
    if not isinstance(ins, dict):
        raise ParameterError("inputs: expected tables [inputs.NAME]")
    inputs: list[Input] = []
    for name, tab in ins.items():
        where = f"inputs.{name}"
        if not isinstance(tab, dict):
            raise ParameterError(f"{where}: expected a table (parameter, distribution and its parameters)")
        _unknown(where, tab, INPUT_KEYS)
        if model == "ishigami":
            tgt = Target(name, -math.inf, math.inf, False, "test")
        else:
            if "parameter" not in tab:
                raise ParameterError(f"{where}.parameter: missing (e.g. \"contact.g0\")")
            tgt = resolve_target(f"{where}.parameter", tab["parameter"], p)
        dist = make_distribution(where, {k: v for k, v in tab.items() if k != "parameter"})
        check_support(where, tgt, dist.support(), f"a {dist.kind} distribution")
        if tgt.name in [i.target.name for i in inputs]:
            raise ParameterError(f"{where}.parameter: {tgt.name} is an input already")
        inputs.append(Input(name, tgt, dist))
    if model == "ishigami" and len(inputs) != 3:
        raise ParameterError(f"inputs: the ishigami function takes 3 inputs, got {len(inputs)}")

    mist = None
    if "mistuning" in data:
        if model != "rotorub":
            raise ParameterError("mistuning: for model = \"rotorub\" only")
        mist = MistuningSpec.from_table(data["mistuning"], p.blades.count)
    needs = [q.name for q in quantities if q.name in NEEDS_MISTUNING]
    if needs and mist is None:
        raise ParameterError(f"study.quantities: '{needs[0]}' compares a mistuned disk with the tuned one; add a "
                             "[mistuning] table")
    if any(i.target.name == "engine.offset" for i in inputs):
        st_q = [q.name for q in quantities if q.level == "static"]
        if st_q:
            raise ParameterError(f"inputs: engine.offset (fixed frame) has no static solution in the rotating frame; "
                                 f"'{st_q[0]}' cannot take it: use detection or transient quantities")
    if not inputs and mist is None:
        raise ParameterError("inputs: nothing is uncertain; add [inputs.NAME] tables or a [mistuning] table")

    curve = None
    if "clearance_curve" in data:
        c = data["clearance_curve"]
        if not isinstance(c, dict):
            raise ParameterError("clearance_curve: expected a table (low, high, n)")
        _unknown("clearance_curve", c, CURVE_KEYS)
        lo = _number("clearance_curve.low", c.get("low", 0.0), -0.05, 0.1, "[-0.05, 0.1] m")
        hi = _number("clearance_curve.high", c.get("high", 0.005), -0.05, 0.1, "[-0.05, 0.1] m")
        if not lo < hi:
            raise ParameterError(f"clearance_curve.low: {lo:g} must be below high = {hi:g}")
        curve = {"low": lo, "high": hi, "n": _number("clearance_curve.n", c.get("n", 41), 3, 1000, "[3, 1000]",
                                                     integer=True)}

    study = Study(
        name=str(st.get("name", Path(source).stem if source else "study")), model=model, method=method,
        sampler=sampler, n=n, replicates=reps, levels=levels, seed=seed, confidence=conf, quantiles=quantiles,
        quantities=quantities, events=events, inputs=inputs, mistuning=mist, params=p, params_file=params_file,
        speed=speed, speeds=speeds, formulation=formulation, t_end=t_end, t_ramp=t_ramp, curve=curve, chunk=chunk,
        bootstrap=boot, source=source, raw=data)
    check_method(study)
    return study


def check_method(s: Study) -> None:
    """The method's own demands on the sample (before any work)."""
    if s.method == "montecarlo":
        if s.sampler == "qmc":
            if not _is_pow2(s.n) or s.n < 16:
                raise ParameterError(f"study.n: {s.n}; the qmc sampler takes a power of 2, at least 16 (Sobol' "
                                     "points are balanced in powers of 2), e.g. 1024")
            if s.replicates < 2:
                raise ParameterError(f"study.replicates: {s.replicates}; a randomised-QMC interval needs at least 2 "
                                     "independent replicates (accepted: [2, 1000], 8 or more recommended)")
        elif s.n < 10:
            raise ParameterError(f"study.n: {s.n}; a Monte Carlo interval needs at least 10 points")
        total = s.n * (s.replicates if s.sampler == "qmc" else 1)
        alpha = 1.0 - s.confidence
        for q in s.quantiles:  # the distribution-free interval of a quantile exists from this many points on
            need = math.ceil(math.log(alpha / 2) / math.log(max(q, 1 - q)))
            if total < need:
                raise ParameterError(f"study.n: {total} points are too few for a {s.confidence:g} interval of the "
                                     f"{q:g} quantile (the order statistics bracket it from {need} points on); "
                                     "accepted: more points, or a less extreme quantile")
    if s.method in ("sobol", "morris"):
        try:
            import SALib  # noqa: F401
        except ImportError:
            raise ParameterError(f"study.method: {s.method} runs on SALib, not installed; pip install "
                                 "'rotorub[uq]'") from None
    if s.method == "sobol":
        if not _is_pow2(s.n) or s.n < SOBOL_MIN_N:
            raise ParameterError(f"study.n: {s.n}; Sobol' indices take a base sample N that is a power of 2, at least "
                                 f"{SOBOL_MIN_N} (below, SALib's bootstrap intervals mean little), e.g. 1024")
        for i in s.inputs:
            if i.distribution.variance == 0.0:
                raise ParameterError(f"inputs.{i.name}: zero variance ({i.distribution.describe()}); a Sobol' index "
                                     "of an input that does not vary is undefined: remove it from a sobol study or "
                                     "give it a spread")
        if s.mistuning is not None and s.mistuning.sd == 0.0:
            raise ParameterError("mistuning.sd: zero variance asked for a Sobol' index")
    elif s.method == "morris":
        if s.n < MORRIS_MIN_TRAJECTORIES:
            raise ParameterError(f"study.n: {s.n} trajectories; the Morris intervals (bootstrap over trajectories) "
                                 f"need at least {MORRIS_MIN_TRAJECTORIES}, 20 or more recommended")
        if s.levels % 2:
            raise ParameterError(f"study.levels: {s.levels}; Morris' grid takes an even number of levels (SALib)")
        for i in s.inputs:
            if i.distribution.variance == 0.0:
                raise ParameterError(f"inputs.{i.name}: zero variance; an elementary effect of an input that does not "
                                     "vary is undefined: remove it from a morris study")
    elif s.method in ("form", "subset"):
        try:
            import openturns  # noqa: F401
        except ImportError:
            raise ParameterError(f"study.method: {s.method} runs on OpenTURNS, not installed; pip install "
                                 "'rotorub[uq]' (OpenTURNS is large: about 250 MB)") from None
        if not s.events or s.events[0].limit_state is None:
            raise ParameterError(f"study.events: {s.method} needs a limit state: the first event a threshold on a "
                                 "value quantity, e.g. \"rub\" (margin < 0) or \"peak_force > 500\"")
        if s.mistuning is not None and s.mistuning.correlation > 0:
            raise ParameterError(f"mistuning.correlation: {s.method} takes independent blades (set 0)")
        if s.method == "subset" and s.n < 100:
            raise ParameterError(f"study.n: {s.n} points per subset step; accepted: 100 or more (1000 typical)")
        if not s.inputs and s.mistuning is None:
            raise ParameterError("inputs: nothing is uncertain")


def spec_json(study: Study, speeds: list[float]) -> str:
    """The evaluation spec every worker receives (plain JSON; its hash keys the resumable rows)."""
    return json.dumps({
        "model": study.model,
        "params": to_dict(study.params) if study.params is not None else None,
        "formulation": study.formulation,
        "speeds": [float(s) for s in speeds],
        "quantities": [q.name for q in study.quantities],
        "targets": [i.target.name for i in study.inputs],
        "t_end": study.t_end,
        "t_ramp": study.t_ramp,
    }, sort_keys=True)
