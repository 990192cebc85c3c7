"""What instantiation places: one scene's planned graph (objects and the edges that constrain them), read from the
generated or the corpus's final graph tables."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..seeding import rng_for

DISTANCE_WEIGHT = {"adjacent": 3.0, "proximal": 2.0, "distant": 1.0}  # PlanIT's C_in weights; support counts as adjacent


@dataclass(frozen=True)
class PlanEdge:
    source: str
    target: str
    edge_type: str  # support | spatial
    direction: str | None
    distance: str | None

    @property
    def weight(self) -> float:
        return DISTANCE_WEIGHT["adjacent"] if self.edge_type == "support" else DISTANCE_WEIGHT[self.distance]


@dataclass
class ScenePlan:
    """Objects to place (ids, categories, symmetries, tiers, support parents, superstructure roles) and the edges
    that involve them (walls may be sources)."""
    scene_id: str
    room_id: str  # the room whose architecture the scene uses
    room_type: str
    ids: list[str]
    categories: list[str]
    symmetry: list[str]
    tier: list[int]
    parent: list[str | None]
    role: list[str]
    edges: list[PlanEdge]

    def index(self, node_id: str) -> int:
        return self.ids.index(node_id)


def plans_from_tables(nodes: pd.DataFrame, edges: pd.DataFrame, pruning: str = "full", seed: int = 0,
                      limit: int | None = None) -> list[ScenePlan]:
    """One plan per scene of a graph table pair (generated tables: per ``scene_id``; final tables: per room), the
    first ``limit`` scenes only when given. ``pruning``: full (kept edges), none (pruned spatial edges too: the
    paper's no-pruning ablation) or half (a seeded half of the pruned ones, drawn over the whole table)."""
    scene_col = "scene_id" if "scene_id" in nodes.columns else "room_id"
    rng = rng_for(seed, "plan-pruning")
    status = edges["status"].astype(str).to_numpy() if "status" in edges.columns else np.full(len(edges), "kept")
    take = status == "kept"
    if pruning != "full":
        pruned = np.flatnonzero((status == "pruned") & (edges["edge_type"].astype(str) == "spatial").to_numpy())
        if pruning == "half":
            pruned = rng.permutation(pruned)[: len(pruned) // 2]
        take[pruned] = True
    edges = edges[take & edges["edge_type"].astype(str).isin(["support", "spatial"]).to_numpy()]
    by_scene = dict(tuple(edges.groupby(scene_col, sort=False)))
    out = []
    for scene_id, g in nodes.groupby(scene_col, sort=False):
        if limit is not None and len(out) >= limit:
            break
        objs = g[g["kind"].astype(str) == "object"]
        e = by_scene.get(scene_id, edges.iloc[:0])
        src_room = str(g["source_room_id"].iloc[0]) if "source_room_id" in g.columns else str(scene_id)
        out.append(ScenePlan(
            scene_id=str(scene_id), room_id=src_room, room_type=str(g["room_type"].iloc[0]),
            ids=objs["node_id"].astype(str).tolist(), categories=objs["category"].astype(str).tolist(),
            symmetry=objs["symmetry"].astype(str).tolist(), tier=objs["tier"].astype(int).tolist(),
            parent=[None if pd.isna(p) else str(p) for p in objs["parent_id"]],
            role=[str(r) if isinstance(r, str) else "none" for r in objs.get("role", pd.Series(["none"] * len(objs)))],
            edges=[PlanEdge(str(s), str(t), str(k), None if pd.isna(d) else str(d), None if pd.isna(x) else str(x))
                   for s, t, k, d, x in zip(e["source"], e["target"], e["edge_type"], e["direction"], e["distance"])]))
    return out
