"""Symmetry stage (gather per corpus): one functional symmetry type per model. This is the one place where the
rule "the config table's type for the category first, else the type detected from the mesh" is applied;
extraction reads the result."""
from __future__ import annotations

import logging
from pathlib import Path

from .. import tables
from ..config import config_hash
from ..geometry import symmetry
from ..log import progress
from ..stage import Files

log = logging.getLogger("planit.symmetry")


def _unique_models(paths: list[Path]) -> list[dict]:
    """Model rows of every shard, one per model id (shards of real corpora share models)."""
    seen, out = set(), []
    for row in tables.read_many(paths, "models").to_pylist():
        if row["model_id"] not in seen:
            seen.add(row["model_id"])
            out.append(row)
    return sorted(out, key=lambda r: r["model_id"])


def run(config: dict, inp: Files, out: Files) -> dict:
    """Write the ``symmetry`` table and ``agreement.json`` (how often detection agrees with the table)."""
    models, out_table, out_agreement = inp.models, out.table, out.agreement
    cfg = config["extract"]["symmetry"]
    rows = []
    for m in progress(_unique_models(models), desc="symmetry"):
        table_value = cfg["table"].get(m["category"])
        detected = None
        if cfg["detect"]:
            v, f = tables.model_mesh(m)
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
    tables.write(out_table, "symmetry", tables.from_rows("symmetry", rows), {"config_hash": config_hash(cfg)})
    tables.write_json(out_agreement, summary)
    log.info("symmetry: %d models, detection agrees with the table on %s of %d", len(rows), summary["agreement"], len(both))
    return summary
