"""Extraction stage, one job per shard: a shard's kept rooms -> raw relation-graph tables (nodes, edges)."""
from __future__ import annotations

import logging
import time
from pathlib import Path

from .. import tables
from ..config import config_hash
from ..extraction import extract_room
from ..geometry.raycast import intersector_class
from ..log import progress
from ..room import room_inputs
from ..stage import Files

log = logging.getLogger("planit.extract")


def load_shard(rooms: Path, architecture: Path, objects: Path, models: Path):
    """A shard's rooms and only their architecture, objects and models: the room and model filters are pushed
    down into the Parquet reads, so rejected rooms and unused meshes are never loaded."""
    room_df = tables.read(rooms, "rooms").to_pandas()
    ids = room_df["room_id"].tolist()
    arch = tables.read(architecture, "architecture", filters=[("room_id", "in", ids)]).to_pandas()
    objs = tables.read(objects, "objects", filters=[("room_id", "in", ids)]).to_pandas()
    meshes, box_models = tables.read_meshes(models, objs["model_id"].dropna())
    return room_df, arch, objs, meshes, box_models


def run(config: dict, inp: Files, out: Files, shard: int) -> dict:
    rooms, architecture, objects, models, symmetry = inp.rooms, inp.architecture, inp.objects, inp.models, inp.symmetry
    out_nodes, out_edges, out_summary = out.nodes, out.edges, out.summary
    cfg = {**config["extract"], "floor_contact": config["floor_contact"]}
    intersector = intersector_class(cfg["backend"])
    room_df, arch, objs, meshes, box_models = load_shard(rooms, architecture, objects, models)
    sym = tables.read(symmetry, "symmetry", columns=["model_id", "symmetry", "origin"]).to_pylist()
    by_model = {r["model_id"]: (r["symmetry"], r["origin"]) for r in sym}
    nodes, edges, skipped = [], [], []
    rays = cycles = hanging = 0
    start = time.perf_counter()
    for room in progress(room_inputs(room_df, arch, objs), total=len(room_df), desc=f"extract shard {shard}"):
        try:
            g = extract_room(room, meshes.get, lambda c, m: by_model.get(m, ("none", "default")), cfg, intersector,
                             box_models)
        except ValueError as exc:
            log.warning("room %s skipped: %s", room.room_id, exc)
            skipped.append({"room_id": room.room_id, "node_id": None, "reason": str(exc)})
            continue
        for node_id, reason in g.skipped:
            log.warning("room %s: %s skipped: %s", room.room_id, node_id, reason)
            skipped.append({"room_id": room.room_id, "node_id": node_id, "reason": reason})
        rays += g.rays
        cycles += g.support_cycles
        hanging += g.hanging
        for row in g.nodes + g.edges:
            row.update(room_type=room.room_type, shard=shard)
        nodes += g.nodes
        edges += g.edges
    seconds = time.perf_counter() - start
    extra = {"config_hash": config_hash(cfg), "shard": str(shard)}
    tables.write(out_nodes, "nodes", tables.from_rows("nodes", nodes), extra)
    tables.write(out_edges, "edges", tables.from_rows("edges", edges), extra)
    summary = {"shard": shard, "rooms": len(room_df), "nodes": len(nodes), "edges": len(edges), "rays": rays,
               "support_cycles": cycles, "hanging": hanging, "seconds": round(seconds, 3), "skipped": skipped, "backend": cfg["backend"]}
    tables.write_json(out_summary, summary)
    return {k: v for k, v in summary.items() if k != "skipped"} | {"skipped": len(skipped)}
