"""Score the refined graphs' hubs and chains against the corpus's ground truth."""
from __future__ import annotations

import logging

from .. import tables
from ..scoring import superstructure_scores
from ..stage import Files

log = logging.getLogger("planit.score")


def run(config: dict, inp: Files, out: Files) -> dict:
    nodes, superstructures, ground_truth = inp.nodes, inp.superstructures, inp.ground_truth
    rooms = set(tables.read(nodes, "final_nodes", columns=["room_id"]).column("room_id").to_pylist())
    gt = tables.read_many(ground_truth, "ground_truth", filters=[("relation", "in", ["hub", "chain"])]).to_pandas()
    metrics = {"rooms": len(rooms), **superstructure_scores(
        tables.read(superstructures, "superstructures").to_pandas(), gt[gt["room_id"].isin(rooms)])}
    tables.write_json(out.metrics, metrics)
    log.info("scores: %s", metrics)
    return metrics
