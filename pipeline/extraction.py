"""Relation-graph extraction for one room (paper §4.3): support, spatial and architecture edges.

A pure function of one room's arrays (:class:`RoomInput`): no file IO. The ray casting runs in one Embree
scene per room with two layers: the objects' world meshes (support rays) and, below the floor, vertical
prisms over every object's and wall's floor footprint (the "plan" layer, where the paper's floor-plane
visibility sweep runs). Support and spatial rays go to Embree in one batch.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import shapely

from .geometry import meshes, relations
from .geometry.boxes import SIDE_NORMALS, SIDES, diagonal_2d, rotation
from .geometry.polygon import nearest_segment
from .geometry.raycast import RoomScene
from .room import BOX_COLUMNS, RoomInput, Walls, merge_walls, wall_footprints

log = logging.getLogger("planit.extract")

PLAN_Z = (-3.0, -2.0)  # z band of the plan layer (below any floor-standing geometry)
MESH, PLAN = 0, 1  # scene layers
PIECE_INSET = 1e-3  # m, rays start this far in from each piece's ends
TOUCH = 1e-6  # m, a footprint this close to an anchor side (or reaching behind it) touches it


@dataclass
class RoomGraph:
    nodes: list[dict] = field(default_factory=list)
    edges: list[dict] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)  # (node id, reason)
    rays: int = 0
    support_cycles: int = 0
    hanging: int = 0  # objects with nothing below and a bottom high above the floor


def extract_room(room: RoomInput, mesh_of, symmetry_of, cfg: dict, intersector, box_models=None,
                 anchors: set[str] | None = None) -> RoomGraph:
    """Raw relation graph of one room.

    ``mesh_of(model_id) -> (vertices, faces) | None`` in model space; ``symmetry_of(category, model_id) ->
    (symmetry, origin)``; ``cfg`` is the ``extract`` config section plus the shared ``floor_contact``;
    ``intersector`` a trimesh ray class; ``box_models`` the ids of models that are only a box (the box-contact
    rules apply to those alone; None: every model); ``anchors``: the ids of the objects and walls whose sides are
    swept (None: all), so that only spatial edges from them are found, each exactly as the whole sweep finds it
    (every side is swept on its own; what is not swept only occludes), and the architecture's edges (walls to walls
    and openings, which no object's relation reads) are left out.
    """
    g = RoomGraph()
    walls = _merged_walls(room)
    keep, parts = _usable_objects(g, room, mesh_of)
    ids = [room.object_ids[k] for k in keep]
    cats = [room.categories[k] for k in keep]
    models = [room.model_ids[k] for k in keep]
    b = room.boxes[keep].reshape(-1, 7)
    n, n_walls = len(ids), len(walls.ids)
    scene, all_fp = _room_scene(parts, b, walls, intersector)

    # support first (the sweep's groups depend on tiers), then the visibility sweep of every anchor side
    boxy = np.array([box_models is None or m in box_models for m in models], bool)
    parent, area, rays, cycles = support_parents(scene, b, cfg["support"], cfg["floor_contact"], boxy)
    g.rays += rays
    g.support_cycles = cycles
    tier = relations.tiers(parent)
    hanging = relations.hanging(b, parent, cfg["floor_contact"], cfg["support"]["hanging_min_height"])
    tier[hanging] = -1
    g.hanging = int(hanging.sum())
    sym = [symmetry_of(c, m) for c, m in zip(cats, models)]
    drop = hanging if cfg["support"]["hanging"] == "drop" else np.zeros(n, bool)
    _object_nodes(g, room.room_id, (ids, cats, models, sym), b, (parent, area, tier), drop)
    _wall_nodes(g, room.room_id, walls)
    radial = np.array([s[0] == "radial" for s in sym], bool)
    # who sees whom: the floor plan (group 0), the objects on one parent (parent + 1); hanging objects none
    group = np.where(tier == 1, 0, parent + 1)
    group[hanging] = n + 1 + np.flatnonzero(hanging)
    group = np.concatenate([group, np.zeros(n_walls, int)])
    g.rays += _spatial_edges(g, room.room_id, PlanLayer(scene, b, all_fp, group, radial, walls, ids + walls.ids), cfg,
                             anchors)
    if anchors is None:
        _architecture_edges(g, room.room_id, walls, room.openings, cfg["architecture"])
    return g


_WALLS: dict[tuple, Walls] = {}  # a search extracts one room's walls once per candidate: merged once per room


def _merged_walls(room: RoomInput) -> Walls:
    """The room's merged walls (:func:`~pipeline.room.merge_walls`), kept for the last few rooms (keyed on content;
    the same object is returned, and no caller changes it)."""
    key = (np.asarray(room.wall_segments, float).tobytes(), tuple(room.wall_ids),
           np.asarray(room.wall_thickness, float).tobytes(), float(room.height))
    if key not in _WALLS:
        if len(_WALLS) >= 8:
            _WALLS.pop(next(iter(_WALLS)))
        _WALLS[key] = merge_walls(room.wall_segments, room.wall_ids, room.wall_thickness, room.height)
    return _WALLS[key]


def _room_scene(parts: list, b: np.ndarray, walls: Walls, intersector) -> tuple[RoomScene, np.ndarray]:
    """The room's ray scene (the objects' meshes, and the plan layer's prisms over every object's and wall's
    footprint, one owner per prism) and those footprints ``(n + w, 4, 2)``."""
    n = len(b)
    all_fp = np.concatenate([relations.footprints(b), wall_footprints(walls)])
    plan = meshes.prisms(all_fp, *PLAN_Z)
    scene = RoomScene(parts + [plan], list(range(n)) + [0], [MESH] * n + [PLAN], intersector)
    scene.owner[-len(plan[1]):] = np.repeat(np.arange(n + len(walls.ids)), meshes.faces_per_prism(4))
    return scene, all_fp


def _object_nodes(g: RoomGraph, room_id: str, named: tuple, b: np.ndarray, support: tuple, drop: np.ndarray) -> None:
    """Object nodes and their support edges (``named``: ids, categories, models, symmetries; ``support``: parent
    index, support area, tier per object); objects in ``drop`` are skipped with the reason."""
    ids, cats, models, sym = named
    parent, area, tier = support
    for k in np.flatnonzero(drop):
        g.skipped.append((ids[k], "hanging: nothing below it and its bottom high above the floor"))
    for k in np.flatnonzero(~drop):
        g.nodes.append({"room_id": room_id, "node_id": ids[k], "kind": "object", "category": cats[k],
                        "model_id": models[k], "symmetry": sym[k][0], "symmetry_origin": sym[k][1], "tier": int(tier[k]),
                        "parent_id": ids[parent[k]] if parent[k] >= 0 else None,
                        **dict(zip(BOX_COLUMNS, map(float, b[k]))), "length": None})
        if parent[k] >= 0:
            g.edges.append(_edge(room_id, ids[parent[k]], ids[k], "support", support_area=float(area[k])))


def support_parents(scene: RoomScene, b: np.ndarray, sc: dict, floor_contact: float,
                    boxy: np.ndarray) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Support parent of every object (-1: the floor) and its supporting area.

    ``b`` (n, 7) boxes, ``sc`` the ``extract.support`` config, ``floor_contact`` (m) how high a bottom may be and
    still stand on the floor, ``boxy (n,)`` which objects' models are only boxes. Objects raised above
    ``floor_contact`` cast a grid of rays down; each ray takes the nearest upward-facing surface of another
    object within reach (a downward-facing one only when the ray did not start inside that object); the parent is
    the object under the largest area. The box-contact rules join box-only
    objects alone. Returns ``parent (n,)``, ``area (n,)`` m^2, the number of rays and of support cycles broken.
    """
    n = len(b)
    raised = np.flatnonzero(b[:, 2] - b[:, 5] > floor_contact)  # only raised objects cast
    s_orig, s_dir, s_obj, cell = relations.support_rays(b[raised], sc["grid"], sc["start_offset"])
    s_obj = raised[s_obj]
    cell = np.zeros(n) if not len(raised) else np.bincount(raised, weights=cell, minlength=n)
    reach = sc["start_offset"] + sc["max_distance"]
    # only upward-facing surfaces hold things; a downward-facing face counts only where the ray did not start
    # inside that object (then it entered through a top face level with the caster's bottom, which the step past
    # the caster's own coincident bottom face skips)
    first_owner, first_dist = scene.first_accepted(
        s_orig, s_dir, lambda r, own, lay, face: (lay == MESH) & (own != s_obj[r])
        & (scene.up[face] | ~relations.inside_boxes(s_orig[r], b[own])), max_dist=reach)
    footprint = 4 * b[:, 3] * b[:, 4]  # "largest" = widest: a thin counter slab is larger than the kettle on it
    if sc["inside_box_contact"]:
        _box_contacts(b, footprint, (s_orig, s_obj, first_owner, first_dist), reach, sc, boxy)
    parent, area = relations.choose_parents(s_obj, first_owner, first_dist, cell, reach, footprint)
    if sc["inside_box_contact"] and len(raised):  # raised box, nothing below: held from around (hung in a slab)?
        loose = raised[(parent[raised] < 0) & boxy[raised]]
        held = relations.holding_box(b, loose, boxy)
        parent[loose] = np.where(held >= 0, held, parent[loose])
        area[loose] = np.where(held >= 0, footprint[loose], area[loose])
    parent, cycles = relations.break_support_cycles(parent, footprint)
    area[parent < 0] = 0.0
    return parent, area, len(s_orig), len(cycles)


def _box_contacts(b: np.ndarray, footprint: np.ndarray, casts: tuple, reach: float, sc: dict, boxy: np.ndarray) -> None:
    """Box-only sources: a grid point whose ray finds nothing within reach but lies in another object's box rests
    on the box whose top is level with the object's bottom (within ``sc['box_top_tolerance']``), else on the widest
    box around it (boxes reach above their support surface: cushions on beds, things in fridges, a desk's hutch; a
    chair tucked under the desk rises above the desk top the bowl stands on). The point just below the object's
    bottom is tested too (a top level with the bottom hides behind the bottom face); ``footprint (n,)`` m^2.
    ``casts``: the support rays' origins and casters and their first hits' owners and distances, the last two
    updated in place."""
    s_orig, s_obj, first_owner, first_dist = casts
    start_offset, top_tolerance = sc["start_offset"], sc["box_top_tolerance"]
    volume = np.prod(2 * b[:, 3:6], axis=1)
    miss = np.flatnonzero((first_dist > reach) & boxy[s_obj])
    if not len(miss):
        return
    origin, own = s_orig[miss], s_obj[miss]
    below = origin - [0.0, 0.0, start_offset + 1e-3]
    inside = relations.box_containment(origin, b, own, boxy) | relations.box_containment(below, b, own, boxy)
    bottom = origin[:, 2] - start_offset
    top = b[:, 2] + b[:, 5]
    off = np.abs(top[None, :] - bottom[:, None])
    # a box whose top is level with the bottom is the surface itself; otherwise the point is inside furniture
    # (a desk with its hutch, a chair tucked under it): the widest box around it holds it
    score = np.where(off <= top_tolerance, off, 10.0 - footprint[None, :] / max(footprint.max(), 1e-12))
    score = np.where(inside, score + 1e-6 * volume[None, :] / max(volume.max(), 1e-12), np.inf)
    best = np.argmin(score, axis=1)
    found = np.isfinite(score[np.arange(len(miss)), best])
    first_owner[miss[found]] = best[found]
    first_dist[miss[found]] = 0.0


def _usable_objects(g: RoomGraph, room: RoomInput, mesh_of) -> tuple[list[int], list]:
    """Indices and world meshes of objects with a finite, non-degenerate box and mesh, centred inside the room;
    the rest are skipped with a reason."""
    outline = shapely.Polygon(room.outline).buffer(0.05)
    inside = shapely.contains_xy(outline, room.boxes[:, 0], room.boxes[:, 1]) if len(room.boxes) else np.zeros(0, bool)
    finite = np.isfinite(room.boxes).all(axis=1) & np.isfinite(room.poses).all(axis=1)
    sized = room.boxes[:, 3:6].min(axis=1) > 1e-4 if len(room.boxes) else np.zeros(0, bool)
    keep, local = [], []
    for k, oid in enumerate(room.object_ids):
        if not (finite[k] and sized[k]):
            g.skipped.append((oid, "zero-size or non-finite box"))
            continue
        if not inside[k]:
            g.skipped.append((oid, "centre outside the room outline"))
            continue
        mesh = mesh_of(room.model_ids[k])
        if mesh is None or len(mesh[1]) == 0 or not np.isfinite(mesh[0]).all():
            g.skipped.append((oid, f"model {room.model_ids[k]}: missing or degenerate mesh"))
            continue
        keep.append(k)
        local.append(mesh)
    if not keep:
        return keep, []
    # all model -> world transforms in one pass
    counts = np.array([len(v) for v, _ in local])
    pose = np.repeat(room.poses[keep], counts, axis=0)
    v = np.concatenate([v for v, _ in local]) * pose[:, 4:7]
    c, s = np.cos(pose[:, 3]), np.sin(pose[:, 3])
    world = np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1], v[:, 2]]) + pose[:, 0:3]
    parts = []
    for (_, f), vw, p in zip(local, np.split(world, np.cumsum(counts)[:-1]), room.poses[keep]):
        parts.append((vw, f[:, ::-1] if np.prod(p[4:7]) < 0 else f))  # mirrored: keep faces outward
    return keep, parts


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


def anchor_sides(b: np.ndarray, walls: Walls, sp: dict) -> dict[str, np.ndarray]:
    """Every anchor side as arrays: 4 per object (front, back, left, right), the inner face per wall."""
    n = len(b)
    r = rotation(b[:, 6])  # (n, 2, 2)
    normal = np.einsum("nij,sj->nsi", r, SIDE_NORMALS).reshape(-1, 2)
    tangent = np.stack([normal[:, 1], -normal[:, 0]], 1)  # to the right when looking out of the side
    along_y = np.tile(SIDE_NORMALS[:, 1] != 0, n)
    hx, hy = np.repeat(b[:, 3], 4), np.repeat(b[:, 4], 4)
    half_depth = np.where(along_y, hy, hx)
    half_len = np.where(along_y, hx, hy)
    centre = np.repeat(b[:, :2], 4, axis=0) + normal * half_depth[:, None]
    inset = np.minimum(sp["inset_fraction"] * 2 * half_depth, sp["inset_max"])
    w = len(walls.ids)
    return {
        "owner": np.concatenate([np.repeat(np.arange(n), 4), n + np.arange(w)]),
        "side": np.concatenate([np.tile(np.arange(4), n), np.zeros(w, int)]),
        "centre": np.concatenate([centre, (walls.a + walls.b) / 2]),
        "tangent": np.concatenate([tangent, walls.dir]),
        "normal": np.concatenate([normal, walls.normal]),
        "half": np.concatenate([half_len, walls.length / 2]),
        "inset": np.concatenate([inset, np.minimum(sp["inset_fraction"] * walls.thickness, sp["inset_max"])]),
    }


def sweep(sides: dict, all_fp: np.ndarray, group: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Split every side at the projected corners of the footprints it may see (same group, not itself,
    not wholly behind its ray origins). Returns ``piece_side (p,)`` (sorted), ``starts (p,)``, ``ends (p,)`` and
    ``near (S, O)``: footprints that may touch the side (a corner on or behind its line)."""
    owners = sides["owner"]
    o = len(all_fp)
    rel = all_fp[None, :, :, :] - sides["centre"][:, None, None, :]  # (S, O, 4, 2)
    t = np.einsum("sokj,sj->sok", rel, sides["tangent"])
    d = np.einsum("sokj,sj->sok", rel, sides["normal"])
    lo, hi = t.min(axis=2), t.max(axis=2)
    half = sides["half"][:, None]
    live = ((group[None, :] == group[owners][:, None]) & (np.arange(o)[None, :] != owners[:, None])
            & (d.max(axis=2) > -sides["inset"][:, None]) & (hi > -half) & (lo < half))
    # every projected corner is a cut: within a piece each footprint's near boundary is one straight edge
    corner_cuts = np.where(live[:, :, None], np.clip(t, -half[:, :, None], half[:, :, None]), np.nan)
    cuts = np.concatenate([-half, half, corner_cuts.reshape(len(owners), 4 * o)], axis=1)
    cuts = np.sort(cuts, axis=1)  # NaN sort last
    starts, ends = cuts[:, :-1], cuts[:, 1:]
    valid = np.isfinite(ends) & (ends - starts > 1e-6)
    side_idx = np.broadcast_to(np.arange(len(owners))[:, None], starts.shape)
    return side_idx[valid], starts[valid], ends[valid], live & (d.min(axis=2) <= TOUCH)


def touching(sides: dict, all_fp: np.ndarray, near: np.ndarray, piece_side: np.ndarray, starts: np.ndarray,
             ends: np.ndarray) -> np.ndarray:
    """Per piece, the footprint that touches or overlaps it (within the piece, less PIECE_INSET at each end as for the
    rays, it reaches from at most TOUCH in front of the side's line to the line or across it), -1 where none.

    Nothing can stand between a side and a footprint that touches it, so no ray decides these pieces: a ray would
    leave the anchor through a face coplanar with the target's and Embree may report either (flush neighbours).
    Where several touch one piece, the deepest wins. ``near (S, O)`` from :func:`sweep`."""
    owner = np.full(len(piece_side), -1, dtype=np.int64)
    s_idx, o_idx = np.nonzero(near)
    counts = np.bincount(piece_side, minlength=len(near))
    reps = counts[s_idx]
    if not reps.sum():
        return owner
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    pair = np.repeat(np.arange(len(s_idx)), reps)
    piece = np.repeat(first[s_idx] - np.cumsum(reps) + reps, reps) + np.arange(reps.sum())
    side = piece_side[piece]
    lo, hi = relations.piece_rays(starts[piece], ends[piece], PIECE_INSET)[0].reshape(-1, 2).T  # as far in as the rays
    clear, reach = relations.strip_span(all_fp[o_idx[pair]], sides["centre"][side], sides["tangent"][side],
                                        sides["normal"][side], lo, hi)
    hit = (clear <= TOUCH) & (reach >= -TOUCH)  # on the side's line or across it, not wholly behind it
    order = np.argsort(-clear[hit], kind="stable")  # the deepest written last
    owner[piece[hit][order]] = o_idx[pair[hit]][order]
    return owner


class PlanLayer(NamedTuple):
    """What the visibility sweep reads of a room: its ray ``scene``, the objects' ``boxes (n, 7)``, the footprints of
    the objects then the walls ``(n + w, 4, 2)``, each one's sweep ``group (n + w,)`` (who may see whom), which objects
    are radially symmetric ``(n,)``, the ``walls`` and every node's name (objects, then walls)."""
    scene: RoomScene
    boxes: np.ndarray
    footprints: np.ndarray
    group: np.ndarray
    radial: np.ndarray
    walls: Walls
    names: list[str]


def _spatial_edges(g, room_id: str, layer: PlanLayer, cfg: dict, anchors=None) -> int:
    """Sweep every anchor side (of ``anchors``, ids, when given) and add the visible spatial edges. Returns the
    number of rays cast."""
    b, all_fp, group, walls, names = layer.boxes, layer.footprints, layer.group, layer.walls, layer.names
    n, n_walls = len(b), len(walls.ids)
    sp = cfg["spatial"]
    sides = anchor_sides(b, walls, sp)
    if anchors is not None:
        chosen = np.isin(np.asarray(names, object), list(anchors))
        sides = {k: v[chosen[sides["owner"]]] for k, v in sides.items()}
    piece_side, starts, ends, near = sweep(sides, all_fp, group)
    diag = np.concatenate([diagonal_2d(b[:, 3], b[:, 4]), np.zeros(n_walls)])  # walls: the target's diagonal decides
    p_owner, p_dist, rays = _cast_pieces(layer, sides, (piece_side, starts, ends), diag)
    touch = touching(sides, all_fp, near, piece_side, starts, ends)
    p_owner = np.where(touch >= 0, touch, p_owner)
    ok = (p_owner >= 0) & (p_owner < n)  # pieces that reach an object (walls only occlude)
    contained = {(a, t) for a, t in _contained_pairs(all_fp[:n], group[:n], sp["contain_fraction"])
                 if anchors is None or names[a] in anchors}
    if not ok.any() and not contained:
        return rays
    total = n + n_walls
    key = piece_side[ok] * total + p_owner[ok]
    uniq, inv = np.unique(key, return_inverse=True)
    vis = np.bincount(inv, weights=(ends - starts)[ok], minlength=len(uniq))
    # Embree decides which target each piece sees; geometry decides how far: the exact clearance of the target's
    # footprint within the piece (rays start inside the anchor, so a target reaching past them is hit from inside)
    ps = piece_side[ok]
    clear = relations.strip_clearance(all_fp[p_owner[ok]], sides["centre"][ps], sides["tangent"][ps],
                                      sides["normal"][ps], starts[ok], ends[ok])
    clear = np.where(np.isfinite(clear), clear, p_dist[ok] - sides["inset"][ps])
    gap = np.full(len(uniq), np.inf)
    np.minimum.at(gap, inv, clear)
    u_side, u_target = uniq // total, uniq % total
    proj = np.einsum("mkj,mj->mk", all_fp[u_target], sides["tangent"][u_side])
    target_share = np.minimum(vis / np.maximum(np.ptp(proj, axis=1), 1e-9), 1.0)
    anchor_share = np.minimum(vis / (2 * sides["half"][u_side]), 1.0)
    u_anchor, u_sidx = sides["owner"][u_side], sides["side"][u_side]
    seen = {"anchor": u_anchor, "target": u_target, "side": u_sidx, "gap": gap, "target_share": target_share,
            "anchor_share": anchor_share, "score": np.maximum(target_share, anchor_share)}
    _emit_spatial_edges(g, room_id, seen, contained, layer, diag, cfg)
    return rays


def _cast_pieces(layer: PlanLayer, sides: dict, pieces: tuple, diag: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """Two rays per sweep piece ``pieces`` (side, start, end) in the plan layer; per piece the nearer hit's owner and
    distance."""
    scene, group, n = layer.scene, layer.group, len(layer.boxes)
    piece_side, starts, ends = pieces
    pos, ray_piece = relations.piece_rays(starts, ends, PIECE_INSET)
    ray_side = piece_side[ray_piece]
    xy = sides["centre"][ray_side] + pos[:, None] * sides["tangent"][ray_side] - sides["normal"][ray_side] * sides["inset"][ray_side, None]
    origins = np.column_stack([xy, np.full(len(pos), sum(PLAN_Z) / 2)])
    dirs = np.column_stack([sides["normal"][ray_side], np.zeros(len(pos))])
    anchor = sides["owner"][ray_side]
    # supported anchors only see siblings on the same parent: their rays stop beyond the parent's footprint
    # group g in 1..n lives on object g - 1; hanging objects (groups above n) see nothing
    reach_of_group = np.concatenate([[np.inf], 2 * diag[:n], np.zeros(n)])
    reach = sides["inset"][ray_side] + reach_of_group[group[anchor]]
    hit_owner, hit_dist = scene.first_accepted(
        origins, dirs, lambda r, own, lay, face: (lay == PLAN) & (own != anchor[r]) & (group[own] == group[anchor[r]]),
        max_dist=reach)
    pr = hit_dist.reshape(-1, 2)  # per piece: the nearer of its two rays
    pick = np.argmin(pr, axis=1)
    return hit_owner.reshape(-1, 2)[np.arange(len(pr)), pick], pr[np.arange(len(pr)), pick], len(origins)


def _emit_spatial_edges(g, room_id: str, seen: dict, contained, layer: PlanLayer, diag: np.ndarray, cfg: dict) -> None:
    """One edge per (anchor, target) from the best qualifying side: highest visibility, then smallest gap."""
    names, n, radial = layer.names, len(layer.boxes), layer.radial
    total = len(names)
    a_, t_ = seen["anchor"], seen["target"]
    side_scores = np.zeros((total, total, 4))
    side_scores[a_, t_, seen["side"]] = seen["score"]
    cand = np.flatnonzero(seen["score"] >= cfg["spatial"]["min_visibility"])
    cand = cand[np.lexsort((seen["gap"][cand], -seen["score"][cand], t_[cand], a_[cand]))]
    unique_pairs, first = np.unique(a_[cand] * total + t_[cand], return_index=True)
    best = dict(zip(unique_pairs.tolist(), cand[first].tolist()))
    for a, t in contained:
        best.setdefault(a * total + t, -1)
    labels = relations.distance_labels(seen["gap"], np.maximum(diag[a_], diag[t_]), relations.DistanceBands.of(cfg["distance"]))
    for pair in sorted(best):
        a, t = divmod(pair, total)
        i = best[pair]
        if i < 0:  # target mostly inside the anchor's footprint, seen by no ray
            direction, gap_i, tv, av, label = "front", 0.0, 1.0, 1.0, "adjacent"
        else:
            direction = "front" if a >= n or radial[a] else SIDES[seen["side"][i]]
            gap_i, tv, av = float(seen["gap"][i]), float(seen["target_share"][i]), float(seen["anchor_share"][i])
            label = "adjacent" if (a, t) in contained else str(labels[i])
        sc = side_scores[a, t]
        g.edges.append(_edge(room_id, names[a], names[t], "spatial", direction, label, gap=gap_i, target_visibility=tv,
                             anchor_visibility=av, score_front=float(sc[0]), score_back=float(sc[1]),
                             score_left=float(sc[2]), score_right=float(sc[3])))


def _contained_pairs(fp: np.ndarray, group: np.ndarray, fraction: float) -> set[tuple[int, int]]:
    """(anchor, target) pairs of one group where at least ``fraction`` of the target's footprint lies in the anchor's."""
    n = len(fp)
    if n < 2:
        return set()
    lo, hi = fp.min(axis=1), fp.max(axis=1)
    touch = np.all((lo[:, None] < hi[None, :]) & (lo[None, :] < hi[:, None]), axis=2)
    i, j = np.nonzero(touch & (group[:, None] == group[None, :]) & ~np.eye(n, dtype=bool))
    if not len(i):
        return set()
    polys = shapely.polygons(fp)
    inter = shapely.area(shapely.intersection(polys[i], polys[j]))
    frac = inter / np.maximum(shapely.area(polys[j]), 1e-12)
    sel = frac >= fraction
    return set(zip(i[sel].tolist(), j[sel].tolist()))


def _architecture_edges(g: RoomGraph, room_id: str, walls: Walls, openings: list[dict], cfg: dict) -> None:
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
            if i == j or abs(i - j) in (1, w - 1) or walls.normal[i] @ walls.normal[j] > -cfg["facing_min_cos"]:
                continue
            dist = float((walls.a[j] - walls.a[i]) @ walls.normal[i])
            t = np.sort([(walls.a[j] - walls.a[i]) @ d[i], (walls.b[j] - walls.a[i]) @ d[i]])
            overlap = min(t[1], walls.length[i]) - max(t[0], 0.0)
            if dist > 0 and overlap >= cfg["facing_min_overlap"] * min(walls.length[i], walls.length[j]):
                g.edges.append(_edge(room_id, walls.ids[i], walls.ids[j], "wall_opposite", "front", "distant", gap=dist))
    for o in openings:
        mid = np.array([(o["x0"] + o["x1"]) / 2, (o["y0"] + o["y1"]) / 2])
        dist, wi = nearest_segment(mid, walls.segments)
        wi = int(wi)
        if dist > cfg["opening_tolerance"]:
            g.skipped.append((o["element_id"], "opening lies on no wall of the room"))
            continue
        width = float(math.hypot(o["x1"] - o["x0"], o["y1"] - o["y0"]))
        g.nodes.append({"room_id": room_id, "node_id": o["element_id"], "kind": o["kind"], "category": o["kind"],
                        "model_id": None, "symmetry": "none", "symmetry_origin": "architecture", "tier": 0, "parent_id": None,
                        "cx": float(mid[0]), "cy": float(mid[1]), "cz": float((o["z0"] + o["z1"]) / 2), "hx": width / 2,
                        "hy": float(walls.thickness[wi] / 2), "hz": float((o["z1"] - o["z0"]) / 2),
                        "yaw": _yaw_facing(walls.normal[wi]), "length": width})
        g.edges.append(_edge(room_id, walls.ids[wi], o["element_id"], "opening", "front", "adjacent", gap=0.0))


def _edge(room_id, src, dst, edge_type, direction=None, distance=None, **extra) -> dict:
    return {"room_id": room_id, "source": src, "target": dst, "edge_type": edge_type, "direction": direction,
            "distance": distance, **extra}
