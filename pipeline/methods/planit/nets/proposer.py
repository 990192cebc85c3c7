"""The trained networks as a search proposer of whole poses. Location: the CFCN's density per anchor (every planned
edge to what is placed: spatial edges either way and the support edge; summed over the anchor's symmetry-equivalent
frames), multiplied across anchors, kept by the room's content so that a backtrack finds an earlier room's densities
again. Orientation at the drawn location: per anchor the network's yaw distribution in each equivalent frame (turned
to world yaws on a grid of :data:`TURNS` and averaged), multiplied across anchors; then, as the paper's snap
classifier does, the object is drawn square to the nearest wall with the networks' mean snap probability (one of
that wall's four axes, weighted by the distribution), else at a yaw off those axes drawn from it. So objects turned
off the walls' axes appear about as often as the networks learned from the training rooms."""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import torch

from ....geometry.frames import Frame, equivalent_frames, to_local, turn_error, yaw_to_local
from ....learning.checkpoint import Checkpoint
from ....placement.anchors import Anchor
from ....placement.layout import render, wall_frame
from ....placement.proposers import DensityProposer, Request, nearest_wall
from ....room import RoomInput, Walls
from .data import Condition, crop_frame, in_frame, relative
from .train import build, views

FLOOR = 1e-3  # an anchor's map never drops below this share of its peak (a window may miss part of the room)
TURNS = 72  # world yaws the orientation is drawn from (5 degrees apart)


def room_key(room: RoomInput, walls: Walls, *parts, arrays: tuple = ()) -> bytes:
    """A digest of a room's content (ids, categories, boxes, outline, walls, openings) and of ``parts`` (reprs)
    and ``arrays``. Backtracking returns to earlier rooms as new objects with the same content: keyed this way,
    what the networks computed for them is found again."""
    h = hashlib.blake2b(digest_size=16)
    for part in (room.room_id, room.object_ids, room.categories, room.openings, *parts):
        h.update(repr(part).encode())
    for arr in (room.boxes, room.outline, walls.a, walls.b, walls.thickness, *arrays):
        h.update(np.ascontiguousarray(arr, float).tobytes())
    return h.digest()


class Memo:
    """The ``size`` most recently used results by key; ``computed`` and ``reused`` count misses and hits."""

    def __init__(self, size: int):
        self.size, self.computed, self.reused = size, 0, 0
        self._items: OrderedDict = OrderedDict()

    def get(self, key: bytes, compute):
        if key in self._items:
            self._items.move_to_end(key)
            self.reused += 1
            return self._items[key]
        self.computed += 1
        out = self._items[key] = compute()
        if len(self._items) > self.size:
            self._items.popitem(last=False)
        return out


def condition_of(a: Anchor | None) -> Condition:
    """The network condition of an anchor's planned edge (None: no anchor, the nearest wall as frame)."""
    if a is None:
        return Condition("none", True)
    return Condition(a.edge, a.wall is not None, a.reverse)


def frames_of(a: Anchor) -> list[Frame]:
    return equivalent_frames(a.frame, "none" if a.wall is not None else a.symmetry)


class NetProposer(DensityProposer):
    def __init__(self, saved: Checkpoint, cache_size: int, film: bool = True, device: str = "cpu"):
        self.categories = tuple(saved.record["categories"])
        self.preset = saved.record["preset"]
        self.snap_angle = np.radians(saved.record.get("snap_angle", 5.0))
        self.loc, self.ori = build(self.preset, self.categories, film)
        self.loc.load_state_dict(saved.state["nets"][0])
        self.ori.load_state_dict(saved.state["nets"][1])
        self.loc.eval()
        self.ori.eval()
        self.loc_view, self.ori_view = views(self.preset, self.categories)
        self.device = device
        self.densities = Memo(cache_size)  # exact: keyed on content (instantiate.density_cache entries)

    def _maps(self, room: RoomInput, walls: Walls, anchors: list[Anchor]) -> list[tuple[list, np.ndarray]]:
        """Per anchor: its frames and the ``(frames, categories + 1, s, s)`` softmax maps."""
        imgs, conds, spans = [], [], []
        for a in anchors:
            frames = frames_of(a)
            for f in frames:
                imgs.append(render(room, walls, self.loc_view, f, anchor=a.obj, anchor_wall=a.wall))
                conds.append(in_frame(condition_of(a), f, a.frame).array())
            spans.append(frames)
        with torch.no_grad():
            probs = torch.softmax(self.loc(torch.as_tensor(np.stack(imgs)), torch.as_tensor(np.stack(conds))), 1).numpy()
        out, k = [], 0
        for frames in spans:
            out.append((frames, probs[k:k + len(frames)]))
            k += len(frames)
        return out

    def density(self, room: RoomInput, walls: Walls, category: str, anchors, points: np.ndarray) -> np.ndarray:
        if not anchors or category not in self.categories:
            return np.ones(len(points))
        key = room_key(room, walls, category, [(a.node, a.obj, a.wall, a.symmetry, a.edge, a.reverse) for a in anchors],
                       arrays=(points,))
        return self.densities.get(key, lambda: self._density(room, walls, category, anchors, points))

    def _density(self, room, walls, category, anchors, points) -> np.ndarray:
        c = self.categories.index(category) + 1
        out = np.ones(len(points))
        for frames, probs in self._maps(room, walls, anchors):
            d = np.zeros(len(points))
            for f, p in zip(frames, probs):
                m = p[c] / max(p[c].sum(), 1e-12)
                row, col, ok = self.loc_view.pixel(to_local(f, points))
                d[ok] += m[row[ok], col[ok]]
            out *= d + FLOOR * max(d.max(), 1e-12)
        return out

    def turns(self, req: Request, xy: np.ndarray) -> tuple[np.ndarray, float]:
        """``(TURNS,)`` the distribution of the object's world yaw at ``xy`` (yaws ``k * 2 pi / TURNS``) and the
        probability that it stands square to the nearest wall, from every anchor (or none)."""
        c = self.categories.index(req.category)
        anchors = req.anchors or [None]
        rows, spans = [], []
        for a in anchors:
            frames = frames_of(a) if a is not None else [wall_frame(req.walls, nearest_wall(req.walls, xy))]
            for f in frames:
                rows.append((f, a))
            spans.append(len(frames))
        imgs = np.stack([render(req.room, req.walls, self.ori_view, crop_frame(f, xy),
                                anchor=None if a is None else a.obj, anchor_wall=None if a is None else a.wall)
                         for f, a in rows])
        conds = np.stack([in_frame(condition_of(a), f, a.frame if a is not None else f).array() for f, a in rows])
        rel = np.stack([relative(f, xy) for f, _ in rows])
        with torch.no_grad():
            out = self.ori(torch.as_tensor(imgs), torch.as_tensor(conds), torch.as_tensor(rel))[:, c].numpy()
        return combine_turns([f for f, _ in rows], spans, out[:, :-1], out[:, -1])

    def orientation(self, req: Request, xy: np.ndarray, rng: np.random.Generator) -> float:
        """A yaw drawn as the paper's orientation module with its snap classifier does (module docstring)."""
        if req.category not in self.categories:
            return float(wall_frame(req.walls, nearest_wall(req.walls, xy)).yaw)
        p, snap = self.turns(req, xy)
        return draw_turn(p, snap, wall_frame(req.walls, nearest_wall(req.walls, xy)).yaw, self.snap_angle, rng)


def combine_turns(frames: list[Frame], spans: list[int], logits: np.ndarray, snap: np.ndarray) -> tuple[np.ndarray, float]:
    """``(TURNS,)`` world-yaw distribution from per-frame bin ``logits (rows, bins)`` (each row's bins relative to its
    frame; consecutive ``spans`` rows are one anchor's frames, averaged; anchors multiplied) and the mean snap
    probability of the rows' ``snap`` logits."""
    grid = np.arange(TURNS) * 2 * np.pi / TURNS
    bins = logits.shape[1]
    p = np.exp(logits - logits.max(1, keepdims=True))
    p /= p.sum(1, keepdims=True)
    out, k = np.ones(TURNS), 0
    for n in spans:
        d = np.zeros(TURNS)
        for f, row in zip(frames[k:k + n], p[k:k + n]):
            b = np.round(yaw_to_local(f, grid) / (2 * np.pi / bins)).astype(int) % bins
            d += row[b]
        out *= d + FLOOR * d.max()
        k += n
    return out / out.sum(), float(np.mean(1 / (1 + np.exp(-snap))))


def draw_turn(p: np.ndarray, snap: float, wall_yaw: float, angle: float, rng: np.random.Generator) -> float:
    """A world yaw from the ``(TURNS,)`` distribution ``p``: with probability ``snap`` one of the wall's four axes
    (weighted by ``p`` there), else a yaw more than ``angle`` rad off them."""
    grid = np.arange(TURNS) * 2 * np.pi / TURNS
    if rng.random() < snap:
        axes = wall_yaw + np.arange(4) * np.pi / 2
        w = p[np.round(axes / (2 * np.pi / TURNS)).astype(int) % TURNS] + 1e-12
        return float(axes[rng.choice(4, p=w / w.sum())])
    off = turn_error(grid - wall_yaw, "rotational-4") > angle
    w = np.where(off, p, 0.0)
    if w.sum() <= 0:
        return float(wall_yaw)
    k = rng.choice(TURNS, p=w / w.sum())
    return float(grid[k] + rng.uniform(-0.5, 0.5) * 2 * np.pi / TURNS)
