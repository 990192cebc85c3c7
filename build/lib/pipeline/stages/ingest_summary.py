"""Ingest summary (gather over ingest shards): the dataset-wide category counts the filter's rare-category rule
needs, and the ingest report summed over shards."""
from __future__ import annotations

import logging
from pathlib import Path


from .. import duck, tables
from ..errors import InputError

log = logging.getLogger("planit.ingest")


def run(rooms: list[Path], objects: list[Path], models: list[Path], reports: list[Path], out_counts: Path,
        out_report: Path) -> dict:
    """Write ``category_counts`` and the summed ``ingest_report`` (plus the distinct models over every shard); no
    room ingested at all is an error."""
    room_t = tables.read_many(rooms, "rooms", columns=["room_id", "room_type"])
    if room_t.num_rows == 0:
        raise InputError(f"no room was ingested from any of the {len(rooms)} shard(s): see the ingest reports "
                         f"({', '.join(map(str, reports))})")
    con = duck.connect()
    con.register("r", room_t)
    con.register("o", tables.read_many(objects, "objects", columns=["room_id", "category"]))
    con.register("rep", tables.read_many(reports, "ingest_report"))
    con.register("m", tables.read_many(models, "models", columns=["model_id", "source"]))
    counts = con.sql("""
        SELECT CAST(r.room_type AS VARCHAR) room_type, CAST(o.category AS VARCHAR) category,
               count(DISTINCT o.room_id) rooms
        FROM o JOIN r USING (room_id) GROUP BY ALL ORDER BY ALL""").to_arrow_table()
    report = con.sql("""
        SELECT CAST(source AS VARCHAR) source, item, CAST(kind AS VARCHAR) kind, CAST(status AS VARCHAR) status,
               reason, sum(count)::BIGINT count
        FROM rep GROUP BY ALL
        UNION ALL
        SELECT any_value(CAST(source AS VARCHAR)), 'models', 'model', 'kept', 'distinct models over every shard',
               count(DISTINCT model_id)
        FROM m HAVING count(*) > 0
        ORDER BY kind, status, item""").to_arrow_table()
    tables.write(out_counts, "category_counts", counts)
    tables.write(out_report, "ingest_report", report)
    summary = {"rooms": room_t.num_rows, "categories": counts.num_rows}
    log.info("ingest summary: %s", summary)
    return summary
