"""Training examples for the placement networks, drawn from real rooms (PlanIT section 6): remove a random subset
of a room's objects (with whatever they support), pick a removed object with a planned edge from a kept node (an
object or a wall) as the target and that node as the anchor, and render the kept room in one of the anchor's
symmetry-equivalent frames (chosen at random: the augmentation). The location example asks for the target's centre
in that frame; the orientation example asks for its yaw, in the frame of the wall nearest to it, from a crop
centred on it. NumPy only: batches are drawn from ``(seed, step)`` so a resumed run sees the same ones."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ....room import RoomInput, Walls
from ....geometry.frames import Frame, equivalent_frames, side_in, to_local, yaw_to_local
from ....placement.layout import View, box_frame, render, wall_frame, walls_of, with_objects
from ....placement.proposers import nearest_wall
from ....graphs.data import DIRECTIONS, DISTANCES


@dataclass
class TrainingRoom:
    room: RoomInput
    walls: Walls
    edges: list[tuple[str, str, str, str]]  # kept spatial edges: source, target, direction, distance
    parent: dict[str, str]  # supported object -> its support
    symmetry: dict[str, str]  # node id -> symmetry type


def training_room(room: RoomInput, nodes, edges) -> TrainingRoom:
    """From a room's canonical arrays and its final graph rows (pandas frames of one room)."""
    kept = edges[edges["status"].astype(str) == "kept"]
    spatial = kept[kept["edge_type"].astype(str) == "spatial"]
    support = kept[kept["edge_type"].astype(str) == "support"]
    return TrainingRoom(room, walls_of(room),
                        list(zip(spatial["source"], spatial["target"], spatial["direction"].astype(str), spatial["distance"].astype(str))),
                        dict(zip(support["target"], support["source"])),
                        dict(zip(nodes["node_id"], nodes["symmetry"].astype(str))))


def condition(direction: str, distance: str, wall: bool) -> np.ndarray:
    return np.array([DIRECTIONS.index(direction), DISTANCES.index(distance), int(wall)])


def orientation_frame(walls: Walls, xy: np.ndarray) -> Frame:
    """The frame the orientation network sees a point in: at the point, turned like the nearest wall."""
    return Frame((float(xy[0]), float(xy[1])), wall_frame(walls, nearest_wall(walls, xy)).yaw)


def bin_targets(yaw_local: float, symmetry: str, bins: int) -> np.ndarray:
    """``(bins,)`` bool: the bins equivalent to ``yaw_local`` under the object's symmetry (all for radial)."""
    k = int(np.round(yaw_local / (2 * np.pi / bins))) % bins
    turns = {"rotational-2": 2, "rotational-4": 4, "radial": bins}.get(symmetry, 1)
    out = np.zeros(bins, bool)
    out[[(k + j * bins // turns) % bins for j in range(turns)]] = True
    return out


def example(tr: TrainingRoom, rng: np.random.Generator, loc_view: View, ori_view: View, bins: int):
    """One (location, orientation) example pair, or None when the drawn subset leaves no target."""
    ids = tr.room.object_ids
    removed = rng.random(len(ids)) < rng.uniform(0.2, 1.0)
    for k, o in enumerate(ids):  # what a removed object supports goes too
        p = tr.parent.get(o)
        while p is not None and not removed[k]:
            removed[k] = p in ids and removed[ids.index(p)]
            p = tr.parent.get(p)
    gone = {o for o, r in zip(ids, removed) if r}
    present = (set(ids) - gone) | set(tr.walls.ids)
    cand = [e for e in tr.edges if e[1] in gone and e[0] in present]
    if not cand:
        return None
    src, tgt, direction, distance = cand[int(rng.integers(len(cand)))]
    keep = np.flatnonzero(~removed)
    kept = with_objects(tr.room, keep)
    wall = src in tr.walls.ids
    a_obj = None if wall else kept.object_ids.index(src)
    base = wall_frame(tr.walls, tr.walls.ids.index(src)) if wall else box_frame(kept.boxes[a_obj])
    frames = equivalent_frames(base, "none" if wall else tr.symmetry.get(src, "none"))
    frame = frames[int(rng.integers(len(frames)))]
    t = tr.room.boxes[ids.index(tgt)]
    row, col, ok = loc_view.pixel(to_local(frame, t[None, :2]))
    if not ok[0]:
        return None
    loc_img = render(kept, tr.walls, loc_view, frame, anchor=a_obj, anchor_wall=tr.walls.ids.index(src) if wall else None)
    cat = loc_view.categories.index(tr.room.categories[ids.index(tgt)])
    cond = condition(side_in(frame, base, direction), distance, wall)
    of = orientation_frame(tr.walls, t[:2])
    ori_img = render(kept, tr.walls, ori_view, of)
    ori_bins = bin_targets(float(yaw_to_local(of, t[6])), tr.symmetry.get(tgt, "none"), bins)
    return loc_img, cond, cat, int(row[0]), int(col[0]), ori_img, ori_bins


def batch(rooms: list[TrainingRoom], seed: int, step: int, size: int, loc_view: View, ori_view: View, bins: int):
    """``size`` examples drawn from ``(seed, step)`` as stacked arrays."""
    rng = np.random.default_rng([seed, step])
    out = []
    tries = 0
    while len(out) < size and tries < 20 * size:
        tries += 1
        ex = example(rooms[int(rng.integers(len(rooms)))], rng, loc_view, ori_view, bins)
        if ex is not None:
            out.append(ex)
    cols = list(zip(*out))
    return {"loc": np.stack(cols[0]), "cond": np.stack(cols[1]), "cat": np.array(cols[2]), "row": np.array(cols[3]),
            "col": np.array(cols[4]), "ori": np.stack(cols[5]), "bins": np.stack(cols[6])}
