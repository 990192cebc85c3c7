"""Evaluate one room type's generated rooms against its held-out real rooms (evaluation issue): per scene, the
physical metrics, walkability and nearest-training-room similarity; per set, the category and object-count
distances beside their sampling floors, the collision, out-of-bounds and walkability rates, graph consistency and
the real-vs-synthetic classifier accuracy. Sets: the default generated rooms (planit), each baseline variant, a
retrieval baseline (each generated scene's nearest training room) and the held-out real rooms themselves (the
ceiling). Every set goes through the same functions."""
from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .. import tables
from ..errors import InputError
from ..evaluation import distributions, physical, render, walkability
from ..geometry.raycast import intersector_class
from ..graphs.data import split_heldout
from ..log import progress
from ..placement.checks import Checker
from ..placement.search import SCORED
from ..room import RoomInput, room_inputs
from ..stage import Files

log = logging.getLogger("planit.evaluate")
REAL, RETRIEVAL = "real_heldout", "retrieval"


@dataclass
class RoomSet:
    """Rooms of one set with each object's support parent and, for generated sets, the instantiation records."""
    name: str
    rooms: list[RoomInput]
    parents: list[list]
    scenes: pd.DataFrame | None = None  # scene_id, consistency, violation (placed scenes)
    attempted: int = 0


def room_set(name: str, rooms: pd.DataFrame, architecture: pd.DataFrame, objects: pd.DataFrame,
             scenes: pd.DataFrame | None = None) -> RoomSet:
    objs = objects.sort_values("room_id", kind="stable")
    parents = {k: g["source_parent_id"].tolist() for k, g in objs.groupby("room_id", sort=False)}
    inputs = list(room_inputs(rooms, architecture, objs))
    return RoomSet(name, inputs, [parents.get(r.room_id, []) for r in inputs], scenes, len(rooms))


def load_generated(name: str, rooms: Path, architecture: Path, objects: Path, scenes: Path) -> RoomSet:
    """A generated set's placed scenes, partial ones included (failed ones are counted, not scored)."""
    scenes = tables.read(scenes, "scenes").to_pandas()
    placed = set(scenes.loc[scenes["status"].astype(str).isin(SCORED), "scene_id"])
    rooms = tables.read(rooms, "rooms").to_pandas()
    out = room_set(name, rooms[rooms["room_id"].isin(placed)], tables.read(architecture, "architecture").to_pandas(),
                   tables.read(objects, "generated_objects").to_pandas(), scenes[scenes["scene_id"].isin(placed)])
    out.attempted = len(scenes)
    return out


def load_real(config: dict, room_type: str, rooms: list[Path], architecture: list[Path], objects: list[Path],
              nodes: Path) -> tuple[RoomSet, RoomSet]:
    """The training and held-out real rooms of ``room_type`` (the graph model's split of the final graphs)."""
    ids = tables.read(nodes, "final_nodes", columns=["room_id"], filters=[("room_type", "=", room_type)])
    ids = sorted(set(ids.column("room_id").to_pylist()))
    if len(ids) < 2:
        raise InputError(f"{nodes}: fewer than 2 graphs of room type '{room_type}' to evaluate against")
    train, held = split_heldout(ids, config["graph_model"]["heldout_fraction"], config["seed"])
    flt = [("room_id", "in", ids)]
    frames = [pd.concat([tables.read(p, t, filters=flt).to_pandas() for p in paths], ignore_index=True)
              for paths, t in ((rooms, "rooms"), (architecture, "architecture"), (objects, "objects"))]
    pick = lambda keep, name: room_set(name, frames[0][frames[0]["room_id"].isin(keep)], frames[1],
                                       frames[2][frames[2]["room_id"].isin(keep)])
    return pick(set(train), "real_train"), pick(set(held), REAL)


def scene_rows(rs: RoomSet, meshes: dict, box_models: set, train_maps: np.ndarray, train_ids: list[str],
               index: dict, config: dict) -> list[dict]:
    """One ``eval_scenes`` row per room of a set."""
    ev = config["evaluate"]
    ccfg = {"max_penetration": ev["collision"]["max_penetration"], "penetration": ev["collision"]["penetration"],
            "intersector": intersector_class(config["extract"]["backend"])}
    records = rs.scenes.set_index("scene_id") if rs.scenes is not None else None
    rows = []
    for room, parents in progress(list(zip(rs.rooms, rs.parents)), desc=f"scoring {rs.name}"):
        mesh = [None if m in box_models else meshes.get(m) for m in room.model_ids]
        walk = walkability.walkability(room, ev["walk"])
        sim = render.similarity(render.label_map(room, index, ev["render"]["size"], ev["render"]["mpp"]), train_maps)
        sim[[k for k, t in enumerate(train_ids) if t == room.room_id]] = -1.0  # a training room is not its own neighbour
        nn = int(np.argmax(sim)) if len(sim) else None
        rec = records.loc[room.room_id] if records is not None and room.room_id in records.index else None
        rows.append({
            "set": rs.name, "scene_id": room.room_id, "room_type": room.room_type, "objects": len(room.object_ids),
            "colliding_objects": int(physical.colliding(room, parents, mesh, ccfg).sum()),
            "out_of_bounds": int(physical.out_of_bounds(room.outline, room.boxes, ev["out_of_bounds"]["erode"],
                                                        ev["out_of_bounds"]["tolerance"]).sum()),
            "walkable_share": walk["walkable_share"], "reachable": walk["reachable"],
            "nn_similarity": None if nn is None else float(sim[nn]), "nn_room_id": None if nn is None else train_ids[nn],
            "consistency": None if rec is None else float(rec["consistency"]),
            "violation": None if rec is None else float(rec["violation"])})
    return rows


def retrieval_set(planit: pd.DataFrame, train: RoomSet) -> RoomSet:
    """The memorisation baseline: for each generated scene, its nearest training room (under the scene's id)."""
    by_id = {r.room_id: (r, p) for r, p in zip(train.rooms, train.parents)}
    picked = [(scene, *by_id[nn]) for scene, nn in zip(planit["scene_id"], planit["nn_room_id"]) if nn in by_id]
    rooms = [RoomInput(**{**vars(r), "room_id": scene}) for scene, r, _ in picked]
    return RoomSet(RETRIEVAL, rooms, [p for _, _, p in picked], None, len(planit))


def rule_view(graph) -> tuple[list[str], list[tuple[int, int, str]]]:
    """(categories, edges with kind names) of an extracted room graph, for the procedural generator's rules."""
    ids = {n["node_id"]: k for k, n in enumerate(graph.nodes)}
    cats = [n["category"] if n["kind"] == "object" else n["kind"] for n in graph.nodes]
    kind = lambda e: "support" if e["edge_type"] == "support" else (
        f"{e['direction']}/{e['distance']}" if e["edge_type"] == "spatial" else e["edge_type"])
    return cats, [(ids[e["source"]], ids[e["target"]], kind(e)) for e in graph.edges
                  if e["source"] in ids and e["target"] in ids]


def rule_satisfaction(rs: RoomSet, checker) -> dict:
    """The procedural generator's arrangement rules on each room's extracted graph (the project's extraction)."""
    from ..corpus.procedural_rules import satisfaction

    return satisfaction([rule_view(checker.extract(r)) for r in progress(rs.rooms, desc=f"rules {rs.name}")])


def set_summary(rows: pd.DataFrame, rs: RoomSet, real: RoomSet, eps: float) -> dict:
    """Set-level figures of one set's scene rows against the held-out real rooms."""
    objects = max(int(rows["objects"].sum()), 1)
    mean = lambda col: None if rows[col].isna().all() else round(float(rows[col].mean()), 5)
    return {
        "scenes": len(rows), "attempted": rs.attempted,
        "partial": 0 if rs.scenes is None else int((rs.scenes["status"].astype(str) == "partial").sum()),
        "category_kl": round(distributions.category_kl(_categories(real), _categories(rs), eps), 6),
        "count_distance": round(distributions.count_distance([len(r.object_ids) for r in real.rooms],
                                                             [len(r.object_ids) for r in rs.rooms]), 5),
        "object_collision_rate": round(float(rows["colliding_objects"].sum() / objects), 5),
        "scene_collision_rate": round(float((rows["colliding_objects"] > 0).mean()), 5) if len(rows) else None,
        "out_of_bounds_rate": round(float(rows["out_of_bounds"].sum() / objects), 5),
        "walkable_share": mean("walkable_share"),
        "reachable_scenes": round(float((rows["reachable"] >= 1.0).mean()), 5) if len(rows) else None,
        "consistency": mean("consistency"), "violation": mean("violation"),
        "nn_similarity": {"mean": mean("nn_similarity"),
                          "sd": None if len(rows) < 2 else round(float(rows["nn_similarity"].std(ddof=0)), 5)},
    }


def _categories(rs: RoomSet) -> list[str]:
    return distributions.flatten([r.categories for r in rs.rooms])


def floors(train: RoomSet, real: RoomSet, generated: int, cfg: dict, seed: int) -> dict:
    """The category KL and count distance between two disjoint sets of real rooms of the held-out and generated
    sizes (what sample size alone costs)."""
    pool = [r for s in (train, real) for r in s.rooms]
    sizes = (len(real.rooms), generated)
    kl = lambda a, b: distributions.category_kl(distributions.flatten([r.categories for r in a]),
                                                distributions.flatten([r.categories for r in b]), cfg["kl_eps"])
    count = lambda a, b: distributions.count_distance([len(r.object_ids) for r in a], [len(r.object_ids) for r in b])
    return {"category_kl": distributions.sampling_floor(pool, sizes, kl, cfg["floor_repeats"], seed),
            "count_distance": distributions.sampling_floor(pool, sizes, count, cfg["floor_repeats"], seed)}


def train_similarity(train_maps: np.ndarray, sample: int, seed: int) -> dict:
    """A training room's similarity to its nearest other training room, over a seeded sample of them."""
    if len(train_maps) < 2:
        return {"mean": None, "sd": None, "rooms": 0}
    pick = np.random.default_rng([seed, 31]).permutation(len(train_maps))[:sample]
    best = []
    for k in pick:
        sim = render.similarity(train_maps[k], train_maps)
        sim[k] = -1.0
        best.append(sim.max())
    return {"mean": round(float(np.mean(best)), 5), "sd": round(float(np.std(best)), 5), "rooms": len(pick)}


def goals(sets: dict, fl: dict) -> dict:
    """The evaluation issue's goals for the default generated rooms (reported, never tuned against)."""
    g, r = sets["planit"], sets[REAL]
    within = lambda key: (fl[key]["mean"] == fl[key]["mean"] and g[key] <= 1.5 * max(fl[key]["mean"], 1e-9))
    out = {"category_kl_within_1.5x_floor": within("category_kl"),
           "count_distance_within_1.5x_floor": within("count_distance"),
           "collision_rate_at_most_real": g["object_collision_rate"] <= r["object_collision_rate"],
           "out_of_bounds_rate_at_most_real": g["out_of_bounds_rate"] <= r["out_of_bounds_rate"],
           "walkable_within_5_points_of_real": (g["walkable_share"] is not None and r["walkable_share"] is not None
                                                and abs(g["walkable_share"] - r["walkable_share"]) <= 0.05)}
    if g.get("sca") and g["sca"]["mean"] == g["sca"]["mean"]:
        out["sca_at_most_60"] = g["sca"]["mean"] <= 60.0
    return {k: bool(v) for k, v in out.items()}


def _finite(value):
    """JSON-safe: NaN and infinities become None (recursively)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def label_maps(rs: RoomSet, index: dict, cfg: dict) -> np.ndarray:
    """``(n, size, size)`` int16 label maps of a set's rooms."""
    size = cfg["size"]
    maps = [render.label_map(r, index, size, cfg["mpp"]) for r in rs.rooms]
    return np.stack(maps) if maps else np.zeros((0, size, size), np.int16)


def generated_sets(inp: Files) -> list[tuple[str, RoomSet]]:
    """(name, rooms) of each generated set, in the order given (the default generator first)."""
    names = [json.loads(Path(s).read_text())["variant"] for s in inp.summaries]
    return [load_generated(n, r, a, o, s) for n, r, a, o, s in zip(names, inp.generated_rooms, inp.generated_architecture,
                                                                    inp.generated_objects, inp.generated_scenes)]


def run(config: dict, inp: Files, out: Files, room_type: str, threads: int = 1) -> dict:
    """Score every set; write the per-scene rows (``eval_scenes``), ``metrics.json``, the table of the sets beside
    each other (CSV) and a gallery of generated and held-out real rooms with their graphs (PNG, GLB). ``generated``:
    (set name, instantiation folder) pairs, the default variant (planit) first."""
    ev = config["evaluate"]
    rooms, architecture, objects, models, nodes, edges = inp.rooms, inp.architecture, inp.objects, inp.models, inp.nodes, inp.edges
    train, real = load_real(config, room_type, rooms, architecture, objects, nodes)
    gen = generated_sets(inp)
    model_ids = {m for rs in (train, real, *gen) for r in rs.rooms for m in r.model_ids}
    meshes, box_models = tables.read_meshes_of(models, model_ids)
    index = {c: k for k, c in enumerate(sorted({c for s in (train, real, *gen) for r in s.rooms for c in r.categories}))}
    train_maps = label_maps(train, index, ev["render"])
    train_ids = [r.room_id for r in train.rooms]
    score = lambda rs: scene_rows(rs, meshes, box_models, train_maps, train_ids, index, config)
    rows = {rs.name: pd.DataFrame(score(rs), columns=tables.SCHEMAS["eval_scenes"].names) for rs in (*gen, real)}
    retrieval = retrieval_set(rows[gen[0].name], train)
    rows[RETRIEVAL] = pd.DataFrame(score(retrieval), columns=tables.SCHEMAS["eval_scenes"].names)
    by_name = {rs.name: rs for rs in (*gen, real, retrieval)}
    sets = {name: set_summary(frame, by_name[name], real, ev["kl_eps"]) for name, frame in rows.items()}
    sca_settings = {**ev["sca"], "device": config["evaluate"]["sca"]["device"]}
    real_maps = (render.to_rgb(train_maps, render.palette(sorted(index))),
                 render.to_rgb(label_maps(real, index, ev["render"]), render.palette(sorted(index))))
    for name, rs in by_name.items():
        if name != REAL:
            sets[name]["sca"] = _sca(real_maps, render.to_rgb(label_maps(rs, index, ev["render"]),
                                                              render.palette(sorted(index))), sca_settings, threads,
                                     config["seed"])
    if config["source"] == "procedural":  # the generator's own rules: an oracle only for its rooms
        checker = Checker(meshes, box_models, _symmetry(inp.symmetry), {**config["extract"], "floor_contact":
                          config["floor_contact"]}, intersector_class(config["extract"]["backend"]), {})
        for name, rs in by_name.items():
            sets[name]["rules"] = rule_satisfaction(rs, checker)
    fl = floors(train, real, len(gen[0].rooms), ev, config["seed"])
    metrics = _finite({"room_type": room_type, "sets": sets, "floors": fl,
                       "train_nn_similarity": train_similarity(train_maps, ev["similarity_sample"], config["seed"]),
                       "goals": goals(sets, fl), "real_train_rooms": len(train.rooms),
                       "settings": {k: ev[k] for k in ("render", "walk", "collision", "out_of_bounds", "sca", "kl_eps")},
                       "categories": sorted(index)})
    frame = pd.concat(list(rows.values()), ignore_index=True)
    tables.write(out.scenes, "eval_scenes", tables.from_rows("eval_scenes", tables.records(frame)))
    tables.write_csv(out.table, metrics_table(metrics))
    gallery(out.gallery, gen[0], Path(inp.generated_files[0]), real, nodes, edges, ev["gallery"])
    tables.write_json(out.metrics, metrics)
    return metrics


TABLE_COLUMNS = ["scenes", "attempted", "category_kl", "count_distance", "object_collision_rate", "scene_collision_rate",
                 "out_of_bounds_rate", "walkable_share", "reachable_scenes", "consistency", "violation"]


def metrics_table(metrics: dict) -> pd.DataFrame:
    """One row per set (the sampling floors and the training rooms' own similarity as rows of their own)."""
    rows = [{"set": name, **{k: s[k] for k in TABLE_COLUMNS}, "nn_similarity": s["nn_similarity"]["mean"],
             "sca_mean": (s.get("sca") or {}).get("mean"), "sca_sd": (s.get("sca") or {}).get("sd")}
            for name, s in metrics["sets"].items()]
    fl = metrics["floors"]
    rows.append({"set": "floor (real vs real)", "category_kl": fl["category_kl"]["mean"],
                 "count_distance": fl["count_distance"]["mean"]})
    rows.append({"set": "training vs nearest training", "nn_similarity": metrics["train_nn_similarity"]["mean"]})
    frame = pd.DataFrame(rows, columns=["set", *TABLE_COLUMNS, "nn_similarity", "sca_mean", "sca_sd"])
    return frame.astype({"scenes": "Int64", "attempted": "Int64"})


def gallery(folder: Path, gen: RoomSet, gen_folder: Path, real: RoomSet, nodes: Path, edges: Path, count: int) -> None:
    """The first ``count`` placed generated scenes (their instantiation PNG with the planned graph, and GLB) and
    held-out real rooms drawn with their own final graphs, into one folder (written whole, then renamed)."""
    import shutil

    from ..placement.export import plan_figure
    from ..placement.layout import walls_of
    from ..placement.plan import plans_from_tables

    tmp = folder.with_name(folder.name + ".tmp")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    for room in gen.rooms[:count]:
        for ext in ("png", "glb"):
            src = gen_folder / f"{room.room_id}.{ext}"
            if src.exists():
                shutil.copyfile(src, tmp / f"generated_{room.room_id}.{ext}")
    picked = real.rooms[:count]
    flt = [("room_id", "in", [r.room_id for r in picked])]
    plans = {p.scene_id: p for p in plans_from_tables(tables.read(nodes, "final_nodes", filters=flt).to_pandas(),
                                                        tables.read(edges, "final_edges", filters=flt).to_pandas())}
    for room in picked:
        plan_edges = plans[room.room_id].edges if room.room_id in plans else []
        tables.write_figure(tmp / f"real_{room.room_id}.png",
                            plan_figure(room, walls_of(room), plan_edges, f"{room.room_id} (held-out real)"))
    shutil.rmtree(folder, ignore_errors=True)
    tmp.rename(folder)


def _symmetry(path: Path) -> dict:
    return {r["model_id"]: r["symmetry"] for r in tables.read(path, "symmetry", columns=["model_id", "symmetry"]).to_pylist()}


def _sca(real_maps: tuple[np.ndarray, np.ndarray], generated: np.ndarray, cfg: dict, threads: int, seed: int) -> dict:
    import torch

    from ..evaluation.sca import sca

    torch.set_num_threads(max(threads, 1))
    out = sca(real_maps[0], real_maps[1], generated, cfg, seed)
    return {k: (round(v, 3) if isinstance(v, float) else v) for k, v in out.items() if k != "runs"} | {
        "runs": [round(a, 3) for a in out["runs"]]}
