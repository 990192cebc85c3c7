"""Filter report (gather): every shard's report in one table, and rooms per (room type, outcome)."""
from __future__ import annotations

import logging

import pandas as pd

from .. import tables
from ..filtering import rule_counts
from ..html import write_table_html
from ..stage import Files

log = logging.getLogger("planit.filter")


def run(config: dict, inp: Files, out: Files) -> pd.DataFrame:
    reports, out_report, out_counts = inp.reports, out.report, out.counts
    table = tables.read_many(reports, "filter_report")
    tables.write(out_report, "filter_report", table)
    counts = rule_counts(table.to_pandas())
    tables.write_tsv(out_counts, counts)
    write_table_html(out.counts_html, counts, "Filter: rooms per room type and outcome",
                     f"Rooms kept, or rejected by their first rejecting rule. The same rows are in {out_counts.name}.")
    for row in counts.itertuples(index=False):
        log.info("  %-9s %-18s %6d", row.room_type, row.outcome, row.rooms)
    return counts
