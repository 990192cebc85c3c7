"""A relative-pose prior: PlanIT's layout without networks (method ``planit_prior``). For every triple (anchor
category or ``wall``, target category, edge kind, reverse) of the fit split's final graphs it keeps the target's
relative poses (:func:`relative_pose`: centre and turn in the anchor's frame; for a wall the place along it as a share
of its half length, the distance from it and the turn from its normal) as a kernel density (a Gaussian per sample,
Scott's bandwidth per axis within ``bandwidth``). A pose is drawn from the tightest anchor's density (the smallest
spread of its triple) and weighed by every other anchor's density (and the relation bands, when given): the field's
strongest non-neural answer (the string method's relative-pose clusters, S-AOG's pairwise terms). Turns are the
training samples' own, so objects off their anchors' axes appear as often as in the training rooms. Nothing is
trained: learning takes seconds. No torch."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.frames import Frame, boxes_to_local, turn_error, wrap
from ..room import RoomInput, Walls
from .anchors import Anchor
from .layout import box_frame, wall_frame, walls_of
from .proposers import DensityProposer, Request, nearest_wall

KIND = "pose_prior"  # the checkpoint kind its learner writes
Triple = tuple[str, str, str, bool]  # anchor category (or "wall"), target category, edge kind, reverse


def relative_pose(frame: Frame, scale: float, box: np.ndarray) -> np.ndarray:
    """``(3,)`` x / scale, y, yaw of ``box (7,)`` in ``frame``."""
    local = boxes_to_local(frame, box)[0]
    return np.array([local[0] / scale, local[1], local[6]])


def from_relative(frame: Frame, scale: float, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World centres ``(m, 2)`` and yaws ``(m,)`` of relative ``pose (m, 3)`` in ``frame`` (the inverse of
    :func:`relative_pose` on centres and yaws; ``frame`` is never mirrored here)."""
    pose = np.asarray(pose, float).reshape(-1, 3)
    c, s = np.cos(frame.yaw), np.sin(frame.yaw)
    x, y = pose[:, 0] * scale, pose[:, 1]
    xy = np.stack([frame.origin[0] + c * x - s * y, frame.origin[1] + s * x + c * y], 1)
    return xy, wrap(frame.yaw + pose[:, 2])


def anchor_frame(node_id: str, room: RoomInput, walls: Walls) -> tuple[Frame, float] | None:
    """The frame of an anchor node (an object or a wall of ``room``) and the scale of its x (a wall's half length;
    1 for an object); None for other nodes (doors, windows)."""
    if node_id in room.object_ids:
        return box_frame(room.boxes[room.object_ids.index(node_id)]), 1.0
    if node_id in walls.ids:
        w = walls.ids.index(node_id)
        return wall_frame(walls, w), float(walls.length[w]) / 2
    return None


def room_samples(room: RoomInput, edges: list[tuple[str, str, str]]) -> dict[Triple, list[np.ndarray]]:
    """Relative poses of one room's kept ``edges`` (source, target, edge kind) by triple: each edge's target in its
    source's frame and, for a spatial edge between objects, its source in its target's frame (reverse)."""
    walls, out = walls_of(room), {}
    cat = dict(zip(room.object_ids, room.categories))
    for src, tgt, kind in edges:
        if tgt not in cat:
            continue
        frame = anchor_frame(src, room, walls)
        if frame is not None:
            key = (cat.get(src, "wall"), cat[tgt], kind, False)
            out.setdefault(key, []).append(relative_pose(*frame, room.boxes[room.object_ids.index(tgt)]))
        if kind != "support" and src in cat:
            back = box_frame(room.boxes[room.object_ids.index(tgt)])
            out.setdefault((cat[tgt], cat[src], kind, True), []).append(
                relative_pose(back, 1.0, room.boxes[room.object_ids.index(src)]))
    return out


def bandwidth(poses: np.ndarray, cfg: dict) -> np.ndarray:
    """``(2,)`` Scott's bandwidth of the positions of ``poses (n, 3)``, clipped to ``cfg['bandwidth']`` (m)."""
    lo, hi = cfg["bandwidth"]
    sd = poses[:, :2].std(0) if len(poses) > 1 else np.full(2, hi)
    return np.clip(sd * len(poses) ** (-1 / 6), lo, hi)


def learn_prior(rooms: list[tuple[RoomInput, list[tuple[str, str, str]]]], cfg: dict) -> dict:
    """The prior's record (JSON-ready): per triple its relative poses, bandwidth and spread, from ``rooms`` (each
    with its kept final edges); triples with fewer than ``cfg['min_samples']`` samples are left out."""
    pooled: dict[Triple, list[np.ndarray]] = {}
    for room, edges in rooms:
        for key, poses in room_samples(room, edges).items():
            pooled.setdefault(key, []).extend(poses)
    triples = []
    for key in sorted(pooled, key=lambda k: (k[0], k[1], k[2], k[3])):
        poses = np.array(pooled[key])
        if len(poses) < cfg["min_samples"]:
            continue
        bw = bandwidth(poses, cfg)
        spread = float(np.sqrt(np.prod(poses[:, :2].std(0) + bw))) if len(poses) > 1 else float(np.prod(bw))
        triples.append({"anchor": key[0], "target": key[1], "edge": key[2], "reverse": key[3],
                        "poses": np.round(poses, 4).tolist(), "bandwidth": bw.round(4).tolist(), "spread": spread})
    return {"triples": triples, "rooms": len(rooms), "settings": dict(cfg)}


@dataclass
class Density:
    """One triple's kernel density: samples ``(n, 3)``, position bandwidth ``(2,)`` and spread."""
    poses: np.ndarray
    bandwidth: np.ndarray
    spread: float

    def weigh(self, rel: np.ndarray, symmetry: str, turn: float) -> np.ndarray:
        """``(m,)`` density of relative poses ``rel (m, 3)`` (positions by their Gaussian kernels, turns within
        ``turn`` rad of a sample's, counting the target's equivalent turns)."""
        d = (rel[:, None, :2] - self.poses[None, :, :2]) / self.bandwidth
        near = turn_error(rel[:, None, 2] - self.poses[None, :, 2], symmetry) <= turn
        return (np.exp(-0.5 * (d ** 2).sum(-1)) * near).mean(1)


class PosePrior(DensityProposer):
    """The prior as a search proposer (module docstring). ``bands``: the relation bands' density (a
    :class:`~pipeline.placement.proposers.RelationPrior`) that weighs the drawn poses too, or None."""

    def __init__(self, densities: dict[Triple, Density], cfg: dict, bands=None):
        self.densities, self.cfg, self.bands = densities, cfg, bands

    @classmethod
    def from_record(cls, record: dict, bands=None) -> "PosePrior":
        dens = {(t["anchor"], t["target"], t["edge"], bool(t["reverse"])):
                Density(np.array(t["poses"], float), np.array(t["bandwidth"], float), float(t["spread"]))
                for t in record["triples"]}
        return cls(dens, record["settings"], bands)

    def density_of(self, a: Anchor, req: Request) -> Density | None:
        anchor = "wall" if a.wall is not None else req.room.categories[a.obj]
        return self.densities.get((anchor, req.category, a.edge, a.reverse))

    def frame(self, a: Anchor, req: Request) -> tuple[Frame, float]:
        return (a.frame, float(req.walls.length[a.wall]) / 2) if a.wall is not None else (a.frame, 1.0)

    def density(self, room, walls, category, anchors, points) -> np.ndarray:
        """Where no anchor has a triple: the bands (or everywhere)."""
        return np.ones(len(points)) if self.bands is None else self.bands.density(room, walls, category, anchors, points)

    def orientation(self, req: Request, xy: np.ndarray, rng: np.random.Generator) -> float:
        return float(wall_frame(req.walls, nearest_wall(req.walls, xy)).yaw)

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        """A pose from the tightest anchor's density weighed by the others' (module docstring)."""
        known = [(a, d) for a in req.anchors if (d := self.density_of(a, req)) is not None]
        if not known or not req.mask.any():
            return super().pose(req, rng)
        lead, dens = min(known, key=lambda ad: ad[1].spread)
        pick = rng.integers(len(dens.poses), size=self.cfg["candidates"])
        rel = dens.poses[pick] + np.concatenate([rng.normal(size=(len(pick), 2)) * dens.bandwidth,
                                                 np.zeros((len(pick), 1))], 1)
        xy, yaw = from_relative(*self.frame(lead, req), rel)
        cells = req.grid.cells(xy)
        w = np.where(cells >= 0, req.mask[np.maximum(cells, 0)], False).astype(float)
        for a, d in known:
            if a is not lead and w.any():
                w *= d.weigh(self.relative(a, req, xy, yaw), req.symmetry, np.radians(self.cfg["turn"]))
        if self.bands is not None and w.any():
            w *= self.bands.density(req.room, req.walls, req.category, req.anchors, xy)
        if w.sum() <= 0:
            drawn = super().pose(req, rng)
            return None if drawn is None else (drawn[0], float(yaw[rng.integers(len(yaw))]))
        k = rng.choice(len(w), p=w / w.sum())
        return xy[k], float(yaw[k])

    def relative(self, a: Anchor, req: Request, xy: np.ndarray, yaw: np.ndarray) -> np.ndarray:
        """``(m, 3)`` candidate poses in anchor ``a``'s frame (its x as a share of a wall's half length)."""
        frame, scale = self.frame(a, req)
        boxes = np.zeros((len(xy), 7))
        boxes[:, :2], boxes[:, 6] = xy, yaw
        local = boxes_to_local(frame, boxes)
        return np.stack([local[:, 0] / scale, local[:, 1], local[:, 6]], 1)
