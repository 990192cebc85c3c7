"""The one way the pipeline opens DuckDB (statistics, the graph report, `planit stats`).

DuckDB sums floating-point values in whatever order its threads finish, so ``avg`` over DOUBLE columns can
differ in the last bits between a 2-core laptop and a 1-CPU cluster job. Outputs must be identical however
a stage is scheduled, so every float mean goes through the ``stable_avg`` macro, which sums in value order
(ties are equal values, so the order is fully determined). Integer aggregates are exact and need nothing.
"""
from __future__ import annotations

import duckdb

# DuckDB takes 80% of the machine's memory by default; a pipeline job stays under 1 GB (profiles/ ask for
# that), so joins and aggregations spill to disk beyond this instead of growing with the corpus.
MEMORY_LIMIT = "512MB"


def connect(threads: int | None = None) -> duckdb.DuckDBPyConnection:
    """An in-memory connection with the ``stable_avg(x)`` macro; ``threads`` overrides DuckDB's default."""
    con = duckdb.connect(config={"memory_limit": MEMORY_LIMIT})
    if threads is not None:
        con.execute(f"SET threads TO {int(threads)}")
    con.execute("CREATE MACRO stable_avg(x) AS avg(x ORDER BY x)")
    return con
