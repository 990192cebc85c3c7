"""Score extracted raw graphs against the corpus's ground truth (support parents, intended adjacencies)."""
from __future__ import annotations

import logging
from collections import Counter

from .. import tables
from ..scoring import extraction_counts, extraction_scores
from ..stage import Files

log = logging.getLogger("planit.score")


def run(config: dict, inp: Files, out: Files) -> dict:
    """Counts shard by shard (shard k's rooms, edges and ground truth), then the scores: memory does not grow
    with the corpus."""
    nodes, edges, ground_truth = inp.nodes, inp.edges, inp.ground_truth
    if not len(nodes) == len(edges) == len(ground_truth):
        raise tables.TableError(f"score: {len(nodes)} node, {len(edges)} edge and {len(ground_truth)} ground-truth "
                                "tables: one of each per shard")
    counts: Counter[str] = Counter()
    for n, e, g in zip(nodes, edges, ground_truth):
        node_df = tables.read(n, "nodes").to_pandas()
        ids = node_df["room_id"].unique().tolist()
        gt = tables.read(g, "ground_truth", filters=[("room_id", "in", ids)] if ids else None).to_pandas()
        counts += extraction_counts(node_df, tables.read(e, "edges").to_pandas(), gt[gt["room_id"].isin(ids)])
    metrics = extraction_scores(counts)
    tables.write_json(out.metrics, metrics)
    log.info("scores: %s", metrics)
    return metrics
