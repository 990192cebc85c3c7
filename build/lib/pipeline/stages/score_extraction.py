"""Score extracted raw graphs against the corpus's ground truth (support parents, intended adjacencies)."""
from __future__ import annotations

import logging
from pathlib import Path

from .. import tables
from ..scoring import adjacency_scores, support_scores

log = logging.getLogger("planit.score")


def run(nodes: list[Path], edges: list[Path], ground_truth: list[Path], out: Path) -> dict:
    node_df = tables.read_many(nodes, "nodes").to_pandas()
    gt = tables.read_many(ground_truth, "ground_truth").to_pandas()
    gt = gt[gt["room_id"].isin(set(node_df["room_id"]))]
    metrics = {"rooms": int(node_df["room_id"].nunique()), **support_scores(node_df, gt),
               **adjacency_scores(tables.read_many(edges, "edges").to_pandas(), gt)}
    tables.write_json(out, metrics)
    log.info("scores: %s", metrics)
    return metrics
