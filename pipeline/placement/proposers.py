"""Proposers without networks: uniform locations (the "random location" ablation of PlanIT's Table 3) and the
orientation rule "face away from the nearest wall" (used where no orientation network is given). The network
proposer is :class:`pipeline.methods.planit.nets.proposer.NetProposer`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..room import RoomInput, Walls
from ..geometry.polygon import segment_distances
from ..geometry.boxes import SIDES
from ..geometry.frames import to_local
from .layout import wall_frame

# how far beyond an anchor's side (m) a target's centre may lie: (from, to) as (its small half extent, its large
# half extent) plus these offsets, per distance label (RelationPrior)
BANDS = {"adjacent": (-0.05, 0.15), "proximal": (0.03, 0.6), "distant": (0.3, np.inf)}


def nearest_wall(walls: Walls, xy: np.ndarray) -> int:
    return int(np.argmin(segment_distances(np.asarray(xy, float), np.stack([walls.a, walls.b], 1))))


class UniformLocation:
    """Every candidate centre equally likely (before the floor / support mask)."""

    def density(self, room: RoomInput, walls: Walls, category: str, anchors, points: np.ndarray) -> np.ndarray:
        return np.ones(len(points))


class RelationPrior:
    """No network: each anchor allows the band beyond its side named by the edge's direction, as deep as
    :data:`BANDS` says for the edge's distance and as wide as the side plus ``margin`` m; anchors multiply. A
    baseline, and the proposer of the tests that must not depend on training."""

    def __init__(self, margin: float = 0.6, soft: float = 0.0):
        self.margin, self.soft = margin, soft  # soft: the density outside a band (0: none)

    def density(self, room: RoomInput, walls: Walls, category: str, anchors, points: np.ndarray) -> np.ndarray:
        out = np.ones(len(points))
        for a in anchors:
            local = to_local(a.frame, points)
            if a.wall is not None:
                depth, along, half_len = local[:, 1], local[:, 0], walls.length[a.wall] / 2
            else:
                hx, hy = room.boxes[a.obj, 3:5]
                s = SIDES.index(a.direction)
                axis, sign = (1, 1.0 if s == 0 else -1.0) if s < 2 else (0, -1.0 if s == 2 else 1.0)
                depth = sign * local[:, axis] - (hy if axis == 1 else hx)
                along, half_len = local[:, 1 - axis], (hx if axis == 1 else hy)
            lo, hi = BANDS[a.distance]
            small, large = min(a.target_half), max(a.target_half)
            inside = (depth >= small + lo) & (depth <= large + hi) & (np.abs(along) <= half_len + self.margin)
            out *= np.where(inside, 1.0, self.soft)
        return out


class FaceAway:
    """Front turned away from the nearest wall (into the room)."""

    def orientation(self, room: RoomInput, walls: Walls, category: str, symmetry: str, xy: np.ndarray,
                    rng: np.random.Generator) -> float:
        return wall_frame(walls, nearest_wall(walls, xy)).yaw


@dataclass
class Combined:
    """Locations from one proposer, orientations from another."""
    location: object
    orienter: object

    def density(self, *args) -> np.ndarray:
        return self.location.density(*args)

    def orientation(self, *args) -> float:
        return self.orienter.orientation(*args)


@dataclass
class Masked:
    """A proposer whose densities are weighted by ``mask``'s (e.g. the network's by the relation bands: with soft
    bands, where fewer relations can hold is unlikely, not impossible)."""
    base: object
    mask: object

    def density(self, *args) -> np.ndarray:
        return self.base.density(*args) * self.mask.density(*args)

    def orientation(self, *args) -> float:
        return self.base.orientation(*args)
