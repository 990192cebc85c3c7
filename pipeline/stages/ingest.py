"""Ingest, one job per shard: the configured source's rooms of that shard as canonical tables (rooms,
architecture, objects, models, ground truth), its ingest report and the drops (corpus/ingest.py)."""
from __future__ import annotations

import logging
from collections import Counter

from .. import tables
from ..config import config_hash
from ..corpus.ingest import OUTPUTS, ingest_shard
from ..stage import Files

log = logging.getLogger("planit.ingest")


def run(config: dict, inp: Files, out: Files, shard: int) -> dict[str, int]:
    """Ingest shard ``shard`` of ``config['source']`` and write every table of ``OUTPUTS`` to ``out``."""
    result = ingest_shard(config, shard)
    extra = {"source": config["source"], "config_hash": config_hash(config), "shard": str(shard)}
    for name in OUTPUTS:
        tables.write(out[name], name, result[name], extra)
    counts = {name: result[name].num_rows for name in OUTPUTS}
    log.info("ingested %s shard %d: %s", config["source"], shard, counts)
    for reason, n in Counter(d["reason"] for d in result["drops"].to_pylist()).most_common(5):
        print(f"  shard {shard}: dropped {n} x {reason}", flush=True)
    for row in result["ingest_report"].to_pylist():
        log.info("  %-8s %-9s %6d  %s", row["kind"], row["status"], row["count"], row["reason"] or row["item"])
    return counts
