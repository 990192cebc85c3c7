"""Dataset-wide statistics over the raw graphs, computed with DuckDB (gather step before refinement)."""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import pandas as pd

from .. import duck

from .refine import node_index
from .superstructures import find_chains, hub_candidates


def _files(paths: list[Path]) -> str:
    return "[" + ", ".join(f"'{p.as_posix()}'" for p in paths) + "]"


def relation_statistics(node_files: list[Path], edge_files: list[Path],
                        threads: int | None = None) -> dict[str, pd.DataFrame]:
    """Co-occurrence, relationship frequencies and category sizes per room type (identical for any
    ``threads``)."""
    con = duck.connect(threads)
    con.execute(f"CREATE VIEW nodes AS SELECT * FROM read_parquet({_files(node_files)})")
    con.execute(f"CREATE VIEW edges AS SELECT * FROM read_parquet({_files(edge_files)})")
    con.execute("""
        CREATE TABLE occ AS
        SELECT room_id, CAST(room_type AS VARCHAR) room_type, CAST(category AS VARCHAR) category, count(*) k
        FROM nodes WHERE kind = 'object' GROUP BY ALL""")
    cooccurrence = con.execute("""
        SELECT x.room_type, x.category cat_a, y.category cat_b, count(*) rooms
        FROM occ x JOIN occ y ON x.room_id = y.room_id AND (x.category <> y.category OR x.k >= 2)
        GROUP BY ALL ORDER BY ALL""").df()
    relations = con.execute("""
        WITH rel AS (
          SELECT CAST(e.room_type AS VARCHAR) room_type, CAST(a.category AS VARCHAR) cat_a,
                 CAST(b.category AS VARCHAR) cat_b, CAST(e.direction AS VARCHAR) direction,
                 CAST(e.distance AS VARCHAR) distance, count(DISTINCT e.room_id) rooms
          FROM edges e
          JOIN nodes a ON a.room_id = e.room_id AND a.node_id = e.source
          JOIN nodes b ON b.room_id = e.room_id AND b.node_id = e.target
          WHERE e.edge_type = 'spatial' AND a.kind = 'object' AND b.kind = 'object'
          GROUP BY ALL),
        co AS (
          SELECT x.room_type, x.category cat_a, y.category cat_b, count(*) cooccur_rooms
          FROM occ x JOIN occ y ON x.room_id = y.room_id AND (x.category <> y.category OR x.k >= 2)
          GROUP BY ALL)
        SELECT rel.*, co.cooccur_rooms, rel.rooms / co.cooccur_rooms AS freq
        FROM rel JOIN co USING (room_type, cat_a, cat_b) ORDER BY ALL""").df()
    sizes = con.execute("""
        SELECT CAST(room_type AS VARCHAR) room_type, CAST(category AS VARCHAR) category, count(*) instances,
               stable_avg(4 * hx * hy) mean_area, stable_avg(2 * sqrt(hx * hx + hy * hy)) mean_diag
        FROM nodes WHERE kind = 'object' GROUP BY ALL ORDER BY ALL""").df()
    return {"cooccurrence": cooccurrence, "relations": relations, "category_sizes": sizes}


def hub_pattern_counts(rooms: list[tuple[list[dict], list[dict]]], cfg: dict) -> pd.DataFrame:
    """How often each (room type, hub category, spoke category) candidate arrangement occurs, and whether it
    passes ``hub_min_pattern_count``. ``rooms`` holds (nodes, edges) per room."""
    counts: Counter = Counter()
    for nodes, edges in rooms:
        if not nodes:
            continue
        idx = node_index(nodes)
        spatial = [e for e in edges if e["edge_type"] == "spatial"]
        chain_of = {m: k for k, c in enumerate(find_chains(idx, spatial, cfg)) for m in c.members}
        for h in hub_candidates(idx, spatial, cfg, chain_of):
            counts[(nodes[0]["room_type"], idx[h.hub]["category"], idx[h.spokes[0]]["category"])] += 1
    rows = [{"room_type": rt, "hub_category": hc, "spoke_category": sc, "count": n,
             "accepted": n >= cfg["hub_min_pattern_count"]} for (rt, hc, sc), n in sorted(counts.items())]
    return pd.DataFrame(rows, columns=["room_type", "hub_category", "spoke_category", "count", "accepted"])
