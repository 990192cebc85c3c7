"""Readable summaries of pipeline tables (``planit stats``), computed with DuckDB."""
from __future__ import annotations

from pathlib import Path
from typing import TextIO

import pyarrow.parquet as pq
from rich.console import Console
from rich.table import Table

from . import duck, tables


def table_summary(path: str | Path, stream: TextIO) -> None:
    """Schema (with units), pipeline metadata, row count and DuckDB's per-column SUMMARIZE."""
    path = Path(path)
    if not path.is_file():
        raise tables.TableError(f"{path}: no such table file")
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # pyarrow raises several types for non-Parquet input
        raise tables.TableError(f"{path}: not a readable Parquet file: {exc}") from exc
    console = Console(file=stream, width=140)
    console.print(f"[bold]{path}[/bold]")
    for key, value in tables.metadata(path).items():
        console.print(f"  {key}: {value}")
    con = duck.connect()
    rows = con.execute("SELECT count(*) FROM read_parquet(?)", [str(path)]).fetchone()[0]
    console.print(f"  rows: {rows}")
    summary = {r[0]: r for r in con.execute("SUMMARIZE SELECT * FROM read_parquet(?)", [str(path)]).fetchall()}
    t = Table("column", "type", "unit", "min", "max", "distinct", "mean", "null %")
    for field in schema:
        meta = {k.decode(): v.decode() for k, v in (field.metadata or {}).items()}
        s = summary.get(field.name)
        cells = ["", "", "", "", ""] if s is None else [str(s[2])[:24], str(s[3])[:24], str(s[4]),
                                                        "" if s[5] is None else f"{float(s[5]):.4g}", str(s[11])]
        t.add_row(field.name, str(field.type), meta.get("unit", ""), *cells)
    console.print(t)
