"""Both flavours of RotorCasingContact.fmu built from a parameter file with imported blades (``[fe_blade]``: the
example's CalculiX blade, examples/fan_blade/example.toml) against the library and against each other.

The native FMU carries the reduced matrices (the Omega^4 term among them) and the imported tip's contact arrays as
the library builds them (builder.tip_data); the pythonfmu FMU carries the saved model (save_model keeps S4 and the
tip's arrays, numpy only). Both step by blocks from the library's BLOCK_MIN_DOFS on (the 14-blade disk: 214 dofs).
The tolerances are round-off: native and pythonfmu to the bit, both and the library to 1e-9.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="the FMU tests drive the FMU with fmpy (pip install -e '.[fmu]')")
pytest.importorskip("pythonfmu", reason="building the FMU needs pythonfmu (pip install -e '.[fmu]')")

from fmu_src.masters.fmi2 import FMUError, Slave, simulate  # noqa: E402
from rotorub_model.analyses.stability import stability_of  # noqa: E402
from rotorub_model.analyses.static import solve_static  # noqa: E402
from rotorub_model.analyses.transient import BLOCK_MIN_DOFS, run_transient  # noqa: E402
from rotorub_model.contact import make_contact  # noqa: E402
from rotorub_model.contact.liner import Liner  # noqa: E402
from rotorub_model.structure.model import build_model  # noqa: E402
from rotorub_model.structure.params import load_parameters  # noqa: E402

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fan_blade" / "example.toml"


def _names(nb: int, what: str) -> list[str]:
    return [f"blade[{j}].{what}" for j in range(1, nb + 1)]


def _builds(params_file: Path, dest: Path) -> dict:
    from fmu_src.models.contact.builder import build_fmu, build_native_fmu

    return {"native": build_native_fmu(dest / "native", params_file=params_file, platforms=("linux64",))["fmu"],
            "pythonfmu": build_fmu(dest / "py", params_file=params_file, platforms=("linux64",))["fmu"]}


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    """Both flavours of the example (ten imported blades, 158 dofs: the dense step) and its model."""
    p = load_parameters(EXAMPLE)
    return _builds(EXAMPLE, tmp_path_factory.mktemp("fe_fmu")), build_model(p)


@pytest.fixture(scope="module")
def fourteen(tmp_path_factory):
    """Fourteen imported blades (214 dofs: the FMUs step by blocks, as the library)."""
    d = tmp_path_factory.mktemp("fe_fmu14")
    text = EXAMPLE.read_text().replace("count = 10 ", "count = 14 ").replace(
        'superelement = "coarse/blade.npz"', f'superelement = "{(EXAMPLE.parent / "coarse" / "blade.npz").as_posix()}"')
    f = d / "fourteen.toml"
    f.write_text(text)
    model = build_model(load_parameters(f))
    assert model.n_dofs >= BLOCK_MIN_DOFS and model.block_layout is not None
    return _builds(f, d), model


def _transient(fmus: dict, model, formulation: str, g0: float, t_end: float = 1.2) -> tuple[dict, object]:
    p = model.params
    nb = p.blades.count
    omega, me = 3.4 * p.normalisation.omega_ref, p.imbalance.me
    sig = np.array([(0.0, omega, 0.0), (1.0, omega, me), (t_end + 1.0, omega, me)],
                   dtype=[("time", float), ("Omega", float), ("imbalance", float)])
    outs = _names(nb, "F_N") + _names(nb, "gap_LE") + _names(nb, "gap_TE") + _names(nb, "contact_fraction") + [
        "friction_torque", "casing_force.x", "gap_min", "status", "n_contact"]
    runs = {k: simulate(f, stop_time=t_end, output_interval=1e-3, input=sig,
                        start_values={"g0": g0, "formulation": formulation}, output=outs) for k, f in fmus.items()}
    lib = run_transient(model, make_contact(model, formulation, g0=g0), omega, t_end=t_end, t_ramp=1.0, me=me,
                        record_dt=1e-3, hold=1e-3)
    return runs, lib


def _check_against_library(runs: dict, lib, nb: int) -> None:
    a, b = runs["native"], runs["pythonfmu"]
    for name in a.dtype.names:
        assert np.array_equal(a[name], b[name]), name  # native and pythonfmu: the same bits
    assert not lib.diverged and np.all(a["status"] == 0)
    F = np.array([a[n] for n in _names(nb, "F_N")]).T[1:]
    scale = np.abs(lib.outputs["F_N"]).max()
    assert scale > 50.0 and a["n_contact"].max() >= 2, "the scenario must rub"
    assert np.abs(F - lib.outputs["F_N"]).max() <= 1e-9 * scale
    gaps = lib.outputs["gap"]  # (t, N, 2): the tip's leading and trailing stations
    for k, what in enumerate(("gap_LE", "gap_TE")):
        g = np.array([a[n] for n in _names(nb, what)]).T[1:]
        ref = gaps[:, :, min(k, gaps.shape[2] - 1)]  # 2D: the tip gap in both
        assert np.abs(g - ref).max() <= 1e-9 * np.abs(gaps).max()
    fr = np.array([a[n] for n in _names(nb, "contact_fraction")]).T[1:]
    assert np.abs(fr - lib.outputs["fraction"]).max() <= 1e-9
    assert 0.0 < fr.max() <= 1.0
    tq = lib.outputs["friction_torque"]
    assert np.abs(a["friction_torque"][1:] - tq).max() <= 1e-9 * np.abs(tq).max()


def test_both_flavours_validate(example):
    from fmpy.validation import validate_fmu

    fmus, _ = example
    for f in fmus.values():
        assert validate_fmu(f) == []


@pytest.mark.parametrize("formulation", ["3D", "2D"])
def test_transient_equals_library_and_flavours_agree_to_the_bit(example, formulation):
    """3D: the imported tip's chord stations (segments, compact rows, per-blade outputs: the leading and trailing
    stations' gaps); 2D: the built-in point tip on the imported blades' disk."""
    fmus, model = example
    runs, lib = _transient(fmus, model, formulation, 0.5e-3)
    _check_against_library(runs, lib, model.params.blades.count)


def test_block_step_of_fourteen_blades_equals_library(fourteen):
    """214 dofs: both FMUs step by blocks (hub, blades, casing) from the library's BLOCK_MIN_DOFS on, as the library
    does: the same bits between the flavours, the library's to 1e-9."""
    fmus, model = fourteen
    runs, lib = _transient(fmus, model, "3D", 0.5e-3)
    _check_against_library(runs, lib, model.params.blades.count)


def test_quasi_static_mode_equals_static_solver(example):
    """A speed sweep through contact in quasi_static mode, 3D: the balanced solution (the Omega^4 term in K(Omega))
    and its stability, as solve_static and stability_of give them."""
    fmus, model = example
    p = model.params
    nb = p.blades.count
    w_ref, g0, me = p.normalisation.omega_ref, 0.5e-3, p.imbalance.me
    speeds = np.linspace(3.2, 3.6, 5) * w_ref
    got = {}
    for flavour, f in fmus.items():
        with Slave(f, mode="quasi_static", formulation="3D", g0=g0, Omega=speeds[0], imbalance=me) as s:
            got[flavour] = []
            for k, w in enumerate(speeds):
                s.set(Omega=float(w))
                s.step(k * 0.1, 0.1)
                got[flavour].append((np.array(s.get_reals(_names(nb, "F_N"))), s.get("max_real_eig")))
    for (Fa, ra), (Fb, rb) in zip(got["native"], got["pythonfmu"]):
        # the forces to the bit; the eigenvalue through each flavour's own assembly of the 2n x 2n matrix (numpy's
        # products in the pythonfmu FMU, C loops in the native one): to round-off, as for the built-in blades
        assert np.array_equal(Fa, Fb) and ra == pytest.approx(rb, rel=1e-9)
    c = make_contact(model, "3D", g0=g0)
    q = solve_static(model, c, speeds[0], me=me).q
    touching = 0
    for (F, re), w in zip(got["native"], speeds):
        st = solve_static(model, c, float(w), me=me, q0=q)
        assert st.converged
        q = st.q
        F_ref = c.outputs(q, float(w))["F_N"]
        assert np.abs(np.array(F) - F_ref).max() <= 1e-9 * max(np.abs(F_ref).max(), 1.0)
        assert re == pytest.approx(stability_of(model, c, float(w), q).max_real, rel=1e-9, abs=1e-12)
        touching = max(touching, st.n_contact)
    assert touching >= 1


def test_wear_against_the_liner_by_station(example):
    """The abradable liner in both FMUs: its rows are the tip's stations, its band and footprint the tip's; the wear
    outputs equal each other to the bit and the library's liner (Liner.for_model) to 1e-9."""
    fmus, model = example
    p = model.params
    omega, me, g0, t_end = 3.4 * p.normalisation.omega_ref, p.imbalance.me, 0.3e-3, 1.2
    sig = np.array([(0.0, omega, 0.0), (1.0, omega, me), (t_end + 1.0, omega, me)],
                   dtype=[("time", float), ("Omega", float), ("imbalance", float)])
    outs = ["wear.depth_max", "wear.depth_mean", "wear.volume", "wear.plastic_work", "clearance_effective"]
    runs = {k: simulate(f, stop_time=t_end, output_interval=1e-3, input=sig,
                        start_values={"g0": g0, "formulation": "3D", "liner": "abradable", "yield_force": 50.0},
                        output=outs) for k, f in fmus.items()}
    for name in outs:
        assert np.array_equal(runs["native"][name], runs["pythonfmu"][name]), name
    c = make_contact(model, "3D", g0=g0)
    liner = Liner.for_model(model, c, wears=True, yield_force=50.0)
    assert liner.depth.shape[0] == c.n_rows == c.geometry.tips.n_rows
    lib = run_transient(model, c, omega, t_end=t_end, t_ramp=1.0, me=me, record_dt=1e-3, hold=1e-3, liner=liner)
    s = liner.summary()
    r = runs["native"]
    assert s["depth_max"] > 1e-6, "the liner must wear"
    assert r["wear.depth_max"][-1] == pytest.approx(s["depth_max"], rel=1e-9)
    assert r["wear.volume"][-1] == pytest.approx(s["volume"], rel=1e-9)
    assert r["wear.plastic_work"][-1] == pytest.approx(s["plastic_work"], rel=1e-9)
    assert not lib.diverged


def test_the_tip_geometry_is_built_in(example):
    """An imported tip's stations face the parameter file's cone: theta and chord are fixed at the built-in values
    (the model description's range says so) and another value is refused."""
    from fmpy import read_model_description

    fmus, model = example
    theta = math.radians(model.params.contact.theta_deg)
    for f in fmus.values():
        v = {x.name: x for x in read_model_description(f).modelVariables}
        assert float(v["theta"].min) == float(v["theta"].max) == pytest.approx(theta)
        assert float(v["chord"].start) == pytest.approx(make_contact(model, "3D").geometry.chord)
        assert "Built in" in v["theta"].description
    with pytest.raises(FMUError), Slave(fmus["native"], theta=0.0) as s:
        s.step(0.0, 1e-3)


@pytest.mark.slow  # the kit's 2 s run-up through both flavours and the library's reference: 20-25 s on 2 cores
def test_crosscheck_kit_of_the_example(example, tmp_path):
    """The cross-check kit written for the example's FMUs (rotorub build-fmu --params example.toml writes it):
    both flavours reproduce it through fmpy."""
    from fmu_src.masters import crosscheck as runs
    from fmu_src.models.contact import crosscheck as cc

    fmus, model = example
    cc.write_kit(tmp_path, model.params)
    for f in fmus.values():
        diff = runs.compare(runs.run_fmpy(f, tmp_path), tmp_path)
        assert max(diff.values()) <= 1e-9, diff


@pytest.mark.slow  # an FMI 3.0 build, the library's reference of the kit and the run: about 20 s on 2 cores
def test_fmi3_fmu_of_the_example_reproduces_its_kit(tmp_path):
    """`rotorub build-fmu --native --fmi3 --params example.toml`: the FMI 3.0 FMU (per-blade arrays) with the
    imported tip reproduces its own kit (FMI 3.0 columns) to the kit's bound."""
    from fmu_src.masters import crosscheck as runs
    from fmu_src.models.contact.builder import build_with_kit as build

    out = build(tmp_path, EXAMPLE, native=True, fmi3=True, platforms=("linux64",))
    r3 = runs.run_fmi3(out["fmu"], tmp_path)
    assert r3["n_contact"].max() >= 1
    assert max(runs.compare(r3, tmp_path).values()) <= 1e-9


@pytest.fixture(scope="module")
def fe_casing(tmp_path_factory):
    """The reference's blades facing a thin ring's modes from 180 FE frames ([fe_casing]): both FMUs."""
    from rotorub_model.fe.casing_modes import casing_from_matrices
    from rotorub_model.fe.coordinates import read_coordinates
    from rotorub_model.fe.matrix_market import read_dof_map, read_mm
    from rotorub_model.fe.ring_model import write_ring
    from rotorub_model.structure.params import REFERENCE_FILE

    d = tmp_path_factory.mktemp("fe_casing_fmu")
    text = REFERENCE_FILE.read_text().replace("ring_thickness = 0.135 ", "ring_thickness = 0.0135 ")
    f = d / "thin.toml"
    f.write_text(text + '\n[fe_casing]\nmodel = "casing.json"\n')
    info = write_ring(load_parameters(REFERENCE_FILE).replace(casing={"ring_thickness": 0.0135}), d / "ring", 180)
    nodes, comps = read_dof_map(info["dofs"])
    ids, xyz = read_coordinates(info["coordinates"])
    casing_from_matrices(read_mm(info["stiffness"]), read_mm(info["mass"]), nodes, comps, ids, xyz,
                         info["circle_nodes"], keep=(2, 3)).save(d / "casing.json")
    model = build_model(load_parameters(f))
    assert model.casing_ratios is not None
    return _builds(f, d), model


@pytest.mark.parametrize("formulation", ["3D", "2D"])
def test_fe_casing_transient_equals_library(fe_casing, formulation):
    """The built-in blades against an FE casing's modes: the geometry the kernel cannot make (its tangential
    ratios are the FE's) is built into the native FMU as the library makes it; the same bits in both FMUs, the
    library's to 1e-9."""
    fmus, model = fe_casing
    runs, lib = _transient(fmus, model, formulation, 0.5e-3)
    _check_against_library(runs, lib, model.params.blades.count)
