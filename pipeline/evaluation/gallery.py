"""The gallery of the evaluation: the first method's scenes (their PNG with the planned graph, from the method's scene
archive) above held-out real rooms drawn with their own final graphs, tiled into one image."""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from .. import tables
from ..placement.export import plan_figure
from ..placement.layout import walls_of
from ..placement.plan import plans_from_tables
from ..room import RoomInput
from .sets import RoomSet


def gallery(path: Path, gen: RoomSet, archive: Path, real: RoomSet, nodes: Path, edges: Path, count: int) -> None:
    """The first ``count`` placed generated scenes (top row) and held-out real rooms (bottom row), one PNG."""
    entries = tables.read_archive(archive)
    generated = [entries[f"{r.room_id}.png"] for r in gen.rooms[:count] if f"{r.room_id}.png" in entries]
    tables.write_image(path, tile([generated, _real_figures(real.rooms[:count], nodes, edges)]))


def _real_figures(rooms: list[RoomInput], nodes: Path, edges: Path) -> list[bytes]:
    """Each held-out room's top-down PNG with its final graph."""
    flt = [("room_id", "in", [r.room_id for r in rooms])]
    plans = {p.scene_id: p for p in plans_from_tables(tables.read(nodes, "final_nodes", filters=flt).to_pandas(),
                                                        tables.read(edges, "final_edges", filters=flt).to_pandas())}
    out = []
    for room in rooms:
        plan_edges = plans[room.room_id].edges if room.room_id in plans else []
        figure = plan_figure(room, walls_of(room), plan_edges, f"{room.room_id} (held-out real)")
        out.append(tables.figure_png(figure))
    return out


def tile(rows: list[list[bytes]]) -> np.ndarray:
    """PNG images tiled row by row on white, each in a cell of the largest one's size: (H, W, 4) floats in [0, 1]."""
    from matplotlib.image import imread

    images = [[imread(io.BytesIO(png), format="png") for png in row] for row in rows]
    flat = [im for row in images for im in row] or [np.ones((1, 1, 4))]
    cell_h, cell_w = max(im.shape[0] for im in flat), max(im.shape[1] for im in flat)
    cols = max(1, *(len(row) for row in images))
    out = np.ones((cell_h * max(len(images), 1), cell_w * cols, 4))
    for i, row in enumerate(images):
        for j, im in enumerate(row):
            rgba = im if im.shape[2] == 4 else np.concatenate([im, np.ones(im.shape[:2] + (1,))], axis=2)
            out[i * cell_h:i * cell_h + im.shape[0], j * cell_w:j * cell_w + im.shape[1]] = rgba
    return out
