"""The 3D contact of an imported (finite-element) blade: its tip nodes along the chord facing the conical casing.

The tip nodes of a solid mesh spread over the chord and the thickness. Along the chord they are gathered into
**stations** (nodes within a thousandth of the chord of one another: the two faces of the tip; or, beyond
``stations`` of them, equal bins of the chord), each the mean of its nodes: its rest position and its map from
the dofs (the disk's rigid motion, the blade's reduced modes: ``structure.tips.tip_node_maps``). Consecutive
stations bound **segments**; each segment carries the paper's chord law (eq. 5-8) over its own length, with the
gap linear between its two stations, the pressure k_r / L where it penetrates (L the tip's chord: a tip pressed
evenly carries k_r times its penetration, as the built-in blades), and friction at its two ends. So the 3D law
of docs/THEORY.md §4 holds station by station: the leading edge, the trailing edge and every station between.

The casing: a cone of half-angle theta whose line passes at g0 from the tip's tightest station (g0 is the tip's
clearance, wherever along the chord it is smallest); a node at radius r and axial position z from the tip's
mean axial position has the rest gap g0 + (R - z tan theta - r) cos theta - min over the stations of the same,
a station the mean of its nodes' (a tip not cut to the casing's line keeps its own gaps: a flat-cut tip facing a
5 deg cone touches at its trailing edge only). The normal,
the sliding direction and the casing's point maps (translation, tilt about its centre of gravity, ring) are the
built-in formulation's at each station.

The kernel sees each segment as a 'blade' of two points with compact rows (the shaft's, its blade's and the
casing's dofs), reports the outputs per blade (the sum of its segments' forces; its leading and trailing
stations' gaps; the smallest gap; the chord fraction in contact) and the liner by station.
"""

from __future__ import annotations

import numpy as np

from ..structure.model import Model
from ..structure.tips import tip_node_maps
from .geometry import ContactGeometry, TipLayout

SAME_STATION = 1e-3  # nodes closer than this fraction of the chord along it are one station
DEFAULT_STATIONS = 12  # at most this many stations by default (more: finer, the segments' count)


def tip_thickness(positions: np.ndarray) -> float:
    """The tip's thickness [m]: the spread of its nodes across the chord (in the tip plane y, z; 0 for a tip
    given as one line of nodes)."""
    yz = positions[:, 1:] - positions[:, 1:].mean(axis=0)
    _, _, vt = np.linalg.svd(yz, full_matrices=False)
    return float(np.ptp(yz @ vt[1])) if vt.shape[0] > 1 else 0.0


def stations(positions: np.ndarray, max_stations: int = DEFAULT_STATIONS) -> tuple[np.ndarray, np.ndarray, float]:
    """Group tip nodes (n_t, 3: blade frame, x radial, y tangential, z axial) into chord stations.

    Returns (members (n_t,) station index of every node, ordered from the leading edge: the upstream end, chord
    coordinate of every station (K,), chord length)."""
    yz = positions[:, 1:] - positions[:, 1:].mean(axis=0)
    _, _, vt = np.linalg.svd(yz, full_matrices=False)
    d = vt[0] if vt[0][1] > 0 else -vt[0]  # the chord's direction, pointing downstream (+z): the trailing edge
    c = yz @ d
    order = np.argsort(c)
    chord = float(c[order[-1]] - c[order[0]])
    if not chord > 0:
        raise ValueError("the tip nodes do not span a chord")
    groups, current = [], [order[0]]
    for a, b in zip(order[:-1], order[1:]):
        if c[b] - c[a] > SAME_STATION * chord:
            groups.append(current)
            current = []
        current.append(b)
    groups.append(current)
    if len(groups) > max_stations:  # equal bins of the chord
        edges = np.linspace(c[order[0]], c[order[-1]], max_stations + 1)
        idx = np.clip(np.searchsorted(edges, c, side="right") - 1, 0, max_stations - 1)
        groups = [list(np.flatnonzero(idx == k)) for k in range(max_stations) if np.any(idx == k)]
    members = np.empty(len(c), dtype=int)
    for k, g in enumerate(groups):
        members[g] = k
    station_c = np.array([c[g].mean() for g in groups])
    return members, station_c, chord


def geometry_fe(model: Model, theta: float, max_stations: int = DEFAULT_STATIONS) -> ContactGeometry:
    """The 3D contact geometry of ``model``'s imported blades (``model.fe_blade``)."""
    p, blade = model.params, model.fe_blade
    if blade is None:
        raise ValueError("geometry_fe: the model has no imported blade")
    N, n = p.blades.count, model.n_dofs
    members, station_c, chord = stations(blade.tip_positions, max_stations)
    K = station_c.size
    if K < 2:
        raise ValueError("an imported tip needs two chord stations or more (its nodes are all at one chord position)")
    node_points, node_Jb = tip_node_maps(p, blade)  # (N, n_t, 3), (N, n_t, 3, n)
    sh, bl, cs = model.slices["shaft"], model.slices["blades"], model.slices["casing"]
    m = blade.m
    R_tip, c_th, s_th, t_th = p.blades.tip_radius, np.cos(theta), np.sin(theta), np.tan(theta)
    z_tip = float(node_points[0, :, 2].mean())  # the tip plane: its mean axial position (the casing's reference)
    seg = np.diff(station_c)
    L = float(station_c[-1] - station_c[0])
    S = N * (K - 1)
    pts, nor, tan = np.zeros((S, 2, 3)), np.zeros((S, 2, 3)), np.zeros((S, 2, 3))
    Jb, Jc = np.zeros((S, 2, 3, n)), np.zeros((S, 2, 3, n))
    g_off = np.zeros((S, 2))
    for j in range(N):
        for k in range(K - 1):
            s = j * (K - 1) + k
            for end, st in enumerate((k, k + 1)):
                nodes = members == st
                P = node_points[j, nodes].mean(axis=0)
                Pz = P.copy()
                Pz[2] -= z_tip  # axial position from the tip plane (the casing's coordinates)
                a = np.arctan2(P[1], P[0])
                e_rho = np.array([np.cos(a), np.sin(a), 0.0])
                pts[s, end] = Pz
                nor[s, end] = c_th * e_rho + s_th * np.array([0.0, 0.0, 1.0])
                tan[s, end] = [-np.sin(a), np.cos(a), 0.0]
                Jb[s, end][:, : node_Jb.shape[-1]] = node_Jb[j, nodes].mean(axis=0)  # rotor dofs (no casing)
                Jc[s, end][:, cs] = model.casing_point_map(Pz)
                # the station's rest gap: the mean of its nodes' own (a station spanning a stretch of the chord lies
                # inside the tip's curved line, its nodes on it)
                X = node_points[j, nodes]
                g_off[s, end] = np.mean((R_tip - (X[:, 2] - z_tip) * t_th - np.hypot(X[:, 0], X[:, 1])) * c_th)
    # g0 is the clearance of the tip's tightest station: the cone passes at g0 from it (a flat-cut tip, whose ends
    # reach further out than its middle, keeps the larger gaps of its middle)
    g_off -= g_off.min()
    rel = Jb - Jc
    G = -np.einsum("spi,spin->spn", nor, rel).reshape(S * 2, n)
    Sr = np.einsum("spi,spin->spn", tan, rel).reshape(S * 2, n)
    seg_len = np.tile(seg, N)
    A = 0.5 * (G[0::2] + G[1::2])
    B = (G[1::2] - G[0::2]) / seg_len[:, None]
    # compact rows: each segment touches the shaft's dofs, its blade's and the casing's only
    cols = np.array([np.concatenate([np.arange(sh.start, sh.stop), np.arange(bl.start + j * m, bl.start + (j + 1) * m),
                                     np.arange(cs.start, cs.stop)]) for j in range(N) for _ in range(K - 1)],
                    dtype=np.intc)
    outside = np.ones((S, n), dtype=bool)
    outside[np.arange(S)[:, None], cols] = False
    for X in (A, B):
        assert not np.any(X[outside]), "a segment's row reaches a dof outside its blade"
    rows = np.repeat(np.arange(S), 2)
    compact = {k: np.take_along_axis(X, cols[(rows if X.shape[0] == 2 * S else np.arange(S))], axis=1)
               for k, X in (("G", G), ("S", Sr), ("A", A), ("B", B))}
    # the liner: rows by station; each station's share of a tip is its tributary chord (half of each segment it
    # ends); the trailing point of a segment that is not the last is the next segment's leading point: a twin
    share = np.zeros((S, 2))
    for j in range(N):
        for k in range(K - 1):
            s = j * (K - 1) + k
            share[s, 0] = (0.5 * seg[k] + (0.5 * seg[k - 1] if k > 0 else 0.0)) / L
            share[s, 1] = 0.5 * seg[k] / L if k == K - 2 else 0.0
    point_row = np.array([[k, k + 1] for _ in range(N) for k in range(K - 1)], dtype=np.intc).ravel()
    # the liner's band (the tip's axial extent) and the tip's footprint (chord x thickness; a tip given as one
    # line of nodes: the [blades] thickness)
    band = float(np.ptp(pts[: K - 1, :, 2]))
    thick = tip_thickness(blade.tip_positions)
    area = L * (thick if thick > 1e-6 * L else p.blades.thickness)
    tips = TipLayout(n_blades=N, n_dofs=n, seg_len=seg_len, seg_k=seg_len / L, g_off=g_off.ravel(), cols=cols,
                     blade_of=np.repeat(np.arange(N), K - 1).astype(np.intc), n_rows=K, point_row=point_row,
                     point_share=share.ravel(), band=band, tip_area=area)
    T, _ = model.disk_maps
    return ContactGeometry(points=pts, normals=nor, tangents=tan, Jb=Jb, Jc=Jc, chord=L,
                           disk=np.ascontiguousarray(T[:2]), tips=tips, **compact)
