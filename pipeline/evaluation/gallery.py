"""The gallery of the evaluation: the first method's scenes (their PNG with the planned graph, and GLB) and held-out
real rooms drawn with their own final graphs, in one folder."""
from __future__ import annotations

import shutil
from pathlib import Path

from .. import tables
from ..placement.export import plan_figure
from ..placement.layout import walls_of
from ..placement.plan import plans_from_tables
from .sets import RoomSet


def gallery(folder: Path, gen: RoomSet, gen_folder: Path, real: RoomSet, nodes: Path, edges: Path, count: int) -> None:
    """The first ``count`` placed generated scenes (their instantiation PNG with the planned graph, and GLB) and
    held-out real rooms drawn with their own final graphs, into one folder (written whole, then renamed)."""
    tmp = folder.with_name(folder.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    for room in gen.rooms[:count]:
        for ext in ("png", "glb"):
            src = gen_folder / f"{room.room_id}.{ext}"
            if src.exists():
                shutil.copyfile(src, tmp / f"generated_{room.room_id}.{ext}")
    picked = real.rooms[:count]
    flt = [("room_id", "in", [r.room_id for r in picked])]
    plans = {p.scene_id: p for p in plans_from_tables(tables.read(nodes, "final_nodes", filters=flt).to_pandas(),
                                                        tables.read(edges, "final_edges", filters=flt).to_pandas())}
    for room in picked:
        plan_edges = plans[room.room_id].edges if room.room_id in plans else []
        tables.write_figure(tmp / f"real_{room.room_id}.png",
                            plan_figure(room, walls_of(room), plan_edges, f"{room.room_id} (held-out real)"))
    shutil.rmtree(folder, ignore_errors=True)
    tmp.rename(folder)
