"""Extraction stage: one shard of filtered rooms -> raw relation-graph tables ``nodes-<shard>`` / ``edges-<shard>``."""
from __future__ import annotations

import logging
import time
from pathlib import Path

import pyarrow.compute as pc
import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..extraction import extract_room
from ..roomdata import room_inputs
from ..geometry.raycast import intersector_class
from ..log import progress
from .symmetry import model_mesh

log = logging.getLogger("planit.extract")


def load_shard(ingest_dir: Path, filter_dir: Path, shard: int):
    """Kept rooms of one shard and their architecture, objects and models (as pandas frames / dicts)."""
    rooms = tables.read(filter_dir / "rooms.parquet", "rooms", filters=[("shard", "=", shard)]).to_pandas()
    ids = pa.array(rooms["room_id"].tolist(), pa.string())
    arch = tables.read(ingest_dir / "architecture.parquet", "architecture")
    arch = arch.filter(pc.is_in(arch["room_id"], value_set=ids)).to_pandas()
    objs = tables.read(ingest_dir / "objects.parquet", "objects")
    objs = objs.filter(pc.is_in(objs["room_id"], value_set=ids)).to_pandas()
    model_ids = pa.array(sorted(set(objs["model_id"].dropna())), pa.string())
    models = tables.read(ingest_dir / "models.parquet", "models")
    models = {m["model_id"]: model_mesh(m) for m in models.filter(pc.is_in(models["model_id"], value_set=model_ids)).to_pylist()}
    return rooms, arch, objs, models


def run(config: dict, shard: int, ingest_dir: str | Path, filter_dir: str | Path, out_dir: str | Path,
        symmetry_path: str | Path | None = None) -> dict:
    cfg = config["extract"]
    ingest_dir, filter_dir, out_dir = Path(ingest_dir), Path(filter_dir), Path(out_dir)
    symmetry_path = Path(symmetry_path) if symmetry_path else Path("results/symmetry/symmetry.parquet")
    intersector = intersector_class(cfg["backend"])
    rooms, arch, objs, models = load_shard(ingest_dir, filter_dir, shard)
    sym_rows = tables.read(symmetry_path, "symmetry").to_pylist()
    by_model = {r["model_id"]: (r["symmetry"], r["origin"]) for r in sym_rows}
    table = cfg["symmetry"]["table"]

    def symmetry_of(category: str, model_id: str) -> tuple[str, str]:
        if category in table:
            return table[category], "table"
        return by_model.get(model_id, ("none", "default"))

    nodes, edges, skipped = [], [], []
    rays, cycles = 0, 0
    start = time.perf_counter()
    for room in progress(room_inputs(rooms, arch, objs), total=len(rooms), desc=f"extract shard {shard}"):
        try:
            g = extract_room(room, models.get, symmetry_of, cfg, intersector)
        except ValueError as exc:
            log.warning("room %s skipped: %s", room.room_id, exc)
            skipped.append({"room_id": room.room_id, "node_id": None, "reason": str(exc)})
            continue
        for node_id, reason in g.skipped:
            log.warning("room %s: %s skipped: %s", room.room_id, node_id, reason)
            skipped.append({"room_id": room.room_id, "node_id": node_id, "reason": reason})
        rays += g.rays
        cycles += g.support_cycles
        for row in g.nodes:
            row.update(room_type=room.room_type, shard=shard)
        for row in g.edges:
            row.update(room_type=room.room_type, shard=shard)
        nodes += g.nodes
        edges += g.edges
    seconds = time.perf_counter() - start
    extra = {"config_hash": config_hash(cfg), "shard": str(shard)}
    tables.write(out_dir / f"nodes-{shard}.parquet", "nodes", tables.from_rows("nodes", nodes), extra)
    tables.write(out_dir / f"edges-{shard}.parquet", "edges", tables.from_rows("edges", edges), extra)
    summary = {"shard": shard, "rooms": len(rooms), "nodes": len(nodes), "edges": len(edges), "rays": rays,
               "support_cycles": cycles, "seconds": round(seconds, 3), "skipped": skipped, "backend": cfg["backend"]}
    tables.write_json(out_dir / f"summary-{shard}.json", summary)
    return {k: v for k, v in summary.items() if k != "skipped"} | {"skipped": len(skipped)}
