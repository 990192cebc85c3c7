"""Refinement stage, one job per shard: superstructures, pruning and connectivity repair of the raw graphs."""
from __future__ import annotations

import logging
from pathlib import Path

from .. import tables
from ..config import config_hash
from ..graphs.refine import Stats, refine_room
from ..graphs.statistics import parse_candidates
from ..log import progress
from ..stage import Files

log = logging.getLogger("planit.graphs")


def load_stats(relations: Path, hub_patterns: Path, category_sizes: Path) -> Stats:
    rel = tables.read(relations, "relations").to_pandas()
    hubs = tables.read(hub_patterns, "hub_patterns").to_pandas()
    sizes = tables.read(category_sizes, "category_sizes").to_pandas()
    s = Stats()
    s.relfreq = {(str(r.room_type), r.cat_a, r.cat_b, str(r.direction), str(r.distance)): float(r.freq)
                 for r in rel.itertuples(index=False)}
    for r in hubs[hubs["accepted"]].itertuples(index=False):
        s.hub_patterns.setdefault(str(r.room_type), set()).add((r.hub_category, r.spoke_category))
    s.category_area = {(str(r.room_type), r.category): float(r.mean_area) for r in sizes.itertuples(index=False)}
    return s


def run(config: dict, inp: Files, out: Files, shard: int) -> dict:
    nodes, edges, candidates, stats = inp.nodes, inp.edges, inp.candidates, inp
    cfg = config["refine"]
    st = load_stats(stats["relations"], stats["hub_patterns"], stats["category_sizes"])
    node_rows, edge_rows = tables.records_by_room(nodes, "nodes"), tables.records_by_room(edges, "edges")
    cand = tables.records_by_room(candidates, "superstructures")
    out_nodes, out_edges, supers, cyclic = [], [], [], []
    repaired = 0
    for room_id, n in progress(list(node_rows.items()), desc=f"refine shard {shard}"):
        r = refine_room(n, edge_rows.get(room_id, []), st, cfg, parse_candidates(cand.get(room_id, [])))
        out_nodes += r.nodes
        out_edges += [dict(e, room_id=room_id, shard=shard) for e in r.edges]
        supers += [dict(s, room_id=room_id, room_type=n[0]["room_type"]) for s in r.superstructures]
        repaired += r.repaired
        if r.cyclic:
            cyclic.append(room_id)
    extra = {"config_hash": config_hash(cfg), "shard": str(shard)}
    tables.write(out["nodes"], "final_nodes", tables.from_rows("final_nodes", out_nodes), extra)
    tables.write(out["edges"], "final_edges", tables.from_rows("final_edges", out_edges), extra)
    tables.write(out["superstructures"], "superstructures", tables.from_rows("superstructures", supers), extra)
    summary = {"shard": shard, "rooms": len(node_rows), "edges": len(out_edges),
               "kept": sum(e["status"] == "kept" for e in out_edges), "repaired": repaired,
               "cyclic_rooms": len(cyclic), "cyclic_room_ids": cyclic}
    tables.write_json(out["summary"], summary)
    log.info("refined shard %d: %s", shard, {k: v for k, v in summary.items() if k != "cyclic_room_ids"})
    return summary
