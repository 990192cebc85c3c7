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


def _flat(value, prefix: str = "") -> list[tuple[str, object]]:
    if isinstance(value, dict):
        return [kv for k, v in value.items() for kv in _flat(v, f"{prefix}{k}.")]
    return [(prefix.rstrip("."), value)]


def print_metrics(path: str | Path, stream: TextIO) -> None:
    """Graph-generator metrics side by side: one column per room type and generator (``path``: a metrics JSON, a
    generator's folder, a room type's folder or the graph_model folder, ``results/graph_model/<type>/<generator>/``)."""
    import json

    path = Path(path)
    files = ([path] if path.suffix == ".json" else [path / "metrics.json"] if (path / "metrics.json").exists()
             else sorted(path.glob("*/metrics.json")) or sorted(path.glob("*/*/metrics.json")))
    if not files:
        raise tables.TableError(f"{path}: no metrics.json (written by rule graph_model_metrics)")
    columns = {}
    for f in files:
        name = f"{f.parent.parent.name}/{f.parent.name}" if f.name == "metrics.json" else f.stem
        try:
            columns[name] = dict(_flat(json.loads(f.read_text())))
        except (OSError, ValueError) as exc:
            raise tables.TableError(f"{f}: unreadable metrics ({exc})") from exc
    table = Table(title=f"graph model metrics ({path})")
    table.add_column("metric")
    for name in columns:
        table.add_column(name, justify="right")
    keys = list(dict.fromkeys(k for c in columns.values() for k in c))
    for k in keys:
        table.add_row(k, *(_show(c.get(k)) for c in columns.values()))
    Console(file=stream, width=200).print(table)


def _show(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return "" if v is None else str(v)
