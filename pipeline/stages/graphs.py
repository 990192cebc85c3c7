"""Graph stages: dataset statistics (gather), per-shard refinement, gathered final tables, and scores."""
from __future__ import annotations

import logging
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from .. import tables
from ..config import config_hash
from ..graphs.refine import Stats, refine_room
from ..graphs.statistics import hub_pattern_counts, relation_statistics
from ..log import progress

log = logging.getLogger("planit.graphs")
STAT_TABLES = ("cooccurrence", "relations", "hub_patterns", "category_sizes")


def shard_files(folder: Path, name: str, shards: int) -> list[Path]:
    """``<folder>/<name>-<k>.parquet`` for k < shards; a missing one is an error naming it."""
    files = [Path(folder) / f"{name}-{k}.parquet" for k in range(shards)]
    missing = [str(f) for f in files if not f.exists()]
    if missing:
        raise tables.TableError(f"missing shard table(s): {', '.join(missing)}")
    return files


def rooms_of(nodes: pd.DataFrame, edges: pd.DataFrame):
    """(room_id, node rows, edge rows) per room, nodes' order kept."""
    node_groups = {k: g.to_dict("records") for k, g in nodes.groupby("room_id", sort=False)}
    edge_groups = {k: g.to_dict("records") for k, g in edges.groupby("room_id", sort=False)}
    for room_id, rows in node_groups.items():
        yield room_id, rows, edge_groups.get(room_id, [])


def _frame(path: Path, name: str) -> pd.DataFrame:
    df = tables.read(path, name).to_pandas()
    for col in df.columns:  # plain strings for the per-room dict code
        if isinstance(df[col].dtype, pd.CategoricalDtype):
            df[col] = df[col].astype(object)
    return df.astype(object).where(df.notna(), None)


def run_statistics(config: dict, raw_dir: Path, out_dir: Path) -> dict:
    cfg = config["refine"]
    shards = config["shards"]
    node_files, edge_files = shard_files(raw_dir, "nodes", shards), shard_files(raw_dir, "edges", shards)
    stats = relation_statistics(node_files, edge_files)
    per_room = []
    for nf, ef in zip(node_files, edge_files):
        per_room += [(n, e) for _, n, e in rooms_of(_frame(nf, "nodes"), _frame(ef, "edges"))]
    stats["hub_patterns"] = hub_pattern_counts(per_room, cfg)
    extra = {"config_hash": config_hash(cfg)}
    for name in STAT_TABLES:
        tables.write(Path(out_dir) / f"{name}.parquet", name, pa.Table.from_pandas(stats[name], preserve_index=False), extra)
    summary = {name: len(stats[name]) for name in STAT_TABLES}
    summary["accepted_hub_patterns"] = int(stats["hub_patterns"]["accepted"].sum()) if len(stats["hub_patterns"]) else 0
    log.info("graph statistics: %s", summary)
    return summary


def load_stats(stats_dir: Path) -> Stats:
    rel = tables.read(stats_dir / "relations.parquet", "relations").to_pandas()
    hubs = tables.read(stats_dir / "hub_patterns.parquet", "hub_patterns").to_pandas()
    sizes = tables.read(stats_dir / "category_sizes.parquet", "category_sizes").to_pandas()
    s = Stats()
    s.relfreq = {(str(r.room_type), r.cat_a, r.cat_b, str(r.direction), str(r.distance)): float(r.freq)
                 for r in rel.itertuples(index=False)}
    for r in hubs[hubs["accepted"]].itertuples(index=False):
        s.hub_patterns.setdefault(str(r.room_type), set()).add((r.hub_category, r.spoke_category))
    s.category_area = {(str(r.room_type), r.category): float(r.mean_area) for r in sizes.itertuples(index=False)}
    return s


def run_refine(config: dict, shard: int, raw_dir: Path, stats_dir: Path, out_dir: Path) -> dict:
    cfg = config["refine"]
    stats = load_stats(Path(stats_dir))
    nodes = _frame(Path(raw_dir) / f"nodes-{shard}.parquet", "nodes")
    edges = _frame(Path(raw_dir) / f"edges-{shard}.parquet", "edges")
    out_nodes, out_edges, supers = [], [], []
    cyclic, repaired, rooms = [], 0, 0
    for room_id, n, e in progress(list(rooms_of(nodes, edges)), desc=f"refine shard {shard}"):
        r = refine_room(n, e, stats, cfg)
        rooms += 1
        out_nodes += r.nodes
        for row in r.edges:
            row.update(room_id=room_id, shard=shard)
        out_edges += r.edges
        room_type = n[0]["room_type"]
        supers += [dict(s, room_id=room_id, room_type=room_type) for s in r.superstructures]
        repaired += r.repaired
        if r.cyclic:
            cyclic.append(room_id)
    extra = {"config_hash": config_hash(cfg), "shard": str(shard)}
    out_dir = Path(out_dir)
    tables.write(out_dir / f"nodes-{shard}.parquet", "final_nodes", tables.from_rows("final_nodes", out_nodes), extra)
    tables.write(out_dir / f"edges-{shard}.parquet", "final_edges", tables.from_rows("final_edges", out_edges), extra)
    tables.write(out_dir / f"superstructures-{shard}.parquet", "superstructures",
                 tables.from_rows("superstructures", supers), extra)
    summary = {"shard": shard, "rooms": rooms, "edges": len(out_edges),
               "kept": sum(e["status"] == "kept" for e in out_edges), "repaired": repaired,
               "cyclic_rooms": len(cyclic), "cyclic_room_ids": cyclic}
    tables.write_json(out_dir / f"summary-{shard}.json", summary)
    log.info("refined shard %d: %s", shard, {k: v for k, v in summary.items() if k != "cyclic_room_ids"})
    return summary


def run_gather(config: dict, final_dir: Path, out_dir: Path) -> dict:
    """One ``nodes.parquet`` / ``edges.parquet`` / ``superstructures.parquet`` for every learning stage, sorted by
    room type then room, so ``filters=[('room_type', '=', t)]`` skips row groups of other types."""
    shards = config["shards"]
    counts = {}
    for name, schema in (("nodes", "final_nodes"), ("edges", "final_edges"), ("superstructures", "superstructures")):
        parts = [tables.read(f, schema) for f in shard_files(final_dir, name, shards)]
        table = pa.concat_tables(parts).combine_chunks() if parts else tables.empty(schema)
        if table.num_rows:
            keys = pa.table({"t": table["room_type"].cast(pa.string()), "r": table["room_id"]})
            table = table.take(pc.sort_indices(keys, sort_keys=[("t", "ascending"), ("r", "ascending")]))
        tables.write(Path(out_dir) / f"{name}.parquet", schema, table, {"shards": str(shards)})
        counts[name] = table.num_rows
    return counts
