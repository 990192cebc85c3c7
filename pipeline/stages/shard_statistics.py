"""Statistics map step, one job per shard: partial counts and superstructure candidates of the shard's raw graphs."""
from __future__ import annotations

import logging

import pandas as pd
import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..graphs.statistics import PARTIAL_KEYS, candidates, shard_counts
from ..stage import Files

log = logging.getLogger("planit.graphs")


def run(config: dict, inp: Files, out: Files) -> dict:
    nodes, edges, out_counts, out_candidates = inp.nodes, inp.edges, out.counts, out.candidates
    cfg = config["refine"]
    node_rows, edge_rows = tables.records_by_room(nodes, "nodes"), tables.records_by_room(edges, "edges")
    rows, patterns = candidates(((n, edge_rows.get(r, [])) for r, n in node_rows.items()), cfg)
    hub_counts = pd.DataFrame([{"kind": "hub_pattern", "room_type": rt, "cat_a": h, "cat_b": s, "direction": None,
                                "distance": None, "count": n} for (rt, h, s), n in sorted(patterns.items())],
                              columns=PARTIAL_KEYS + ["count"])
    counts = pd.concat([shard_counts(nodes, edges), hub_counts], ignore_index=True)
    extra = {"config_hash": config_hash(cfg)}
    tables.write(out_counts, "partial_counts", pa.Table.from_pandas(counts, preserve_index=False), extra)
    tables.write(out_candidates, "superstructures", tables.from_rows("superstructures", rows), extra)
    summary = {"rooms": len(node_rows), "partial_counts": len(counts), "candidate_rows": len(rows)}
    log.info("shard statistics: %s", summary)
    return summary
