"""Score stage: extracted raw graphs vs the source's ground truth, written to a metrics JSON each run."""
from __future__ import annotations

import json
import logging
from pathlib import Path

import pandas as pd
import pyarrow.compute as pc
import pyarrow as pa

from .. import tables
from ..scoring import adjacency_scores, support_scores

log = logging.getLogger("planit.score")


def read_shards(folder: Path, name: str) -> pd.DataFrame:
    """Concatenate every ``<name>-<shard>.parquet`` of a folder."""
    files = sorted(folder.glob(f"{name}-*.parquet"))
    if not files:
        raise FileNotFoundError(f"{folder}: no {name}-<shard>.parquet files")
    return pa.concat_tables([tables.read(f, name) for f in files]).to_pandas()


def run(config: dict, ingest_dir: str | Path, raw_dir: str | Path, out: str | Path) -> dict:
    nodes = read_shards(Path(raw_dir), "nodes")
    edges = read_shards(Path(raw_dir), "edges")
    gt = tables.read(Path(ingest_dir) / "ground_truth.parquet", "ground_truth")
    gt = gt.filter(pc.is_in(gt["room_id"], value_set=pa.array(nodes["room_id"].unique().tolist(), pa.string()))).to_pandas()
    metrics = {"source": config["source"], "rooms": int(nodes["room_id"].nunique()), **support_scores(nodes, gt),
               **adjacency_scores(edges, gt)}
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.name}.tmp")
    tmp.write_text(json.dumps(metrics, indent=2))
    tmp.replace(out)
    log.info("extraction scores: %s", metrics)
    return metrics
