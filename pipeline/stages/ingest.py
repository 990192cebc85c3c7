"""Ingest stage: a source -> canonical tables ``rooms``, ``architecture``, ``objects``, ``models``,
``ground_truth`` and an ``ingest_report``, under ``results/ingest/``."""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..corpus import procedural
from ..log import progress

log = logging.getLogger("planit.ingest")
OUTPUTS = ("rooms", "architecture", "objects", "models", "ground_truth", "ingest_report")


def ingest_procedural(config: dict) -> dict[str, pa.Table]:
    cfg = config["procedural"]
    seed = config["seed"]
    models, model_rows = procedural.build_models(cfg["variants_per_category"], seed)
    rooms, arch, objs, gt = [], [], [], []
    jobs = [(i, rt) for rt in procedural.ROOM_TYPES for i in range(cfg["rooms"].get(rt, 0))]
    for i, rt in progress(jobs, desc="procedural rooms"):
        r = procedural.generate_room(i, rt, seed, models, cfg["defect_rate"], cfg["l_shape_rate"])
        room, a, o, g = procedural.room_tables(r)
        rooms.append(room)
        arch += a
        objs += o
        gt += g
    used = {o["model_id"] for o in objs}
    model_rows = [m for m in model_rows if m["model_id"] in used]
    per_type = Counter(r["room_type"] for r in rooms)
    cats = Counter(o["category"] for o in objs)
    report = [{"source": "procedural", "item": rt, "kind": "room", "status": "read", "reason": None, "count": n}
              for rt, n in sorted(per_type.items())]
    report += [{"source": "procedural", "item": c, "kind": "category", "status": "found", "reason": None, "count": n}
               for c, n in sorted(cats.items())]
    report.append({"source": "procedural", "item": "models", "kind": "model", "status": "kept", "reason": None,
                   "count": len(model_rows)})
    return {"rooms": tables.from_rows("rooms", rooms), "architecture": tables.from_rows("architecture", arch),
            "objects": tables.from_rows("objects", objs), "models": tables.from_rows("models", model_rows),
            "ground_truth": tables.from_rows("ground_truth", gt), "ingest_report": tables.from_rows("ingest_report", report)}


SOURCES = {"procedural": ingest_procedural}


def run(config: dict, out_dir: str | Path) -> dict[str, int]:
    """Ingest ``config['source']`` and write every canonical table; returns row counts."""
    source = config["source"]
    if source not in SOURCES:
        raise NotImplementedError(f"source '{source}' is not implemented in this version; available: {sorted(SOURCES)}")
    result = SOURCES[source](config)
    out_dir = Path(out_dir)
    section = {"seed": config["seed"], "source": source, source: config.get(source)}
    for name in OUTPUTS:
        tables.write(out_dir / f"{name}.parquet", name, result[name],
                     extra={"source": source, "config_hash": config_hash(section)})
    counts = {name: result[name].num_rows for name in OUTPUTS}
    log.info("ingested %s: %s", source, counts)
    return counts
