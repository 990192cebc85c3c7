"""Symmetry stage: one functional symmetry type per model (config table first, else detected from the mesh)."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from .. import tables
from ..config import config_hash
from ..geometry import symmetry
from ..log import progress

log = logging.getLogger("planit.symmetry")


def model_mesh(row: dict) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3), faces (m, 3)) of a ``models`` table row."""
    v = np.asarray(row["vertices"] if row["vertices"] is not None else [], dtype=float).reshape(-1, 3)
    f = np.asarray(row["faces"] if row["faces"] is not None else [], dtype=np.int64).reshape(-1, 3)
    return v, f


def run(config: dict, ingest_dir: str | Path, out_dir: str | Path) -> dict:
    """Write ``symmetry.parquet`` and ``agreement.json`` (how often detection agrees with the table)."""
    cfg = config["extract"]["symmetry"]
    models = tables.read(Path(ingest_dir) / "models.parquet", "models").to_pylist()
    rows = []
    for m in progress(models, desc="symmetry"):
        table_value = cfg["table"].get(m["category"])
        detected = None
        if cfg["detect"]:
            v, f = model_mesh(m)
            detected = symmetry.detect(v, f, cfg["tolerance"], cfg["samples"], seed=config["seed"])
        final = table_value or detected or "none"
        origin = "table" if table_value else ("detected" if detected else "default")
        rows.append({"model_id": m["model_id"], "category": m["category"], "detected": detected, "table": table_value,
                     "symmetry": final, "origin": origin})
    both = [r for r in rows if r["detected"] and r["table"]]
    agree = sum(r["detected"] == r["table"] for r in both)
    summary = {"models": len(rows), "with_table_entry": sum(r["table"] is not None for r in rows),
               "detected_only": sum(r["origin"] == "detected" for r in rows), "compared": len(both),
               "agree": agree, "agreement": round(agree / len(both), 4) if both else None,
               "disagreements": sorted({f"{r['category']}: table {r['table']} / detected {r['detected']}"
                                        for r in both if r["detected"] != r["table"]})}
    out_dir = Path(out_dir)
    tables.write(out_dir / "symmetry.parquet", "symmetry", tables.from_rows("symmetry", rows),
                 {"config_hash": config_hash(cfg)})
    tables.write_json(out_dir / "agreement.json", summary)
    log.info("symmetry: %d models, detection agrees with the table on %s of %d", len(rows), summary["agreement"], len(both))
    return summary
