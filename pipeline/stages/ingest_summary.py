"""Ingest summary (gather over ingest shards): the dataset-wide category counts the filter's rare-category rule
needs, and the ingest report summed over shards."""
from __future__ import annotations

import logging
from collections import Counter
from pathlib import Path

import pyarrow as pa
import pyarrow.compute  # noqa: F401  (pa.compute)

from .. import duck, tables
from ..errors import InputError
from ..stage import Files

log = logging.getLogger("planit.ingest")


def run(config: dict, inp: Files, out: Files) -> dict:
    """Write ``category_counts``, the summed ``ingest_report`` (plus the distinct models over every shard) and every
    shard's ``drops`` in one table; print the top drop reasons. No room ingested at all is an error."""
    rooms, objects, models, reports, drops = inp.rooms, inp.objects, inp.models, inp.reports, inp.drops
    out_counts, out_report, out_drops = out.counts, out.report, out.drops
    room_t = tables.read_many(rooms, "rooms", columns=["room_id", "room_type"])
    if room_t.num_rows == 0:
        raise InputError(f"no room was ingested from any of the {len(rooms)} shard(s): see the ingest reports "
                         f"({', '.join(map(str, reports))})")
    con = duck.connect()
    con.register("r", room_t)
    con.register("o", tables.read_many(objects, "objects", columns=["room_id", "category"]))
    con.register("shard_rep", tables.read_many(reports, "ingest_report"))
    # a house uid read from more than one file: its rooms stay apart (room ids start with the file name); reported
    con.execute("""
        CREATE VIEW rep AS
        SELECT * FROM shard_rep WHERE NOT (kind = 'house' AND status = 'uid')
        UNION ALL
        SELECT any_value(source), item, 'house', 'duplicate uid',
               'the same house uid in ' || count(*) || ' files: ' || string_agg(reason, ', ' ORDER BY reason), count(*)
        FROM shard_rep WHERE kind = 'house' AND status = 'uid' GROUP BY item HAVING count(*) > 1""")
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
    drop_t = tables.read_many(drops, "drops")
    tables.write(out_counts, "category_counts", counts)
    tables.write(out_report, "ingest_report", report)
    tables.write(out_drops, "drops", drop_t)
    summary = {"rooms": room_t.num_rows, "categories": counts.num_rows, "dropped": drop_t.num_rows}
    _print_drops(drop_t, out_drops)
    for row in report.filter(pa.compute.equal(report["status"], "duplicate uid")).to_pylist():
        print(f"ingest: house {row['item']}: {row['reason']} (rooms kept apart by file name)", flush=True)
    log.info("ingest summary: %s", summary)
    return summary


def _print_drops(drops: pa.Table, path: Path, top: int = 5) -> None:
    """The console summary: how many of each level were dropped, the top reasons, and where the table is."""
    if not drops.num_rows:
        print("ingest: nothing dropped", flush=True)
        return
    rows = drops.select(["level", "reason"]).to_pylist()
    levels = Counter(r["level"] for r in rows)
    print(f"ingest: dropped {', '.join(f'{n} {lvl}(s)' for lvl, n in levels.most_common())}; every one, with its file, "
          f"ids and field, in {path} (planit stats {path})", flush=True)
    for (level, reason), n in Counter((r["level"], r["reason"]) for r in rows).most_common(top):
        print(f"  {n:6d} {level}: {reason}", flush=True)
