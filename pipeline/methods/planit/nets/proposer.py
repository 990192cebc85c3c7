"""The trained networks as a search proposer: location densities from the CFCN (per anchor: summed over its
symmetry-equivalent frames; across anchors: multiplied; kept by the room's content, so that a backtrack finds an
earlier room's densities again), orientations sampled from the orientation network."""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import torch

from ....learning.checkpoint import Checkpoint
from ....room import RoomInput, Walls
from ....geometry.frames import equivalent_frames, side_in, to_local, yaw_to_world
from ....placement.layout import render
from .data import condition, orientation_frame
from .train import build, views

FLOOR = 1e-3  # an anchor's map never drops below this share of its peak (a window may miss part of the room)


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


class NetProposer:
    def __init__(self, saved: Checkpoint, cache_size: int, film: bool = True, device: str = "cpu"):
        self.categories = tuple(saved.record["categories"])
        self.preset = saved.record["preset"]
        self.loc, self.ori = build(self.preset, self.categories, film)
        self.loc.load_state_dict(saved.state["nets"][0])
        self.ori.load_state_dict(saved.state["nets"][1])
        self.loc.eval()
        self.ori.eval()
        self.loc_view, self.ori_view = views(self.preset, self.categories)
        self.device = device
        self.densities = Memo(cache_size)  # exact: keyed on content (instantiate.density_cache entries)

    def _maps(self, room: RoomInput, walls: Walls, anchors) -> list[tuple[list, np.ndarray]]:
        """Per anchor: its frames and the ``(frames, categories + 1, s, s)`` softmax maps."""
        imgs, conds, spans = [], [], []
        for a in anchors:
            frames = equivalent_frames(a.frame, a.symmetry)
            for f in frames:
                imgs.append(render(room, walls, self.loc_view, f, anchor=a.obj, anchor_wall=a.wall))
                conds.append(condition(side_in(f, a.frame, a.direction), a.distance, a.wall is not None))
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
        key = room_key(room, walls, category, [(a.node, a.obj, a.wall, a.symmetry, a.direction, a.distance) for a in anchors],
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

    def orientation(self, room: RoomInput, walls: Walls, category: str, symmetry: str, xy: np.ndarray,
                    rng: np.random.Generator) -> float:
        frame = orientation_frame(walls, xy)
        if category not in self.categories:
            return float(frame.yaw)
        with torch.no_grad():
            logits = self.ori(torch.as_tensor(render(room, walls, self.ori_view, frame)[None]))[0, self.categories.index(category)]
        p = torch.softmax(logits, 0).numpy().astype(float)
        b = int(rng.choice(len(p), p=p / p.sum()))
        return float(yaw_to_world(frame, b * 2 * np.pi / len(p)))
