"""PlanIT's Table 3 of one room type: one row per instantiation variant's summary (CSV, and HTML for the report)."""
from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from .. import tables
from ..errors import InputError
from ..html import write_table_html
from ..stage import Files

TABLE3_COLUMNS = ["variant", "scenes", "placed", "failed", "rejections_per_scene", "backtracks_per_insertion", "violation",
                  "consistency", "collision_rate", "median_seconds", "unplanned_adjacent_per_scene"]


def run(config: dict, inp: Files, out: Files) -> pd.DataFrame:
    """One row per variant's summary.json (PlanIT's Table 3 and our consistency), written as CSV and HTML."""
    rows = []
    for p in inp.summaries:
        try:
            rows.append(json.loads(Path(p).read_text()))
        except (OSError, json.JSONDecodeError) as exc:
            raise InputError(f"{p}: not a readable instantiation summary ({exc}); rerun snakemake --forcerun instantiate") from exc
    frame = pd.DataFrame(rows).reindex(columns=["room_type", *TABLE3_COLUMNS])
    tables.write_csv(out.table, frame)
    room_type = ", ".join(frame["room_type"].dropna().astype(str).unique())
    write_table_html(out.table_html, frame, f"Table 3: {room_type}",
                     f"Held-out rooms' own graphs placed by the full method and each ablation. The same rows are in "
                     f"{out.table.name}.")
    return frame
