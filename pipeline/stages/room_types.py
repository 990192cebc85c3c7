"""Which room types the learners, the methods and the evaluation run for: every candidate type
(``config.candidate_room_types``) whose final graphs are enough to split into fit, validation and held-out rooms;
the others are skipped, each with its reason (in the log, the table and the report)."""
from __future__ import annotations

import logging

import pandas as pd

from .. import tables
from ..config import candidate_room_types
from ..html import write_table_html
from ..stage import Files

log = logging.getLogger("planit.room_types")
MIN_GRAPHS = 3  # fit, validation and held-out need one room each


def run(config: dict, inp: Files, out: Files) -> pd.DataFrame:
    rows = tables.read(inp.nodes, "final_nodes", columns=["room_id", "room_type"]).to_pandas()
    counts = rows.drop_duplicates("room_id")["room_type"].astype(str).value_counts()
    out_rows = []
    for room_type in candidate_room_types(config):
        n = int(counts.get(room_type, 0))
        reason = None if n >= MIN_GRAPHS else (
            "no room of this type passed the filter" if n == 0 else f"{n} room(s); training needs {MIN_GRAPHS}")
        if reason:
            log.warning("room type %s skipped: %s", room_type, reason)
        out_rows.append({"room_type": room_type, "graphs": n, "status": "skipped" if reason else "learned",
                         "reason": reason or ""})
    frame = pd.DataFrame(out_rows, columns=["room_type", "graphs", "status", "reason"])
    tables.write_csv(out.table, frame)
    write_table_html(out.table_html, frame, "Room types learned and skipped",
                     f"Every candidate room type with its final graphs; one with fewer than {MIN_GRAPHS} is skipped "
                     f"with its reason. The same rows are in {out.table.name}.")
    return frame
