"""Statistics gather (per corpus): every shard's partial counts summed with DuckDB, hub patterns accepted by
their dataset-wide count, category sizes over every raw node."""
from __future__ import annotations

import logging

import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..graphs.statistics import gather
from ..stage import Files

log = logging.getLogger("planit.graphs")
STAT_TABLES = ("cooccurrence", "relations", "hub_patterns", "category_sizes")


def run(config: dict, inp: Files, out: Files) -> dict:
    partials, nodes = inp.partial, inp.nodes
    for p in partials:  # a missing or corrupt shard is named here, not deep inside DuckDB
        tables.check(p, "partial_counts")
    for p in nodes:
        tables.check(p, "nodes")
    min_count = config["refine"]["hub_min_pattern_count"]
    stats = gather(partials, nodes, min_count)
    extra = {"config_hash": config_hash(min_count)}
    for name in STAT_TABLES:
        tables.write(out[name], name, pa.Table.from_pandas(stats[name], preserve_index=False), extra)
    summary = {name: len(stats[name]) for name in STAT_TABLES}
    summary["accepted_hub_patterns"] = int(stats["hub_patterns"]["accepted"].sum()) if len(stats["hub_patterns"]) else 0
    log.info("graph statistics: %s", summary)
    return summary
