"""A twisted, tapered fan blade meshed with gmsh, its matrices computed with CalculiX at rest and at speed.

The project's own example of "bring your own blade" (docs/THEORY.md section 9, README "Bring your own
blade"): a titanium plate-like blade, clamped at the hub radius (400 mm) and reaching the reference's tip
radius (1000 mm), its chord tapering from 280 to 250 mm and its thickness from 10 to 6 mm, its stagger (the
chord's angle from the spin axis) twisting from 25 deg at the root to 45 deg at the tip (the reference blade's
45 deg at the tip). About the reference blade's mass (5.7 kg against 5.8) and first frequency (25.8 Hz at rest
against 25.0).

Everything is written in N-mm-t-s, as an FE engineer's deck usually is. Quadratic tetrahedra (C3D10); the
root face is clamped (*BOUNDARY on every node at r = 400 mm); the contact (tip) nodes are the nodes on the
tip face's two long edges, from the leading to the trailing edge (``tip_nodes.txt``). The tip is ground to
the casing's cone (``--cone-deg``, the reference casing's 5 deg): every tip node's radius is
r_tip - z tan(theta), z axial from the disk's station, as a fan's tips are ground on the assembled rotor to
the casing's line (a flat-cut tip, ``--cone-deg 0``, facing a 5 deg cone would touch at its trailing edge
only: its leading edge sits 16 mm further from the casing). The blade's shape is the script's options
(``--chord``, ``--thickness``, ``--stagger``, ``--radii``: root and tip values, linear along the span).
One CalculiX job a speed: at rest, a *FREQUENCY step; at speed, a *STATIC step under the centrifugal load
(CENTRIF about the z axis) then *FREQUENCY steps with PERTURBATION: their stiffness holds the stress
stiffening, the spin softening and the initial-displacement stiffness of the static deflection, so it is
exactly K0 + Omega^2 K1 + Omega^4 K2 (the importer's model; measured: four speeds fit to rounding). With
``--nlgeom`` the static step is geometrically nonlinear: the deflection is then not linear in Omega^2 and
neither is K(Omega) a polynomial (measured: 0.25 % on the frequencies from a least-squares fit over four
speeds, 1 % at a speed held out of a three-speed fit, on a mode that veers; docs/THEORY.md 9). Each job writes its own
eigenfrequencies (.dat) and its matrices (*FREQUENCY, SOLVER=MATRIXSTORAGE: .sti, .mas, .dof). A last job
of the unclamped blade stores its whole mass matrix (the root's rows too: the blade's rigid mass on the disk).

Needs the Debian packages gmsh and calculix-ccx (``apt-get install -y -q calculix-ccx gmsh``).

    python examples/fan_blade/make_fan_blade.py --out /tmp/fan --mesh-size 30        # coarse, seconds
    python examples/fan_blade/make_fan_blade.py --out /tmp/fan_fine --mesh-size 9.5  # ~60 000 dofs
    python examples/fan_blade/make_fan_blade.py --out /tmp/mine --chord 300 220 --thickness 12 5 \
        --stagger 20 50                                                                  # a blade of your own

Then ``rotorub import-blade`` (or :func:`import_example`) reads the jobs.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

HUB, TIP = 400.0, 1000.0  # [mm]
CHORD = (280.0, 250.0)  # root, tip [mm]
THICK = (10.0, 6.0)  # [mm]
STAGGER = (25.0, 45.0)  # [deg] from the spin axis: the reference blade's 45 deg at the tip
CONE = 5.0  # [deg] the casing's cone (the reference's contact.theta_deg): the tip is ground to it
E, NU, RHO = 114000.0, 0.34, 4.43e-9  # Ti-6Al-4V in N-mm-t-s: MPa, -, t/mm^3
OMEGA_TOP = 12.0 * 53.4  # [rad/s] the reference's speed_max * omega_ref
N_SECTIONS = 7


@dataclass(frozen=True)
class Shape:
    """The blade's dimensions: (root, tip) pairs, linear along the span; millimetres and degrees."""

    radii: tuple[float, float] = (HUB, TIP)
    chord: tuple[float, float] = CHORD
    thickness: tuple[float, float] = THICK
    stagger: tuple[float, float] = STAGGER
    cone_deg: float = CONE

    def check(self) -> None:
        for name in ("radii", "chord", "thickness", "stagger"):
            v = getattr(self, name)
            if len(v) != 2 or not all(np.isfinite(v)):
                raise SystemExit(f"--{name}: two finite numbers (root, tip), got {v!r}")
        if not 0 < self.radii[0] < self.radii[1]:
            raise SystemExit(f"--radii: 0 < hub < tip [mm], got {self.radii!r}")
        if min(self.chord) <= 0 or min(self.thickness) <= 0 or any(t >= c for t, c in zip(self.thickness, self.chord)):
            raise SystemExit(f"--chord, --thickness: positive, the thickness below the chord, got {self.chord!r}, "
                             f"{self.thickness!r}")
        if not all(0 <= b < 90 for b in self.stagger):
            raise SystemExit(f"--stagger: [0, 90) deg from the spin axis, got {self.stagger!r}")
        if not 0 <= self.cone_deg < 45:
            raise SystemExit(f"--cone-deg: [0, 45) deg, got {self.cone_deg!r}")


def geo_text(mesh_size: float, shape: Shape = Shape()) -> str:
    """gmsh script: sections at N_SECTIONS radii (rectangles of the local chord and thickness turned by the
    local stagger), a ThruSections solid, second-order tetrahedra."""
    lines = ['SetFactory("OpenCASCADE");', "Mesh.ElementOrder = 2;", "Mesh.SecondOrderLinear = 0;",
             f"Mesh.MeshSizeMax = {mesh_size};", f"Mesh.MeshSizeMin = {mesh_size / 4};",
             "Mesh.Optimize = 1;", "Mesh.OptimizeNetgen = 0;"]
    loops = []
    (hub, tip), ch, th, st = shape.radii, shape.chord, shape.thickness, shape.stagger
    for i in range(N_SECTIONS):
        s = i / (N_SECTIONS - 1)
        r = hub + s * (tip - hub)
        c = ch[0] + s * (ch[1] - ch[0])
        t = th[0] + s * (th[1] - th[0])
        b = np.radians(st[0] + s * (st[1] - st[0]))
        chord = np.array([-np.sin(b), np.cos(b)])  # (y, z): from the axis by the stagger
        normal = np.array([np.cos(b), np.sin(b)])
        pts = []
        for a, d in ((-0.5, 0.5), (0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)):
            y, z = a * c * chord + d * t * normal
            pts.append(f"Point({10 * i + len(pts) + 1}) = {{{r!r}, {float(y)!r}, {float(z)!r}}};")
        lines += pts
        base = 10 * i
        lines += [f"Line({base + k + 1}) = {{{base + k + 1}, {base + (k + 1) % 4 + 1}}};" for k in range(4)]
        lines.append(f"Curve Loop({i + 1}) = {{{base + 1}, {base + 2}, {base + 3}, {base + 4}}};")
        loops.append(str(i + 1))
    lines += [f"ThruSections(1) = {{{', '.join(loops)}}};", 'Physical Volume("BLADE") = {1};']
    return "\n".join(lines) + "\n"


def mesh(out: Path, mesh_size: float, shape: Shape = Shape()) -> Path:
    (out / "blade.geo").write_text(geo_text(mesh_size, shape))
    run(["gmsh", "blade.geo", "-3", "-format", "inp", "-o", "mesh_raw.inp"], out, "gmsh")
    hub, tip_r = shape.radii
    # keep the nodes and the C3D10 elements (gmsh also writes the boundary's line and surface elements)
    keep, mode = [], None
    for line in (out / "mesh_raw.inp").read_text().splitlines():
        if line.startswith("*"):
            mode = "node" if line.upper().startswith("*NODE") else (
                "vol" if line.upper().startswith("*ELEMENT") and "C3D10" in line.upper() else None)
            if mode == "vol":
                line = "*ELEMENT, TYPE=C3D10, ELSET=EALL"
            if mode:
                keep.append(line)
            continue
        if mode:
            keep.append(line)
    (out / "mesh_raw.inp").unlink()
    at = keep.index("*ELEMENT, TYPE=C3D10, ELSET=EALL")
    nodes = np.array([[float(v) for v in s.split(",")] for s in keep[1:at]])
    root = nodes[np.abs(nodes[:, 1] - hub) < 1e-6, 0].astype(int)
    on_tip = np.abs(nodes[:, 1] - tip_r) < 1e-6
    # the tip ground to the casing's cone: each tip node's radius sqrt(x^2 + y^2) = r_tip - z tan(cone), the blade
    # stretched radially in proportion to the span to meet it (the root face stays where it is)
    x, y, z = nodes[:, 1], nodes[:, 2], nodes[:, 3]
    x_tip = np.sqrt((tip_r - z * np.tan(np.radians(shape.cone_deg))) ** 2 - y * y)
    nodes[:, 1] = hub + (x - hub) * (x_tip - hub) / (tip_r - hub)
    keep[1:at] = [f"{int(n[0])}, {float(n[1])!r}, {float(n[2])!r}, {float(n[3])!r}" for n in nodes]
    face = nodes[on_tip]
    # the contact nodes: the tip face's two long edges (pressure and suction side), leading to trailing edge
    b = np.radians(shape.stagger[1])
    d = face[:, 2] * np.cos(b) + face[:, 3] * np.sin(b)  # across the thickness
    along = -face[:, 2] * np.sin(b) + face[:, 3] * np.cos(b)  # along the chord
    edge = np.abs(np.abs(d) - 0.5 * shape.thickness[1]) < 1e-3
    tip = face[edge][np.lexsort((d[edge], along[edge])), 0].astype(int)
    text = "\n".join(keep) + "\n*NSET, NSET=ROOT\n" + "".join(f"{k},\n" for k in root)
    text += "*NSET, NSET=TIP\n" + "".join(f"{k},\n" for k in tip)
    (out / "mesh.inp").write_text(text)
    (out / "tip_nodes.txt").write_text("".join(f"{k}\n" for k in tip))
    return out / "mesh.inp"


MATERIAL = f"""*MATERIAL, NAME=TI64
*ELASTIC
{E!r}, {NU!r}
*DENSITY
{RHO!r}
*SOLID SECTION, ELSET=EALL, MATERIAL=TI64
"""


def deck(omega: float, n_modes: int, clamped: bool = True, nlgeom: bool = False) -> str:
    text = "*INCLUDE, INPUT=mesh.inp\n" + MATERIAL
    if clamped:
        text += "*BOUNDARY\nROOT, 1, 3\n"
    if not clamped:  # the whole mass matrix only
        return text + "*STEP\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n"
    if omega > 0:
        text += (f"*STEP{', NLGEOM' if nlgeom else ''}\n*STATIC\n*DLOAD\n"
                 f"EALL, CENTRIF, {omega * omega!r}, 0., 0., 0., 0., 0., 1.\n*END STEP\n")
        pert = ", PERTURBATION"
    else:
        pert = ""
    return (text + f"*STEP{pert}\n*FREQUENCY\n{n_modes}\n*END STEP\n"
            f"*STEP{pert}\n*FREQUENCY, SOLVER=MATRIXSTORAGE\n*END STEP\n")


def run(cmd: list[str], cwd: Path, what: str) -> None:
    env = dict(os.environ, OMP_NUM_THREADS=os.environ.get("OMP_NUM_THREADS", "2"))
    r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=env)
    if r.returncode != 0 or "*ERROR" in r.stdout:
        tail = "\n".join((r.stdout + r.stderr).splitlines()[-15:])
        raise SystemExit(f"{what} failed in {cwd}:\n{tail}")


def make(out: str | Path, mesh_size: float = 30.0, speeds: tuple[float, ...] | None = None,
         n_modes: int = 10, nlgeom: bool = False, shape: Shape = Shape()) -> dict:
    """Mesh and run every job in ``out``; returns the jobs, their speeds [rad/s] and CalculiX's own
    frequencies [Hz] (also written to ``out/ccx_frequencies.json``)."""
    for tool in ("gmsh", "ccx"):
        if shutil.which(tool) is None:
            raise SystemExit(f"{tool} not found: apt-get install -y -q calculix-ccx gmsh")
    shape.check()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    speeds = speeds or (0.0, OMEGA_TOP / 3.0, 2.0 * OMEGA_TOP / 3.0, OMEGA_TOP)
    mesh(out, mesh_size, shape)
    jobs, freqs = [], {}
    for k, w in enumerate(speeds):
        name = f"speed{k}"
        (out / f"{name}.inp").write_text(deck(w, n_modes, nlgeom=nlgeom))
        run(["ccx", "-i", name], out, f"ccx {name}")
        jobs.append(name)
        freqs[name] = read_frequencies(out / f"{name}.dat")
    (out / "free.inp").write_text(deck(0.0, n_modes, clamped=False))
    run(["ccx", "-i", "free"], out, "ccx free")
    summary = {"units": "N-mm-t-s", "jobs": jobs, "speeds_rad_s": list(speeds), "ccx_frequencies_hz": freqs,
               "mesh_size_mm": mesh_size, "nlgeom": nlgeom, "dofs": int(sum(1 for _ in open(out / "speed0.dof"))),
               "shape_mm_deg": asdict(shape)}
    (out / "ccx_frequencies.json").write_text(json.dumps(summary, indent=1) + "\n")
    return summary


def read_frequencies(dat: Path) -> list[float]:
    """CalculiX's eigenfrequencies [Hz] from the first eigenvalue table of a .dat file."""
    lines = dat.read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if "E I G E N V A L U E   O U T P U T" in s)
    out = []
    for s in lines[k + 1:]:
        p = s.split()
        if len(p) == 5 and p[0].isdigit():
            out.append(float(p[3]))
        elif out and not s.strip():
            break
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="fan_blade_fe", help="folder of the mesh, decks and CalculiX results")
    ap.add_argument("--mesh-size", type=float, default=30.0, help="largest element edge [mm] (9.5: ~60 000 dofs)")
    ap.add_argument("--modes", type=int, default=10, help="CalculiX's own eigenfrequencies a speed")
    ap.add_argument("--nlgeom", action="store_true", help="geometrically nonlinear static prestress")
    ap.add_argument("--radii", nargs=2, type=float, default=(HUB, TIP), metavar=("HUB", "TIP"),
                    help=f"clamped root's and tip's radius [mm] (default {HUB:g} {TIP:g}: the reference's)")
    ap.add_argument("--chord", nargs=2, type=float, default=CHORD, metavar=("ROOT", "TIP"),
                    help=f"chord at the root and the tip [mm] (default {CHORD[0]:g} {CHORD[1]:g})")
    ap.add_argument("--thickness", nargs=2, type=float, default=THICK, metavar=("ROOT", "TIP"),
                    help=f"thickness at the root and the tip [mm] (default {THICK[0]:g} {THICK[1]:g})")
    ap.add_argument("--stagger", nargs=2, type=float, default=STAGGER, metavar=("ROOT", "TIP"),
                    help=f"chord's angle from the spin axis at the root and the tip [deg] (default {STAGGER[0]:g} "
                         f"{STAGGER[1]:g}: the twist)")
    ap.add_argument("--cone-deg", type=float, default=CONE, help=f"the casing's cone the tip is ground to [deg] "
                    f"(default {CONE:g}: the reference's contact.theta_deg; 0: a flat-cut tip)")
    ns = ap.parse_args(argv)
    shape = Shape(tuple(ns.radii), tuple(ns.chord), tuple(ns.thickness), tuple(ns.stagger), ns.cone_deg)
    s = make(ns.out, ns.mesh_size, n_modes=ns.modes, nlgeom=ns.nlgeom, shape=shape)
    print(json.dumps({"dofs": s["dofs"], "first_frequency_hz": {k: v[0] for k, v in s["ccx_frequencies_hz"].items()},
                      "tip_radius_mm": shape.radii[1], "written": str(Path(ns.out) / "ccx_frequencies.json")},
                     indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
