"""Inspection of final relation graphs (``planit stats graphs``): the paper's Table 1 per room type, edges
per node before and after pruning, pruning shares per rule, superstructure counts, frequent relations.
Aggregations run in DuckDB over the gathered Parquet tables."""
from __future__ import annotations

from pathlib import Path
from typing import TextIO

import duckdb
import pandas as pd
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from .. import duck, tables
from ..html import write_table_html

ARCH = "('wall_adjacent', 'wall_opposite', 'opening')"


def _con(nodes: Path, edges: Path, superstructures: Path) -> duckdb.DuckDBPyConnection:
    con = duck.connect()
    for name, path, schema in (("nodes", nodes, "final_nodes"), ("edges", edges, "final_edges"),
                               ("superstructures", superstructures, "superstructures")):
        tables.check(path, schema)
        con.execute(f"CREATE VIEW {name} AS SELECT * FROM read_parquet('{Path(path).as_posix()}')")
    return con


def graph_tables(folder: Path) -> tuple[Path, Path, Path]:
    """The gathered final graph tables of a corpus folder (``results/graphs/<corpus>``)."""
    nodes, edges, superstructures = (Path(folder) / f"{n}.parquet" for n in ("nodes", "edges", "superstructures"))
    return nodes, edges, superstructures


def graph_report(nodes: Path, edges: Path, superstructures: Path) -> dict[str, pd.DataFrame]:
    con = _con(nodes, edges, superstructures)
    table1 = con.execute("""
        WITH n AS (SELECT room_id, CAST(room_type AS VARCHAR) room_type, count(*) nodes,
                          count(*) FILTER (WHERE kind = 'object') non_wall_nodes FROM nodes GROUP BY ALL),
             e AS (SELECT e.room_id,
                          count(*) FILTER (WHERE status = 'kept') edges,
                          count(*) FILTER (WHERE status = 'kept' AND a.kind = 'object' AND b.kind = 'object') non_wall_edges,
                          count(*) FILTER (WHERE origin = 'raw') raw_edges
                   FROM edges e JOIN nodes a ON a.room_id = e.room_id AND a.node_id = e.source
                                JOIN nodes b ON b.room_id = e.room_id AND b.node_id = e.target GROUP BY ALL),
             s AS (SELECT room_id, count(DISTINCT group_id) FILTER (WHERE kind = 'hub') hubs,
                          count(DISTINCT group_id) FILTER (WHERE kind = 'chain') chains FROM superstructures GROUP BY ALL)
        SELECT room_type, count(*) rooms, avg(nodes) nodes, avg(non_wall_nodes) non_wall_nodes, avg(edges) edges,
               avg(non_wall_edges) non_wall_edges, stable_avg(raw_edges / nodes) edges_per_node_raw,
               stable_avg(edges / nodes) edges_per_node_final, sum(coalesce(hubs, 0)) hubs, sum(coalesce(chains, 0)) chains
        FROM n JOIN e USING (room_id) LEFT JOIN s USING (room_id) GROUP BY ALL ORDER BY room_type""").df()
    pruning = con.execute(f"""
        WITH c AS (SELECT CAST(room_type AS VARCHAR) room_type, CAST(rule AS VARCHAR) rule,
                          CAST(status AS VARCHAR) status, count(*) edges
                   FROM edges WHERE origin = 'raw' AND edge_type NOT IN {ARCH} GROUP BY 1, 2, 3)
        SELECT *, edges / sum(edges) OVER (PARTITION BY room_type) share_of_raw FROM c
        ORDER BY room_type, edges DESC, rule, status""").df()
    relations = con.execute("""
        WITH c AS (
          SELECT CAST(e.room_type AS VARCHAR) room_type, CAST(a.category AS VARCHAR) anchor,
                 CAST(e.edge_type AS VARCHAR) edge_type, coalesce(CAST(e.direction AS VARCHAR), '') direction,
                 coalesce(CAST(e.distance AS VARCHAR), '') distance, CAST(b.category AS VARCHAR) target, count(*) edges
          FROM edges e JOIN nodes a ON a.room_id = e.room_id AND a.node_id = e.source
                       JOIN nodes b ON b.room_id = e.room_id AND b.node_id = e.target
          WHERE e.status = 'kept' AND b.kind = 'object' GROUP BY 1, 2, 3, 4, 5, 6)
        SELECT * FROM c QUALIFY row_number() OVER (PARTITION BY room_type ORDER BY edges DESC, anchor, target, edge_type,
                                                   direction, distance) <= 10
        ORDER BY room_type, edges DESC, anchor, target, edge_type, direction, distance""").df()
    return {"table1": table1, "pruning": pruning, "relations": relations}


def print_report(report: dict[str, pd.DataFrame], stream: TextIO) -> None:
    console = Console(file=stream, width=160)
    for name, title in (("table1", "Per room type (paper Table 1 columns: averages per room)"),
                        ("pruning", "Raw object edges by deciding rule"), ("relations", "Most frequent kept relations")):
        df = report[name]
        t = Table(*df.columns, title=title)
        for row in df.itertuples(index=False):
            t.add_row(*[f"{v:.2f}" if isinstance(v, float) else str(v) for v in row])
        console.print(t)


HTML = {"table1": ("Table 1: relation graphs per room type", "Rooms, and per room the average nodes and edges "
                   "(kept; non_wall: between objects), edges per node before and after pruning, hubs and chains."),
        "pruning": ("Pruning by rule", "Raw object edges per room type and the refinement rule that kept or pruned "
                    "each; share_of_raw: their share of the room type's raw object edges.")}


def write_report(report: dict[str, pd.DataFrame], outputs: dict[str, Path]) -> list[Path]:
    """CSV per table (``outputs[name]``), an HTML page per table of ``HTML`` (``outputs[name + '_html']``, where
    given) and one PNG (``outputs['plot']``): edges per node before/after pruning and the pruning shares, per room
    type. Every file is written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    for name, df in report.items():
        tables.write_csv(outputs[name], df)
        if outputs.get(f"{name}_html") is not None:
            title, caption = HTML[name]
            write_table_html(outputs[f"{name}_html"], df, title, f"{caption} The same rows are in "
                                                                 f"{Path(outputs[name]).name}.")
    t1, pr = report["table1"], report["pruning"]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    x = range(len(t1))
    ax1.bar([i - 0.2 for i in x], t1["edges_per_node_raw"], width=0.4, label="raw")
    ax1.bar([i + 0.2 for i in x], t1["edges_per_node_final"], width=0.4, label="after pruning")
    ax1.set_xticks(list(x), t1["room_type"])
    ax1.set_ylabel("edges per node")
    ax1.set_ylim(0, 1.25 * max(t1["edges_per_node_raw"].max(), t1["edges_per_node_final"].max(), 1e-9))
    ax1.legend(loc="upper center", ncol=2)  # above the bars, in the headroom
    pivot = pr.pivot_table(index="room_type", columns="rule", values="share_of_raw", fill_value=0.0)
    pivot.plot(kind="bar", stacked=True, ax=ax2, legend=False, colormap="tab20")
    ax2.set_ylabel("share of raw object edges, by deciding rule")
    ax2.set_xlabel("")
    ax2.tick_params(axis="x", rotation=0)
    ax2.legend(fontsize=7, bbox_to_anchor=(1.0, 1.0), loc="upper left")
    fig.tight_layout()
    tables.write_figure(outputs["plot"], fig, dpi=110)
    return [Path(outputs[k]) for k in (*report, "plot", *(f"{n}_html" for n in HTML)) if outputs.get(k) is not None]


def print_room(graph_dir: Path, room_id: str, stream: TextIO) -> None:
    """One room's graph, readably: nodes, then kept and pruned edges with the deciding rule."""
    con = _con(*graph_tables(graph_dir))
    nodes = con.execute("SELECT * FROM nodes WHERE room_id = ? ORDER BY kind DESC, node_id", [room_id]).df()
    if nodes.empty:
        raise tables.TableError(f"room '{room_id}' is not in {graph_dir}/nodes.parquet")
    edges = con.execute("SELECT * FROM edges WHERE room_id = ? ORDER BY status, source, target", [room_id]).df()
    console = Console(file=stream, width=160)
    console.print(f"[bold]{room_id}[/bold] ({nodes['room_type'].iloc[0]}): {len(nodes)} nodes, "
                  f"{int((edges.status == 'kept').sum())} kept / {len(edges)} edges")
    cat = dict(zip(nodes.node_id, nodes.category.astype(str)))
    t = Table("node", "category", "symmetry", "tier", "parent", "role")
    for n in nodes.itertuples(index=False):
        parent = n.parent_id if isinstance(n.parent_id, str) else ""
        t.add_row(n.node_id, str(n.category), str(n.symmetry), str(n.tier), parent, str(n.role))
    console.print(t)
    for status in ("kept", "pruned"):
        console.print(f"[bold]{status} edges[/bold]")
        for e in edges[edges.status == status].itertuples(index=False):
            label = str(e.edge_type) if e.edge_type != "spatial" else f"{e.direction}/{e.distance}"
            why = f"[{e.rule}{', ' + e.origin if e.origin != 'raw' else ''}]"
            console.print(escape(f"  {e.source} ({cat.get(e.source)}) --{label}--> {e.target} ({cat.get(e.target)})  {why}"))
