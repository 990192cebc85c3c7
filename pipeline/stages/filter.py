"""Filter stage: every room gets a report row (kept, or the rule that rejected it); kept rooms get a shard."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import pyarrow as pa

from .. import tables
from ..config import config_hash
from ..filtering import filter_rooms, rule_counts

log = logging.getLogger("planit.filter")


def run(config: dict, ingest_dir: str | Path, out_dir: str | Path) -> pd.DataFrame:
    """Filter the ingested rooms; write ``rooms.parquet`` (kept, with shard), ``report.parquet`` and ``rule_counts.tsv``."""
    ingest_dir, out_dir = Path(ingest_dir), Path(out_dir)
    rooms = tables.read(ingest_dir / "rooms.parquet", "rooms").to_pandas()
    arch = tables.read(ingest_dir / "architecture.parquet", "architecture").to_pandas()
    objects = tables.read(ingest_dir / "objects.parquet", "objects").to_pandas()
    cfg, shards = config["filter"], config["shards"]
    report = filter_rooms(rooms, arch, objects, cfg, shards)
    kept = rooms.drop(columns="shard").merge(report.loc[report["status"] == "kept", ["room_id", "shard"]], on="room_id")
    extra = {"config_hash": config_hash({"filter": cfg, "shards": shards}), "shards": str(shards)}
    tables.write(out_dir / "report.parquet", "filter_report", pa.Table.from_pandas(report, preserve_index=False), extra)
    tables.write(out_dir / "rooms.parquet", "rooms", pa.Table.from_pandas(kept, preserve_index=False), extra)
    counts = rule_counts(report)
    tables.write_tsv(out_dir / "rule_counts.tsv", counts)
    log.info("kept %d of %d rooms", len(kept), len(rooms))
    for row in counts.itertuples(index=False):
        log.info("  %-9s %-18s %6d", row.room_type, row.outcome, row.rooms)
    return report
