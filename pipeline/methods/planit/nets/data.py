"""Training examples for the pose networks, drawn from real rooms (PlanIT section 6): remove a random subset of a
room's objects (with whatever they support), pick a removed object and one of its planned edges to a kept node as the
condition (a spatial edge from a kept object or wall, its support edge from its kept parent, or a spatial edge of its
own to a kept object: a *reverse* edge), and render the kept room in one of that anchor's symmetry-equivalent frames
(chosen at random: the augmentation). Every object is a target: those on a parent through their support edge. A
share ``none_share`` of examples has no planned edge (the nearest wall as the frame, condition ``none``).

The location example asks for the target's centre in the anchor's frame. The orientation example asks for its yaw
relative to that frame (bins, each symmetric target's equivalent bins together) and whether it stands square to the
nearest wall (within ``snap_angle``: the paper's snap), from a crop centred on the target turned like the anchor's
frame, with the edge and the target's position in that frame as the condition. NumPy only: batches are drawn from
``(seed, step)`` so a resumed run sees the same ones."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ....geometry.frames import Frame, equivalent_frames, side_in, to_local, turn_error, yaw_to_local
from ....graphs.data import DIRECTIONS, DISTANCES
from ....placement.layout import View, box_frame, render, wall_frame, walls_of, with_objects
from ....placement.proposers import nearest_wall
from ....room import RoomInput, Walls
from ....seeding import rng_for

EDGE_KINDS = (*(f"{d}/{s}" for d in DIRECTIONS for s in DISTANCES), "support", "none")
REACH = 4.0  # m: the scale of the target's position in its anchor's frame, as the orientation network reads it


@dataclass
class TrainingRoom:
    room: RoomInput
    walls: Walls
    edges: list[tuple[str, str, str]]  # kept support and spatial edges: source, target, edge kind (EDGE_KINDS)
    parent: dict[str, str]  # supported object -> its support
    symmetry: dict[str, str]  # node id -> symmetry type


@dataclass(frozen=True)
class Condition:
    """The planned edge a pose is conditioned on: its kind (:data:`EDGE_KINDS`; a forward spatial edge's direction
    named in the frame the network sees), whether the anchor is a wall, and whether the edge runs from the target to
    the anchor."""
    edge: str
    wall: bool = False
    reverse: bool = False

    def array(self) -> np.ndarray:
        return np.array([EDGE_KINDS.index(self.edge), int(self.wall), int(self.reverse)])


def training_room(room: RoomInput, nodes, edges) -> TrainingRoom:
    """From a room's canonical arrays and its final graph rows (pandas frames of one room)."""
    kept = edges[(edges["status"].astype(str) == "kept") & edges["edge_type"].astype(str).isin(["spatial", "support"])]
    kind = [("support" if t == "support" else f"{d}/{x}") for t, d, x in
            zip(kept["edge_type"].astype(str), kept["direction"].astype(str), kept["distance"].astype(str))]
    support = kept[kept["edge_type"].astype(str) == "support"]
    return TrainingRoom(room, walls_of(room), list(zip(kept["source"], kept["target"], kind)),
                        dict(zip(support["target"], support["source"])),
                        dict(zip(nodes["node_id"], nodes["symmetry"].astype(str))))


def in_frame(cond: Condition, frame: Frame, base: Frame) -> Condition:
    """The condition as seen in ``frame``, an equivalent frame of the anchor's ``base``: a forward spatial edge's side
    renamed (a reverse edge's direction is the target's own; support and none have none)."""
    if cond.reverse or "/" not in cond.edge:
        return cond
    direction, distance = cond.edge.split("/")
    return Condition(f"{side_in(frame, base, direction)}/{distance}", cond.wall, cond.reverse)


def relative(frame: Frame, xy: np.ndarray) -> np.ndarray:
    """``(2,)`` a point's position in ``frame``, in units of :data:`REACH`."""
    return (to_local(frame, np.asarray(xy, float)[None])[0] / REACH).astype(np.float32)


def crop_frame(frame: Frame, xy: np.ndarray) -> Frame:
    """The orientation crop's frame: centred on ``xy``, turned (and mirrored) like ``frame``."""
    return Frame((float(xy[0]), float(xy[1])), frame.yaw, frame.mirror)


def bin_targets(yaw_local: float, symmetry: str, bins: int) -> np.ndarray:
    """``(bins,)`` bool: the bins equivalent to ``yaw_local`` under the object's symmetry (all for radial)."""
    k = int(np.round(yaw_local / (2 * np.pi / bins))) % bins
    turns = {"rotational-2": 2, "front-back": 2, "rotational-4": 4, "radial": bins}.get(symmetry, 1)
    out = np.zeros(bins, bool)
    out[[(k + j * bins // turns) % bins for j in range(turns)]] = True
    return out


def square_to_wall(walls: Walls, xy: np.ndarray, yaw: float, angle: float) -> bool:
    """Whether ``yaw`` lies within ``angle`` rad of the nearest wall's axes (a quarter turn of its frame)."""
    return bool(turn_error(yaw - wall_frame(walls, nearest_wall(walls, xy)).yaw, "rotational-4") <= angle)


def removal(tr: TrainingRoom, rng: np.random.Generator) -> np.ndarray:
    """``(n,)`` bool: a random subset of the room's objects, with whatever they support."""
    ids = tr.room.object_ids
    removed = rng.random(len(ids)) < rng.uniform(0.2, 1.0)
    for k, o in enumerate(ids):
        p = tr.parent.get(o)
        while p is not None and not removed[k]:
            removed[k] = p in ids and removed[ids.index(p)]
            p = tr.parent.get(p)
    return removed


def candidates(tr: TrainingRoom, gone: set[str], present: set[str]) -> list[tuple[str, str, Condition]]:
    """(anchor, target, condition) of every kept edge between a removed target and a kept anchor."""
    walls = set(tr.walls.ids)
    out = []
    for src, tgt, kind in tr.edges:
        if tgt in gone and src in present:
            out.append((src, tgt, Condition(kind, src in walls)))
        elif kind != "support" and src in gone and tgt in present and tgt not in walls:
            out.append((tgt, src, Condition(kind, False, True)))
    return out


def draw(tr: TrainingRoom, rng: np.random.Generator, none_share: float):
    """The kept rooms' object mask, and (anchor, target, condition), or None when the draw leaves no target."""
    removed = removal(tr, rng)
    gone = {o for o, r in zip(tr.room.object_ids, removed) if r}
    if not gone:
        return None
    cand = candidates(tr, gone, (set(tr.room.object_ids) - gone) | set(tr.walls.ids))
    if not cand or rng.random() < none_share:
        tgt = sorted(gone)[int(rng.integers(len(gone)))]
        xy = tr.room.boxes[tr.room.object_ids.index(tgt), :2]
        return removed, (tr.walls.ids[nearest_wall(tr.walls, xy)], tgt, Condition("none", True))
    return removed, cand[int(rng.integers(len(cand)))]


def example(tr: TrainingRoom, rng: np.random.Generator, loc_view: View, ori_view: View, bins: int, snap_angle: float,
            none_share: float):
    """One (location, orientation) example pair, or None when the draw leaves no target in view."""
    drawn = draw(tr, rng, none_share)
    if drawn is None:
        return None
    removed, (src, tgt, cond) = drawn
    kept = with_objects(tr.room, np.flatnonzero(~removed))
    a_obj = None if cond.wall else kept.object_ids.index(src)
    a_wall = tr.walls.ids.index(src) if cond.wall else None
    base = wall_frame(tr.walls, a_wall) if cond.wall else box_frame(kept.boxes[a_obj])
    frames = equivalent_frames(base, "none" if cond.wall else tr.symmetry.get(src, "none"))
    frame = frames[int(rng.integers(len(frames)))]
    t = tr.room.boxes[tr.room.object_ids.index(tgt)]
    row, col, ok = loc_view.pixel(to_local(frame, t[None, :2]))
    if not ok[0]:
        return None
    cond = in_frame(cond, frame, base)
    loc_img = render(kept, tr.walls, loc_view, frame, anchor=a_obj, anchor_wall=a_wall)
    ori_img = render(kept, tr.walls, ori_view, crop_frame(frame, t[:2]), anchor=a_obj, anchor_wall=a_wall)
    ori_bins = bin_targets(float(yaw_to_local(frame, t[6])), tr.symmetry.get(tgt, "none"), bins)
    cat = loc_view.categories.index(tr.room.categories[tr.room.object_ids.index(tgt)])
    snapped = square_to_wall(tr.walls, t[:2], float(t[6]), snap_angle)
    return loc_img, cond.array(), cat, int(row[0]), int(col[0]), ori_img, relative(frame, t[:2]), ori_bins, snapped


FIELDS = ("loc", "cond", "cat", "row", "col", "ori", "rel", "bins", "snap")


def batch(rooms: list[TrainingRoom], seed: int, step: int, size: int, loc_view: View, ori_view: View, cfg: dict):
    """``size`` examples drawn from ``(seed, step)`` as stacked arrays (``cfg``: bins, snap_angle (deg), none_share)."""
    rng = rng_for(seed, step)
    out, tries = [], 0
    while len(out) < size and tries < 20 * size:
        tries += 1
        ex = example(rooms[int(rng.integers(len(rooms)))], rng, loc_view, ori_view, cfg["bins"],
                     np.radians(cfg["snap_angle"]), cfg["none_share"])
        if ex is not None:
            out.append(ex)
    return {name: np.stack(col) if name in ("loc", "cond", "ori", "rel", "bins") else np.array(col)
            for name, col in zip(FIELDS, zip(*out))}
