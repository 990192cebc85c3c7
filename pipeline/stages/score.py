"""Score stage: extracted raw graphs vs the source's ground truth, written to a metrics JSON each run."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import pyarrow.compute as pc
import pyarrow as pa

from .. import tables
from ..scoring import adjacency_scores, superstructure_scores, support_scores

log = logging.getLogger("planit.score")


def read_shards(folder: Path, name: str, shards: int) -> pd.DataFrame:
    """Concatenate ``<name>-<k>.parquet`` for every shard k."""
    from .graphs import shard_files

    return pa.concat_tables([tables.read(f, name) for f in shard_files(folder, name, shards)]).to_pandas()


def _ground_truth(ingest_dir: Path, room_ids) -> pd.DataFrame:
    gt = tables.read(Path(ingest_dir) / "ground_truth.parquet", "ground_truth")
    return gt.filter(pc.is_in(gt["room_id"], value_set=pa.array(list(room_ids), pa.string()))).to_pandas()


def run(config: dict, ingest_dir: str | Path, raw_dir: str | Path, out: str | Path) -> dict:
    nodes = read_shards(Path(raw_dir), "nodes", config["shards"])
    edges = read_shards(Path(raw_dir), "edges", config["shards"])
    gt = _ground_truth(ingest_dir, nodes["room_id"].unique())
    metrics = {"source": config["source"], "rooms": int(nodes["room_id"].nunique()), **support_scores(nodes, gt),
               **adjacency_scores(edges, gt)}
    return _write(metrics, out)


def run_superstructures(config: dict, ingest_dir: str | Path, graph_dir: str | Path, out: str | Path) -> dict:
    nodes = tables.read(Path(graph_dir) / "nodes.parquet", "final_nodes").to_pandas()
    supers = tables.read(Path(graph_dir) / "superstructures.parquet", "superstructures").to_pandas()
    gt = _ground_truth(ingest_dir, nodes["room_id"].unique())
    metrics = {"source": config["source"], "rooms": int(nodes["room_id"].nunique()), "pruning": config["refine"]["pruning"],
               **superstructure_scores(supers, gt)}
    return _write(metrics, out)


def _write(metrics: dict, out: str | Path) -> dict:
    tables.write_json(out, metrics)
    log.info("scores: %s", metrics)
    return metrics
