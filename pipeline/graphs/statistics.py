"""Dataset-wide statistics over the raw graphs, as map-reduce: each shard emits its partial counts and its
superstructure candidates (:func:`shard_counts`, :func:`candidates`); the gather sums the counts with DuckDB
(:func:`gather`). Counts are integers, so the sums do not depend on how rooms are split into shards; float
means (category sizes) are taken over every node at once with the value-ordered ``stable_avg``."""
from __future__ import annotations

from collections import Counter
from pathlib import Path

import pandas as pd

from .. import duck
from .superstructures import Chain, Hub, node_index, room_candidates

PARTIAL_KEYS = ["kind", "room_type", "cat_a", "cat_b", "direction", "distance"]


def _files(paths: list[Path]) -> str:
    return "[" + ", ".join(f"'{Path(p).as_posix()}'" for p in paths) + "]"


_OCCURRENCES = """
    CREATE TABLE occ AS
    SELECT room_id, CAST(room_type AS VARCHAR) room_type, CAST(category AS VARCHAR) category, count(*) k
    FROM nodes WHERE kind = 'object' GROUP BY ALL"""


def shard_counts(node_file: Path, edge_file: Path) -> pd.DataFrame:
    """One shard's co-occurrence and relation room counts (``partial_counts`` rows)."""
    con = duck.connect()
    con.execute(f"CREATE VIEW nodes AS SELECT * FROM read_parquet('{Path(node_file).as_posix()}')")
    con.execute(f"CREATE VIEW edges AS SELECT * FROM read_parquet('{Path(edge_file).as_posix()}')")
    con.execute(_OCCURRENCES)
    return con.execute("""
        SELECT 'cooccurrence' kind, x.room_type, x.category cat_a, y.category cat_b, NULL direction, NULL distance,
               count(*) count
        FROM occ x JOIN occ y ON x.room_id = y.room_id AND (x.category <> y.category OR x.k >= 2)
        GROUP BY ALL
        UNION ALL
        SELECT 'relation' kind, CAST(e.room_type AS VARCHAR), CAST(a.category AS VARCHAR), CAST(b.category AS VARCHAR),
               CAST(e.direction AS VARCHAR), CAST(e.distance AS VARCHAR), count(DISTINCT e.room_id)
        FROM edges e
        JOIN nodes a ON a.room_id = e.room_id AND a.node_id = e.source
        JOIN nodes b ON b.room_id = e.room_id AND b.node_id = e.target
        WHERE e.edge_type = 'spatial' AND a.kind = 'object' AND b.kind = 'object'
        GROUP BY ALL ORDER BY ALL""").df()


def candidates(rooms, cfg: dict) -> tuple[list[dict], Counter]:
    """Chains and hub candidates of every room (``superstructures`` rows: group ``chain_<k>`` / ``hubc_<k>``) and
    the (room type, hub category, spoke category) counts of the candidates. ``rooms`` yields (nodes, edges)."""
    rows: list[dict] = []
    patterns: Counter = Counter()
    for nodes, edges in rooms:
        if not nodes:
            continue
        idx = node_index(nodes)
        room_id, room_type = nodes[0]["room_id"], nodes[0]["room_type"]
        chains, hubs = room_candidates(idx, edges, cfg)
        for h in hubs:
            patterns[(room_type, idx[h.hub]["category"], idx[h.spokes[0]]["category"])] += 1
        rows += [dict(r, room_id=room_id, room_type=room_type) for r in candidate_rows(chains, hubs)]
    return rows, patterns


def candidate_rows(chains: list[Chain], hubs: list[Hub]) -> list[dict]:
    rows = [{"group_id": f"chain_{k}", "kind": "chain", "anchor_id": c.members[0], "member_id": m, "position": p,
             "direction": c.direction, "label": c.label} for k, c in enumerate(chains) for p, m in enumerate(c.members)]
    rows += [{"group_id": f"hubc_{k}", "kind": "hub", "anchor_id": h.hub, "member_id": s, "position": None,
              "direction": h.directions[s], "label": None} for k, h in enumerate(hubs) for s in h.spokes]
    return rows


def parse_candidates(rows: list[dict]) -> tuple[list[Chain], list[Hub]]:
    """The chains and hub candidates of one room back from its :func:`candidate_rows`."""
    groups: dict[str, list[dict]] = {}
    for r in rows:
        groups.setdefault(r["group_id"], []).append(r)
    chains, hubs = [], []
    for gid in sorted(groups, key=lambda g: (g.split("_")[0], int(g.split("_")[1]))):
        g = groups[gid]
        if g[0]["kind"] == "chain":
            members = [r["member_id"] for r in sorted(g, key=lambda r: r["position"])]
            chains.append(Chain(members, g[0]["direction"], g[0]["label"]))
        else:
            directions = {r["member_id"]: r["direction"] for r in g}
            hubs.append(Hub(g[0]["anchor_id"], sorted(directions), directions))
    return chains, hubs


def gather(partial_files: list[Path], node_files: list[Path], min_pattern_count: int,
           threads: int | None = None) -> dict[str, pd.DataFrame]:
    """Co-occurrence, relation frequencies, hub patterns and category sizes per room type from every shard's
    partial counts and raw nodes (identical for any ``threads`` and any sharding)."""
    con = duck.connect(threads)
    con.execute(f"CREATE VIEW partial AS SELECT * FROM read_parquet({_files(partial_files)})")
    con.execute(f"CREATE VIEW nodes AS SELECT * FROM read_parquet({_files(node_files)})")
    con.execute("""
        CREATE TABLE total AS SELECT CAST(kind AS VARCHAR) kind, CAST(room_type AS VARCHAR) room_type, cat_a, cat_b,
               CAST(direction AS VARCHAR) direction, CAST(distance AS VARCHAR) distance, sum(count)::BIGINT n
        FROM partial GROUP BY ALL""")
    cooccurrence = con.execute("""
        SELECT room_type, cat_a, cat_b, n rooms FROM total WHERE kind = 'cooccurrence' ORDER BY ALL""").df()
    relations = con.execute("""
        SELECT r.room_type, r.cat_a, r.cat_b, r.direction, r.distance, r.n rooms, c.n cooccur_rooms,
               r.n / c.n AS freq
        FROM total r JOIN total c ON c.kind = 'cooccurrence' AND r.room_type = c.room_type AND r.cat_a = c.cat_a
                                     AND r.cat_b = c.cat_b
        WHERE r.kind = 'relation' ORDER BY ALL""").df()
    hubs = con.execute("""
        SELECT room_type, cat_a hub_category, cat_b spoke_category, n count, n >= ? accepted
        FROM total WHERE kind = 'hub_pattern' ORDER BY room_type, hub_category, spoke_category""",
                       [min_pattern_count]).df()
    sizes = con.execute("""
        SELECT CAST(room_type AS VARCHAR) room_type, CAST(category AS VARCHAR) category, count(*) instances,
               stable_avg(4 * hx * hy) mean_area, stable_avg(2 * sqrt(hx * hx + hy * hy)) mean_diag
        FROM nodes WHERE kind = 'object' GROUP BY ALL ORDER BY ALL""").df()
    return {"cooccurrence": cooccurrence, "relations": relations, "hub_patterns": hubs, "category_sizes": sizes}
