"""Per-scene rows and per-set figures of the evaluation: physical checks, walkability, nearest-training-room
similarity, distribution distances beside their sampling floors, the goals and the table of sets."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from ..geometry.collision import CollisionTest
from ..geometry.raycast import intersector_class
from ..log import progress
from ..room import walkability
from ..seeding import rng_for
from . import distributions, physical, render
from .sets import RoomSet

if TYPE_CHECKING:
    from ..extraction import RoomGraph
    from ..placement.checks import Checker


def scene_rows(rs: RoomSet, meshes: dict[str, Any], box_models: set[str], train_maps: np.ndarray, train_ids: list[str],
               index: dict[str, int], config: dict[str, Any]) -> list[dict[str, Any]]:
    """One ``eval_scenes`` row per room of a set."""
    ev = config["evaluate"]
    collision_test = CollisionTest.of(ev["collision"]["penetration"], ev["collision"]["max_penetration"],
                                      intersector_class(config["extract"]["backend"]))
    records = rs.scenes.set_index("scene_id") if rs.scenes is not None else None
    measure = walkability.Walk.of(ev["walk"])
    rows = []
    for room, parents in progress(list(zip(rs.rooms, rs.parents)), desc=f"scoring {rs.name}"):
        mesh = [None if m in box_models else meshes.get(m) for m in room.model_ids]
        walk = walkability.walkability(room, measure)
        sim = render.similarity(render.label_map(room, index, ev["render"]["size"], ev["render"]["mpp"]), train_maps)
        sim[[k for k, t in enumerate(train_ids) if t == room.room_id]] = -1.0  # a training room is not its own neighbour
        nn = int(np.argmax(sim)) if len(sim) else None
        rec = records.loc[room.room_id] if records is not None and room.room_id in records.index else None
        rows.append({
            "set": rs.name, "scene_id": room.room_id, "room_type": room.room_type, "objects": len(room.object_ids),
            "colliding_objects": int(physical.colliding(room, parents, mesh, collision_test).sum()),
            "out_of_bounds": int(physical.out_of_bounds(room.outline, room.boxes, ev["out_of_bounds"]["erode"],
                                                        ev["out_of_bounds"]["tolerance"]).sum()),
            "walkable_share": walk["walkable_share"], "reachable": walk["reachable"],
            "nn_similarity": None if nn is None else float(sim[nn]), "nn_room_id": None if nn is None else train_ids[nn],
            "consistency": _optional(rec, "consistency"), "violation": _optional(rec, "violation")})
    return rows


def rule_view(graph: RoomGraph) -> tuple[list[str], list[tuple[int, int, str]]]:
    """(categories, edges with kind names) of an extracted room graph, for the procedural generator's rules."""
    ids = {n["node_id"]: k for k, n in enumerate(graph.nodes)}
    cats = [n["category"] if n["kind"] == "object" else n["kind"] for n in graph.nodes]
    kind = lambda e: "support" if e["edge_type"] == "support" else (
        f"{e['direction']}/{e['distance']}" if e["edge_type"] == "spatial" else e["edge_type"])
    return cats, [(ids[e["source"]], ids[e["target"]], kind(e)) for e in graph.edges
                  if e["source"] in ids and e["target"] in ids]


def rule_satisfaction(rs: RoomSet, checker: Checker) -> dict[str, Any]:
    """The procedural generator's arrangement rules on each room's extracted graph (the project's extraction)."""
    from ..corpus.procedural_rules import satisfaction  # the procedural corpus's rules: an oracle for its rooms only

    return satisfaction([rule_view(checker.extract(r)) for r in progress(rs.rooms, desc=f"rules {rs.name}")])


def set_counts(rows: pd.DataFrame, rs: RoomSet) -> dict[str, Any]:
    """How many rooms a set scores, how many its method attempted and how many of them are partial."""
    seconds = None if rs.scenes is None or rs.scenes["seconds"].isna().all() else float(rs.scenes["seconds"].median())
    relaxed = None if rs.scenes is None or rs.scenes["relaxed_objects"].isna().all() else float(
        rs.scenes["relaxed_objects"].fillna(0).sum() / max(rs.scenes["placed_objects"].sum(), 1))
    return {"scenes": len(rows), "attempted": rs.attempted,
            "partial": 0 if rs.scenes is None else int((rs.scenes["status"].astype(str) == "partial").sum()),
            "seconds_per_scene": seconds, "relaxed_share": relaxed}


def floors(train: RoomSet, real: RoomSet, generated: int, cfg: dict[str, Any], seed: int) -> dict[str, Any]:
    """The category KL and count distance between two disjoint sets of real rooms of the held-out and generated
    sizes (what sample size alone costs)."""
    pool = [r for s in (train, real) for r in s.rooms]
    sizes = (len(real.rooms), generated)
    kl = lambda a, b: distributions.category_kl(distributions.flatten([r.categories for r in a]),
                                                distributions.flatten([r.categories for r in b]), cfg["kl_eps"])
    count = lambda a, b: distributions.count_distance([len(r.object_ids) for r in a], [len(r.object_ids) for r in b])
    return {"category_kl": distributions.sampling_floor(pool, sizes, kl, cfg["floor_repeats"], seed),
            "count_distance": distributions.sampling_floor(pool, sizes, count, cfg["floor_repeats"], seed)}


def train_similarity(train_maps: np.ndarray, sample: int, seed: int) -> dict[str, Any]:
    """A training room's similarity to its nearest other training room, over a seeded sample of them."""
    if len(train_maps) < 2:
        return {"mean": None, "sd": None, "rooms": 0}
    pick = rng_for(seed, "train-similarity").permutation(len(train_maps))[:sample]
    best = []
    for k in pick:
        sim = render.similarity(train_maps[k], train_maps)
        sim[k] = -1.0
        best.append(sim.max())
    return {"mean": round(float(np.mean(best)), 5), "sd": round(float(np.std(best)), 5), "rooms": len(pick)}


def goals(metrics: dict[str, Any], first: str, real: str) -> dict[str, Any]:
    """The evaluation issue's goals for the first method's rooms and for the evaluation itself (reported, never tuned
    against). The classifier's goal reads ``inconclusive`` when its power check failed."""
    sets, fl, checks = metrics["sets"], metrics["floors"], metrics["checks"]
    g, r = sets[first], sets[real]
    within = lambda key: (fl[key]["mean"] == fl[key]["mean"] and g[key] <= 1.5 * max(fl[key]["mean"], 1e-9))
    near = lambda key, points: (g[key] == g[key] and r[key] == r[key] and abs(g[key] - r[key]) <= points)
    out = {"category_kl_within_1.5x_floor": within("category_kl"),
           "count_distance_within_1.5x_floor": within("count_distance"),
           "collision_rate_at_most_real": g["object_collision_rate"] <= r["object_collision_rate"],
           "out_of_bounds_rate_at_most_real": g["out_of_bounds_rate"] <= r["out_of_bounds_rate"],
           "walkable_within_5_points_of_real": near("walkable_share", 0.05),
           "functional_all_within_5_points_of_real": near("functional_all", 0.05),
           "classifier_power_check_passed": metrics["power"]["passed"]}
    out = {k: bool(v) for k, v in out.items()}
    # no check learned (too few training rooms for the Wilson bound): nothing to pass
    out["real_rooms_pass_every_functional_check_95"] = (
        bool(all(not r[c] == r[c] or r[c] >= 0.95 for c in checks)) if checks else "no checks")
    sca = (g.get("sca") or {}).get("accuracy")
    if sca is not None and sca == sca:
        out["sca_at_most_60"] = bool(sca <= 60.0) if metrics["power"]["passed"] else "inconclusive"
    return out


def finite(value: Any) -> Any:
    """JSON-safe: NaN and infinities become None (recursively)."""
    if isinstance(value, dict):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def label_maps(rs: RoomSet, index: dict[str, int], cfg: dict[str, Any]) -> np.ndarray:
    """``(n, size, size)`` int16 label maps of a set's rooms."""
    size = cfg["size"]
    maps = [render.label_map(r, index, size, cfg["mpp"]) for r in rs.rooms]
    return np.stack(maps) if maps else np.zeros((0, size, size), np.int16)


TABLE_COLUMNS = ["scenes", "attempted", "category_kl", "count_distance", "object_collision_rate", "scene_collision_rate",
                 "out_of_bounds_rate", "walkable_share", "reachable_scenes", "consistency", "violation", "relaxed_share",
                 "nn_similarity", "contents_excess", "contents_missing", "functional_all", "cooccurrence_similarity",
                 "off_axis_share", "off_axis_gap", "seconds_per_scene"]


def metrics_table(metrics: dict[str, Any]) -> pd.DataFrame:
    """One row per set with every figure and the classifier's accuracy (the sampling floors and the training
    rooms' own similarity as rows of their own), then one row per power set."""
    rows = [{"set": name, **{k: s.get(k) for k in TABLE_COLUMNS + metrics["checks"]},
             "sca": (s.get("sca") or {}).get("accuracy")} for name, s in metrics["sets"].items()]
    fl = metrics["floors"]
    rows.append({"set": "floor (real vs real)", "category_kl": fl["category_kl"]["mean"],
                 "count_distance": fl["count_distance"]["mean"]})
    rows.append({"set": "training vs nearest training", "nn_similarity": metrics["train_nn_similarity"]["mean"]})
    rows += [{"set": f"power: {name}", "sca": s["accuracy"]} for name, s in metrics["power"]["scores"].items()]
    frame = pd.DataFrame(rows, columns=["set", *TABLE_COLUMNS, *metrics["checks"], "sca"])
    return frame.astype({"scenes": "Int64", "attempted": "Int64"})


def _optional(record: pd.Series | None, column: str) -> float | None:
    """A float of a scene's instantiation record, None where there is no record or no value."""
    if record is None or pd.isna(record[column]):
        return None
    return float(record[column])
