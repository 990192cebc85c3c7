"""Filter stage, one job per shard: every room gets a report row (kept, or the rule that rejected it)."""
from __future__ import annotations

import logging

import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..filtering import filter_rooms
from ..geometry.raycast import intersector_class
from ..stage import Files

log = logging.getLogger("planit.filter")


def run(config: dict, inp: Files, out: Files) -> dict:
    """Write the shard's kept rooms (``rooms`` schema) and its filter report."""
    rooms, architecture, objects, models, counts = inp.rooms, inp.architecture, inp.objects, inp.models, inp.counts
    out_rooms, out_report = out.rooms, out.report
    room_df = tables.read(rooms, "rooms").to_pandas()
    obj_df = tables.read(objects, "objects").to_pandas()
    meshes, box_models = tables.read_meshes(models, obj_df["model_id"].dropna())
    cfg = {**config["filter"], "floor_contact": config["floor_contact"],
           "intersector": intersector_class(config["extract"]["backend"])}
    report = filter_rooms(room_df, tables.read(architecture, "architecture").to_pandas(), obj_df, cfg,
                          tables.read(counts, "category_counts").to_pandas(),
                          {k: v for k, v in meshes.items() if k not in box_models})
    kept = room_df[room_df["room_id"].isin(report.loc[report["status"] == "kept", "room_id"])]
    extra = {"config_hash": config_hash(config["filter"])}
    tables.write(out_report, "filter_report", pa.Table.from_pandas(report, preserve_index=False), extra)
    tables.write(out_rooms, "rooms", pa.Table.from_pandas(kept, preserve_index=False), extra)
    log.info("kept %d of %d rooms", len(kept), len(room_df))
    return {"rooms": len(room_df), "kept": len(kept)}
