"""The trained networks as a search proposer: location densities from the CFCN (per anchor: summed over its
symmetry-equivalent frames; across anchors: multiplied), orientations sampled from the orientation network."""
from __future__ import annotations

import numpy as np
import torch

from ..extraction import RoomInput, Walls
from ..geometry.frames import equivalent_frames, side_in, to_local, yaw_to_world
from ..placement.layout import render
from .placement_data import condition, orientation_frame
from .placement_train import build, views

FLOOR = 1e-3  # an anchor's map never drops below this share of its peak (a window may miss part of the room)


class NetProposer:
    def __init__(self, saved: dict, film: bool = True, device: str = "cpu"):
        self.categories = tuple(saved["categories"])
        self.preset = saved["preset"]
        self.loc, self.ori = build(self.preset, self.categories, film)
        self.loc.load_state_dict(saved["nets"][0])
        self.ori.load_state_dict(saved["nets"][1])
        self.loc.eval()
        self.ori.eval()
        self.loc_view, self.ori_view = views(self.preset, self.categories)
        self.device = device
        self._cache: dict = {}

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
        key = (id(room.boxes), len(room.object_ids), category, tuple((a.node, a.direction, a.distance) for a in anchors))
        if key not in self._cache:
            self._cache = {key: self._density(room, walls, category, anchors, points)}
        return self._cache[key]

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
