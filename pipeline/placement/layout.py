"""A room being furnished: its architecture (a :class:`~pipeline.extraction.RoomInput`) and the objects placed so
far, and the top-down views of it that the placement networks read (in any plan frame)."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..geometry import raster
from ..geometry.frames import Frame, boxes_to_local, to_local
from ..room import RoomInput, Walls, merge_walls


@dataclass(frozen=True)
class View:
    """How a view is rendered: ``size`` pixels square at ``mpp`` metres per pixel; ``categories`` names the
    per-category channels."""
    size: int
    mpp: float
    categories: tuple[str, ...]

    @property
    def channels(self) -> int:
        return len(raster.CHANNELS) + len(self.categories)

    def pixel(self, local: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Rows, cols of frame points ``(n, 2)`` and whether they fall in the view."""
        col = np.floor(local[:, 0] / self.mpp + self.size / 2).astype(int)
        row = np.floor(self.size / 2 - local[:, 1] / self.mpp).astype(int)
        ok = (row >= 0) & (row < self.size) & (col >= 0) & (col < self.size)
        return row, col, ok

    def centres(self) -> np.ndarray:
        """``(size, size, 2)`` frame coordinates of the pixel centres."""
        xs, ys = raster.pixel_centres(self.size, self.mpp, (0.0, 0.0))
        return np.stack(np.meshgrid(xs, ys), -1)


def wall_frame(walls: Walls, w: int) -> Frame:
    """A wall's frame: origin mid-wall on its inner face, +y into the room."""
    mid = (walls.a[w] + walls.b[w]) / 2
    n = walls.normal[w]
    return Frame((float(mid[0]), float(mid[1])), math.atan2(n[1], n[0]) - math.pi / 2)


def box_frame(box: np.ndarray) -> Frame:
    return Frame((float(box[0]), float(box[1])), float(box[6]))


def walls_of(room: RoomInput) -> Walls:
    return merge_walls(room.wall_segments, room.wall_ids, room.wall_thickness, room.height)


def with_objects(room: RoomInput, keep) -> RoomInput:
    """The room holding only the objects ``keep`` (indices or a bool mask)."""
    idx = np.flatnonzero(keep) if np.asarray(keep).dtype == bool else np.asarray(keep, int)
    return replace(room, object_ids=[room.object_ids[k] for k in idx], categories=[room.categories[k] for k in idx],
                   model_ids=[room.model_ids[k] for k in idx], boxes=room.boxes[idx].reshape(-1, 7),
                   poses=room.poses[idx].reshape(-1, 7))


def add_object(room: RoomInput, object_id: str, category: str, model_id: str, box: np.ndarray, pose: np.ndarray) -> RoomInput:
    return replace(room, object_ids=room.object_ids + [object_id], categories=room.categories + [category],
                   model_ids=room.model_ids + [model_id], boxes=np.vstack([room.boxes.reshape(-1, 7), box]),
                   poses=np.vstack([room.poses.reshape(-1, 7), pose]))


def render(room: RoomInput, walls: Walls, view: View, frame: Frame, anchor: int | None = None,
           anchor_wall: int | None = None) -> np.ndarray:
    """``(view.channels, size, size)`` float32 view of the room in ``frame``; the anchor channel holds object
    ``anchor``'s footprint or wall ``anchor_wall``'s slab."""
    centre_line = np.stack([walls.a, walls.b], 1) - (walls.normal * walls.thickness[:, None] / 2)[:, None, :]
    segs = to_local(frame, centre_line)
    openings = {}
    for kind in ("door", "window"):
        o = [[(e["x0"], e["y0"]), (e["x1"], e["y1"])] for e in room.openings if e["kind"] == kind]
        openings[kind + "s"] = to_local(frame, np.asarray(o, float).reshape(-1, 2, 2))
    index = {c: k for k, c in enumerate(view.categories)}
    cats = np.array([index.get(c, -1) for c in room.categories], int)
    known = cats >= 0
    b = boxes_to_local(frame, room.boxes)
    anchor_k = None if anchor is None else int(np.cumsum(known)[anchor] - 1) if known[anchor] else None
    shell = raster.Shell(to_local(frame, room.outline), segs, walls.thickness / 2, openings)
    image = raster.render_room(shell, b[known], cats[known], len(view.categories), raster.Canvas(view.size, view.mpp),
                               anchor_k)
    if anchor_wall is not None:
        raster.fill_quads(image[raster.CHANNELS.index("anchor")], raster.segment_quads(segs[anchor_wall:anchor_wall + 1],
                          walls.thickness[anchor_wall:anchor_wall + 1] / 2), 1.0, view.mpp, (0.0, 0.0))
    return image
