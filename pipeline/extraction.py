"""Relation-graph extraction for one room (paper §4.3): support, spatial and architecture edges.

A pure function of one room's canonical rows: no file IO. The ray casting runs in one Embree scene per room
with two layers: the objects' world meshes (support rays) and, below the floor, vertical prisms over every
object's and wall's floor footprint (the "plan" layer, where the paper's floor-plane visibility is swept).
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
import shapely

from .geometry import meshes, relations
from .geometry.boxes import SIDES, diagonal_2d
from .geometry.polygon import inward_normals, merge_collinear, outline_from_loop, signed_area, wall_loop
from .geometry.raycast import RoomScene, first_accepted

log = logging.getLogger("planit.extract")

PLAN_Z = (-3.0, -2.0)  # z band of the plan layer (below any floor-standing geometry)
MESH, PLAN = 0, 1  # scene layers
BOX_COLUMNS = ["cx", "cy", "cz", "hx", "hy", "hz", "yaw"]
PIECE_INSET = 1e-3  # m, rays start this far in from each piece's ends


@dataclass
class RoomGraph:
    nodes: list[dict] = field(default_factory=list)
    edges: list[dict] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (node id, reason)
    rays: int = 0
    support_cycles: int = 0


@dataclass
class Walls:
    """Merged wall segments of a room in loop order (inner faces, counter-clockwise)."""
    ids: list[str]
    a: np.ndarray  # (w, 2) start points
    b: np.ndarray  # (w, 2) end points
    normal: np.ndarray  # (w, 2) into the room
    thickness: np.ndarray
    height: float

    @property
    def length(self) -> np.ndarray:
        return np.linalg.norm(self.b - self.a, axis=1)

    @property
    def dir(self) -> np.ndarray:
        return (self.b - self.a) / self.length[:, None]


def merge_walls(arch_walls, height: float, tol: float = 1e-3) -> Walls:
    """Order wall segments along their loop, make it counter-clockwise and merge collinear neighbours.

    A merged wall keeps the id of the original wall at its start.
    """
    segs = arch_walls[["x0", "y0", "x1", "y1"]].to_numpy(float).reshape(-1, 2, 2)
    ids = arch_walls["element_id"].astype(str).to_list()
    thick = arch_walls["thickness"].astype(float).fillna(0.1).to_numpy(float)
    closed, why, order = wall_loop(segs, tol)
    if not closed:
        raise ValueError(f"walls do not form a closed loop: {why}")
    oriented = [(segs[o], o) if o >= 0 else (segs[-o - 1][::-1], -o - 1) for o in order]
    if signed_area(outline_from_loop(segs, order)) < 0:
        oriented = [(s[::-1], k) for s, k in oriented[::-1]]
    start = {tuple(np.round(s[0], 6)): k for s, k in oriented}
    outline = merge_collinear(np.array([s[0] for s, _ in oriented]))
    keys = [start.get(tuple(np.round(p, 6))) for p in outline]
    names = [ids[k] if k is not None else f"wall_m{i}" for i, k in enumerate(keys)]
    thickness = np.array([thick[k] if k is not None else float(np.median(thick)) for k in keys])
    nxt = np.roll(outline, -1, axis=0)
    return Walls(names, outline, nxt, inward_normals(np.stack([outline, nxt], 1)), thickness, height)


def wall_footprints(w: Walls) -> np.ndarray:
    """(w, 4, 2) counter-clockwise footprints of the walls, behind their inner faces."""
    back = -w.normal * w.thickness[:, None]
    return np.stack([w.a, w.b, w.b + back, w.a + back], 1)[:, ::-1]


def extract_room(room, walls_df, openings_df, objects_df, mesh_of, symmetry_of, cfg: dict, intersector) -> RoomGraph:
    """Raw relation graph of one room.

    ``mesh_of(model_id) -> (vertices, faces) | None`` in model space; ``symmetry_of(category, model_id) ->
    (symmetry, origin)``; ``cfg`` is the ``extract`` config section; ``intersector`` a trimesh ray class.
    """
    g = RoomGraph()
    walls = merge_walls(walls_df, float(room.height))
    objs, parts = _usable_objects(g, room, objects_df, mesh_of)
    n, n_walls = len(objs), len(walls.ids)
    ids = objs["object_id"].astype(str).to_numpy()
    b = objs[BOX_COLUMNS].to_numpy(float).reshape(-1, 7)
    obj_fp, wall_fp = relations.footprints(b), wall_footprints(walls)
    # one scene: object meshes (layer MESH) + plan prisms of objects and walls (layer PLAN)
    prism_parts = [meshes.prisms(fp[None], *PLAN_Z) for fp in np.concatenate([obj_fp, wall_fp])]
    scene = RoomScene(parts + prism_parts, list(range(n)) + list(range(n + n_walls)),
                      [MESH] * n + [PLAN] * (n + n_walls), intersector)

    parent, area = np.full(n, -1), np.zeros(n)
    volume = np.prod(2 * b[:, 3:6], axis=1)
    if n:
        sc = cfg["support"]
        origins, dirs, obj, cell = relations.support_rays(b, sc["grid"], sc["start_offset"])
        ray, own, lay, dist = scene.hits(origins, dirs)
        g.rays += len(origins)
        first_owner, first_dist = first_accepted(ray, own, dist, (lay == MESH) & (own != obj[ray]), len(origins))
        parent, area = relations.choose_parents(obj, first_owner, first_dist, cell, sc["start_offset"] + sc["max_distance"], volume)
        parent, cycles = relations.break_support_cycles(parent, volume)
        area[parent < 0] = 0.0
        g.support_cycles = len(cycles)
    tier = relations.tiers(parent)
    sym = [symmetry_of(c, m) for c, m in zip(objs["category"].astype(str), objs["model_id"].astype(str))]

    for k, o in enumerate(objs.itertuples(index=False)):
        g.nodes.append({"room_id": room.room_id, "node_id": ids[k], "kind": "object", "category": str(o.category),
                        "model_id": o.model_id, "symmetry": sym[k][0], "symmetry_origin": sym[k][1], "tier": int(tier[k]),
                        "parent_id": ids[parent[k]] if parent[k] >= 0 else None,
                        **{c: float(b[k, i]) for i, c in enumerate(BOX_COLUMNS)}, "length": None})
        if parent[k] >= 0:
            g.edges.append(_edge(room.room_id, ids[parent[k]], ids[k], "support", support_area=float(area[k])))
    _wall_nodes(g, room.room_id, walls)
    radial = np.array([s[0] == "radial" for s in sym], bool)
    g.rays += _spatial_edges(g, room.room_id, scene, b, obj_fp, ids, parent, tier, radial, walls, wall_fp, cfg)
    _architecture_edges(g, room.room_id, walls, openings_df)
    return g


def _usable_objects(g: RoomGraph, room, objects_df, mesh_of):
    """Objects with a finite, non-degenerate box and mesh, centred inside the room; the rest are skipped with a reason."""
    objs = objects_df.reset_index(drop=True)
    outline = shapely.Polygon(np.column_stack([room.floor_x, room.floor_y])).buffer(0.05)
    keep, parts = [], []
    for k, o in enumerate(objs.itertuples(index=False)):
        box = np.array([getattr(o, c) for c in BOX_COLUMNS], float)
        if not np.all(np.isfinite(box)) or min(o.hx, o.hy, o.hz) <= 1e-4:
            g.skipped.append((o.object_id, "zero-size or non-finite box"))
            continue
        if not shapely.contains_xy(outline, o.cx, o.cy):
            g.skipped.append((o.object_id, "centre outside the room outline"))
            continue
        mesh = mesh_of(o.model_id)
        if mesh is None or len(mesh[1]) == 0 or not np.all(np.isfinite(mesh[0])):
            g.skipped.append((o.object_id, f"model {o.model_id}: missing or degenerate mesh"))
            continue
        v = meshes.transform(mesh[0], (o.px, o.py, o.pz), o.yaw, (o.sx, o.sy, o.sz))
        f = mesh[1][:, ::-1] if (o.sx * o.sy * o.sz) < 0 else mesh[1]
        keep.append(k)
        parts.append((v, f))
    return objs.iloc[keep].reset_index(drop=True), parts


def _wall_nodes(g: RoomGraph, room_id: str, walls: Walls) -> None:
    for w in range(len(walls.ids)):
        mid = (walls.a[w] + walls.b[w]) / 2
        g.nodes.append({"room_id": room_id, "node_id": walls.ids[w], "kind": "wall", "category": "wall", "model_id": None,
                        "symmetry": "none", "symmetry_origin": "architecture", "tier": 0, "parent_id": None,
                        "cx": float(mid[0]), "cy": float(mid[1]), "cz": walls.height / 2,
                        "hx": float(walls.length[w] / 2), "hy": float(walls.thickness[w] / 2), "hz": walls.height / 2,
                        "yaw": _yaw_facing(walls.normal[w]), "length": float(walls.length[w])})


def _yaw_facing(normal) -> float:
    return math.atan2(normal[1], normal[0]) - math.pi / 2


def _spatial_edges(g, room_id, scene, b, obj_fp, ids, parent, tier, radial, walls, wall_fp, cfg) -> int:
    """Sweep every anchor side (4 per object, the inner face per wall) and add the visible spatial edges."""
    n, n_walls = len(b), len(walls.ids)
    sp = cfg["spatial"]
    group = np.concatenate([np.where(tier <= 1, 0, parent + 1), np.zeros(n_walls, int)])  # who sees whom
    all_fp = np.concatenate([obj_fp, wall_fp])
    diag = diagonal_2d(b[:, 3], b[:, 4])
    sides = []  # (anchor owner, side index, centre, tangent, normal, half_len, inset)
    for k in range(n):
        for s, (_, c, t, nrm, half, depth) in enumerate(relations.box_sides(b[k])):
            sides.append((k, s, c, t, nrm, half, min(sp["inset_fraction"] * depth, sp["inset_max"])))
    for w in range(n_walls):
        c = (walls.a[w] + walls.b[w]) / 2
        sides.append((n + w, 0, c, walls.dir[w], walls.normal[w], walls.length[w] / 2,
                      min(sp["inset_fraction"] * walls.thickness[w], sp["inset_max"])))
    origins, ray_piece, piece_side, piece_len, offset = [], [], [], [], 0
    for si, (owner, _, c, t, nrm, half, inset) in enumerate(sides):
        others = np.flatnonzero((group == group[owner]) & (np.arange(n + n_walls) != owner))
        starts, ends, _ = relations.sweep_pieces(c, t, nrm, half, all_fp[others], inset)
        pos, piece = relations.piece_rays(starts, ends, PIECE_INSET)
        xy = c + pos[:, None] * t - nrm * inset
        origins.append(np.column_stack([xy, np.full(len(pos), sum(PLAN_Z) / 2)]))
        ray_piece.append(piece + offset)
        offset += len(starts)
        piece_side.append(np.full(len(starts), si))
        piece_len.append(ends - starts)
    piece_side = np.concatenate(piece_side)
    piece_len = np.concatenate(piece_len)
    ray_piece = np.concatenate(ray_piece)
    origins = np.concatenate(origins)
    side_owner = np.array([s[0] for s in sides])
    side_normal = np.array([s[4] for s in sides])
    side_inset = np.array([s[6] for s in sides])
    ray_side = piece_side[ray_piece]
    dirs = np.column_stack([side_normal[ray_side], np.zeros(len(origins))])
    ray, own, lay, dist = scene.hits(origins, dirs)
    anchor_of_ray = side_owner[ray_side]
    accept = (lay == PLAN) & (own != anchor_of_ray[ray]) & (group[own] == group[anchor_of_ray[ray]])
    hit_owner, hit_dist = first_accepted(ray, own, dist, accept, len(origins))
    # per piece: the nearer of its two rays
    pr = hit_dist.reshape(-1, 2)
    pick = np.argmin(pr, axis=1)
    p_owner = hit_owner.reshape(-1, 2)[np.arange(len(pr)), pick]
    p_dist = pr[np.arange(len(pr)), pick]
    ok = (p_owner >= 0) & (p_owner < n)  # pieces that reach an object (walls only occlude)
    if not ok.any():
        return len(origins)
    ps, po = piece_side[ok], p_owner[ok]
    key = ps * (n + n_walls) + po
    uniq, inv = np.unique(key, return_inverse=True)
    vis = np.bincount(inv, weights=piece_len[ok])
    gap = np.full(len(uniq), np.inf)
    np.minimum.at(gap, inv, p_dist[ok])
    u_side, u_target = uniq // (n + n_walls), uniq % (n + n_walls)
    gap -= side_inset[u_side]
    tangents = np.array([s[3] for s in sides])[u_side]
    proj = np.einsum("mkj,mj->mk", obj_fp[u_target], tangents)
    target_share = np.minimum(vis / np.maximum(np.ptp(proj, axis=1), 1e-9), 1.0)
    anchor_share = vis / (2 * np.array([s[5] for s in sides])[u_side])
    score = np.maximum(target_share, anchor_share)
    u_anchor = side_owner[u_side]
    u_sidx = np.array([s[1] for s in sides])[u_side]
    scores = {}  # (anchor, target) -> per-side scores
    for a, t, s, sc in zip(u_anchor, u_target, u_sidx, score):
        scores.setdefault((int(a), int(t)), np.zeros(4))[s] = sc
    keep = score >= sp["min_visibility"]
    best: dict[tuple[int, int], int] = {}
    for i in np.flatnonzero(keep):
        pair = (int(u_anchor[i]), int(u_target[i]))
        j = best.get(pair)
        if j is None or (score[i], -gap[i]) > (score[j], -gap[j]):
            best[pair] = i
    contained = _contained_pairs(obj_fp, group[:n], sp["contain_fraction"])
    for pair in contained:
        if pair not in best:
            best[pair] = -1
    for (a, t), i in sorted(best.items()):
        is_wall = a >= n
        max_diag = diag[t] if is_wall else max(diag[a], diag[t])
        if i < 0:  # target mostly inside the anchor's footprint
            direction, gap_i, tv, av, label = "front", 0.0, 1.0, 1.0, "adjacent"
        else:
            direction = "front" if is_wall or radial[a] else SIDES[u_sidx[i]]
            gap_i, tv, av = float(gap[i]), float(target_share[i]), float(anchor_share[i])
            label = str(relations.distance_labels(gap_i, max_diag, cfg["distance"]))
            if (a, t) in contained:
                label = "adjacent"
        sc = scores.get((a, t), np.zeros(4))
        src = walls.ids[a - n] if is_wall else ids[a]
        g.edges.append(_edge(room_id, src, ids[t], "spatial", direction, label, gap=gap_i, target_visibility=tv,
                             anchor_visibility=av, score_front=float(sc[0]), score_back=float(sc[1]),
                             score_left=float(sc[2]), score_right=float(sc[3])))
    return len(origins)


def _contained_pairs(fp: np.ndarray, group: np.ndarray, fraction: float) -> set[tuple[int, int]]:
    """(anchor, target) pairs of one group where at least ``fraction`` of the target's footprint lies in the anchor's."""
    n = len(fp)
    if n < 2:
        return set()
    polys = shapely.polygons(fp)
    i, j = np.nonzero((group[:, None] == group[None, :]) & ~np.eye(n, dtype=bool))
    inter = shapely.area(shapely.intersection(polys[i], polys[j]))
    frac = inter / np.maximum(shapely.area(polys[j]), 1e-12)
    sel = frac >= fraction
    return set(zip(i[sel].tolist(), j[sel].tolist()))


def _architecture_edges(g: RoomGraph, room_id: str, walls: Walls, openings_df) -> None:
    """Wall loop (adjacent, with the corner angle), walls facing each other, doors and windows on their wall."""
    w = len(walls.ids)
    d = walls.dir
    for i in range(w):
        j = (i + 1) % w
        turn = math.atan2(d[i][0] * d[j][1] - d[i][1] * d[j][0], float(d[i] @ d[j]))
        angle = math.pi - turn  # interior angle at the shared corner
        g.edges.append(_edge(room_id, walls.ids[i], walls.ids[j], "wall_adjacent", "right", "adjacent", angle=angle, gap=0.0))
        g.edges.append(_edge(room_id, walls.ids[j], walls.ids[i], "wall_adjacent", "left", "adjacent", angle=angle, gap=0.0))
    for i in range(w):
        for j in range(w):
            if i == j or abs(i - j) in (1, w - 1) or walls.normal[i] @ walls.normal[j] > -0.99:
                continue
            dist = float((walls.a[j] - walls.a[i]) @ walls.normal[i])
            t = np.sort([(walls.a[j] - walls.a[i]) @ d[i], (walls.b[j] - walls.a[i]) @ d[i]])
            overlap = min(t[1], walls.length[i]) - max(t[0], 0.0)
            if dist > 0 and overlap >= 0.3 * min(walls.length[i], walls.length[j]):
                g.edges.append(_edge(room_id, walls.ids[i], walls.ids[j], "wall_opposite", "front", "distant", gap=dist))
    for o in openings_df.itertuples(index=False):
        mid = np.array([(o.x0 + o.x1) / 2, (o.y0 + o.y1) / 2])
        rel = mid - walls.a
        t = np.einsum("ij,ij->i", rel, d)
        off = np.abs(np.einsum("ij,ij->i", rel, walls.normal))
        on = (t >= -1e-3) & (t <= walls.length + 1e-3)
        if not on.any():
            g.skipped.append((o.element_id, "opening is on no wall"))
            continue
        wi = int(np.flatnonzero(on)[np.argmin(off[on])])
        if off[wi] > 0.05:
            g.skipped.append((o.element_id, f"opening lies {off[wi]:.2f} m off its nearest wall"))
            continue
        width = float(math.hypot(o.x1 - o.x0, o.y1 - o.y0))
        g.nodes.append({"room_id": room_id, "node_id": o.element_id, "kind": str(o.kind), "category": str(o.kind),
                        "model_id": None, "symmetry": "none", "symmetry_origin": "architecture", "tier": 0, "parent_id": None,
                        "cx": float(mid[0]), "cy": float(mid[1]), "cz": float((o.z0 + o.z1) / 2), "hx": width / 2,
                        "hy": float(walls.thickness[wi] / 2), "hz": float((o.z1 - o.z0) / 2),
                        "yaw": _yaw_facing(walls.normal[wi]), "length": width})
        g.edges.append(_edge(room_id, walls.ids[wi], o.element_id, "opening", "front", "adjacent", gap=0.0))


def _edge(room_id, src, dst, edge_type, direction=None, distance=None, **extra) -> dict:
    return {"room_id": room_id, "source": src, "target": dst, "edge_type": edge_type, "direction": direction,
            "distance": distance, **extra}
