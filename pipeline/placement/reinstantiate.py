"""Re-instantiating real rooms' own graphs, no network needed: each room is emptied and its objects placed again
from its extracted graph by the search with the relation-band proposer (turned to what the plan puts around each
object, else away from the nearest wall), then extracted again. How the search does
on real furniture meshes and real room shapes (tests, bench/front3d_instantiate.py)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..geometry.raycast import intersector_class
from ..room import room_inputs
from . import order, scene_metrics
from .checks import Checker, checks_config
from .layout import walls_of, with_objects
from .plan import plans_from_tables
from .proposers import Combined, FaceAway, FacePlanned, RelationPrior
from .retrieval import ModelPool
from .search import Kit, instantiate


def own_plans(nodes: pd.DataFrame, edges: pd.DataFrame, distances=("adjacent",)):
    """Plans from raw extracted graphs: support edges and spatial edges of the given distance labels."""
    keep = (edges["edge_type"] == "support") | ((edges["edge_type"] == "spatial") & edges["distance"].isin(distances))
    return plans_from_tables(nodes, edges[keep].assign(status="kept"))


def reinstantiate(frames: dict[str, pd.DataFrame], models: tuple[dict, set, dict], config: dict, plans,
                  min_objects: int = 3, seed: int = 0) -> list[dict]:
    """One row per room with at least ``min_objects`` planned objects: placed or not, why, consistency, collisions.
    ``frames``: the rooms', architecture and objects tables (``rooms``, ``architecture``, ``objects``); ``models``:
    the meshes by model id, the box-only model ids and the symmetry type by model id."""
    rooms, architecture, objects = frames["rooms"], frames["architecture"], frames["objects"]
    meshes, box_models, symmetry = models
    ext = {"floor_contact": config["floor_contact"], **config["extract"]}
    ic = config["instantiate"]
    checker = Checker(meshes, box_models, symmetry, ext, intersector_class(ext["backend"]), checks_config(config))
    inputs = {r.room_id: r for r in room_inputs(rooms, architecture, objects)}
    pool = ModelPool(objects, symmetry, config["floor_contact"])
    areas = objects.assign(a=4 * objects["hx"] * objects["hy"]).groupby("category")["a"].mean().to_dict()
    rows = []
    for plan in plans:
        if plan.room_id not in inputs or len(plan.ids) < min_objects:
            continue
        room = with_objects(inputs[plan.room_id], [])
        walls = walls_of(room)
        out = instantiate(plan, room, order.placement_order(plan, areas),
                          Combined(RelationPrior(config["extract"]), FacePlanned(FaceAway())), Kit(pool, checker), ic, seed)
        m = scene_metrics.consistency(plan, out.room, walls.ids, checker)
        rows.append({"room_id": plan.room_id, "objects": len(plan.ids), "placed": out.status == "placed", "reason": out.reason,
                     "seconds": out.seconds, "backtracks": out.backtracks, "attempts": out.attempts, **m,
                     "colliding_objects": scene_metrics.colliding_objects(out.room, dict(zip(plan.ids, plan.parent)), checker)})
    return rows


def summary(rows: list[dict]) -> dict:
    placed = [r for r in rows if r["placed"]]
    return {"rooms": len(rows), "placed": len(placed), "restarted": sum(r["attempts"] > 1 for r in rows),
            "mean_consistency_placed": round(float(np.mean([r["consistency"] for r in placed])), 4) if placed else None,
            "median_seconds": round(float(np.median([r["seconds"] for r in rows])), 2) if rows else None,
            "colliding_objects_placed": int(sum(r["colliding_objects"] for r in placed))}
