"""Instantiate graphs of one room type into rooms (one job per room type and variant): sampled graphs, or the
held-out rooms' own final graphs (Table 3's ablations), placed by the search with the trained networks. Writes the
generated rooms as canonical tables (every stage reads them unchanged), one record per scene (failed ones included,
with their reason), and per scene a GLB, a top-down PNG with the planned graph, and a JSON summary."""
from __future__ import annotations

import json
import logging
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .. import tables
from ..errors import InputError
from ..geometry.raycast import intersector_class
from ..log import progress
from ..placement import export, order, proposers, scene_metrics
from ..placement.checks import Checker, checks_config
from ..placement.layout import walls_of, with_objects
from ..placement.plan import ScenePlan, plans_from_tables
from ..placement.retrieval import Catalog
from ..placement.search import SCORED, instantiate
from ..room import load_rooms
from ..stage import Files

log = logging.getLogger("planit.instantiate")


@dataclass
class Context:
    """Everything the scenes of one room type share."""
    room_type: str
    rooms: pd.DataFrame  # canonical rows of the source rooms
    architecture: pd.DataFrame
    objects: pd.DataFrame  # the corpus's objects of the room type
    inputs: dict  # room id -> RoomInput (with its real objects)
    catalog: Catalog
    checker: Checker
    mean_area: dict
    heldout_ids: list[str]
    models: list[Path]


def load_context(config: dict, room_type: str, saved, rooms: list[Path], architecture: list[Path],
                 objects: list[Path], models: list[Path], symmetry: Path, category_sizes: Path) -> Context:
    room_df, arch, objs, inputs = load_rooms(rooms, architecture, objects)
    keep = room_df["room_type"].astype(str) == room_type
    room_df = room_df[keep]
    objs = objs[objs["room_id"].isin(set(room_df["room_id"]))]
    held = set(saved.record["heldout_ids"])
    sym_rows = tables.read(symmetry, "symmetry", columns=["model_id", "symmetry"]).to_pylist()
    sym = {r["model_id"]: r["symmetry"] for r in sym_rows}
    meshes, box_models = tables.read_meshes_of(models, objs["model_id"].dropna())
    sizes = tables.read(category_sizes, "category_sizes").to_pandas()
    sizes = sizes[sizes["room_type"].astype(str) == room_type]
    ext = {**config["extract"], "floor_contact": config["floor_contact"]}
    checker = Checker(meshes, box_models, sym, ext, intersector_class(ext["backend"]), checks_config(config))
    return Context(room_type, room_df, arch[arch["room_id"].isin(set(room_df["room_id"]))], objs,
                   {k: v for k, v in inputs.items() if k in set(room_df["room_id"])},
                   Catalog(objs[~objs["room_id"].isin(held)], sym, config["floor_contact"]), checker,
                   dict(zip(sizes["category"].astype(str), sizes["mean_area"])), list(saved.record["heldout_ids"]), models)


def make_proposer(location: str, saved: dict, cfg: dict):
    """The variant's proposer: network densities (weighted by the relation bands when ``relation_mask``), uniform or
    rule-band locations; orientations from the network. ``cfg``: the instantiate section."""
    from ..methods.planit.nets.proposer import NetProposer

    nets = NetProposer(saved, cfg["density_cache"], film=location == "cfcn")
    if location in ("cfcn", "fcn"):
        bands = proposers.RelationPrior(soft=cfg["band_softness"])
        return proposers.Masked(nets, bands) if cfg["relation_mask"] else nets
    return proposers.Combined(proposers.UniformLocation() if location == "random" else proposers.RelationPrior(), nets)


def place_scene(plan: ScenePlan, ctx: Context, proposer, cfg: dict, variant: dict, seed: int, keep: int = 0):
    """Search one scene. ``keep``: the first objects of the constraint order stay where the source room has them
    (completion of a real room)."""
    source = ctx.inputs.get(plan.room_id)
    if source is None:
        raise InputError(f"scene {plan.scene_id}: its room {plan.room_id} is not among the kept rooms of {ctx.room_type}")
    rng = np.random.default_rng(seed)
    seq = order.placement_order(plan, ctx.mean_area, variant["ordering"] == "constraint", rng)
    fixed = [plan.ids[k] for k in seq[:keep]]
    start = with_objects(source, [source.object_ids.index(o) for o in fixed if o in source.object_ids])
    walls = walls_of(start)
    return instantiate(plan, start, walls, seq[keep:], proposer, ctx.catalog, ctx.checker, cfg, seed), walls


def scene_rows(plan: ScenePlan, ctx: Context, outcome, walls, variant_name: str) -> tuple[dict, list[dict], list[dict], dict]:
    """The scene's record and its rooms / architecture / objects rows (its room id is the scene id)."""
    room = outcome.room
    metrics = scene_metrics.consistency(plan, room, walls.ids, ctx.checker, outcome.dropped)
    parents = dict(zip(plan.ids, plan.parent))
    record = {"scene_id": plan.scene_id, "room_type": ctx.room_type, "variant": variant_name, "source_room_id": plan.room_id,
              "status": outcome.status, "reason": outcome.reason, "seconds": outcome.seconds,
              "planned_objects": len(plan.ids), "placed_objects": len(room.object_ids), "insertions": outcome.insertions,
              "rejections": outcome.rejections, "backtracks": outcome.backtracks, "attempts": outcome.attempts,
              "failures": json.dumps(outcome.failures),
              **metrics, "colliding_objects": scene_metrics.colliding_objects(room, parents, ctx.checker)}
    src = tables.records(ctx.rooms[ctx.rooms["room_id"] == plan.room_id])[0]
    room_row = {**src, "room_id": plan.scene_id, "n_objects": len(room.object_ids), "shard": 0}
    arch = tables.records(ctx.architecture[ctx.architecture["room_id"] == plan.room_id].assign(room_id=plan.scene_id))
    objs = [{"room_id": plan.scene_id, "scene_id": plan.scene_id, "object_id": o, "category": c, "model_id": m,
             **dict(zip(["cx", "cy", "cz", "hx", "hy", "hz", "yaw"], map(float, b))),
             **dict(zip(["px", "py", "pz", "_yaw", "sx", "sy", "sz"], map(float, p))), "source_parent_id": parents.get(o)}
            for o, c, m, b, p in zip(room.object_ids, room.categories, room.model_ids, room.boxes, room.poses)]
    return record, [room_row], arch, objs



def write_scene_files(folder: Path, plan: ScenePlan, ctx: Context, outcome, walls, record: dict) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    export.write_glb(folder / f"{plan.scene_id}.glb", outcome.room, walls, ctx.checker.meshes.get)
    title = f"{plan.scene_id} ({record['status']}, consistency {record['consistency']:.2f})"
    tables.write_figure(folder / f"{plan.scene_id}.png", export.plan_figure(outcome.room, walls, plan.edges, title))
    tables.write_json(folder / f"{plan.scene_id}.json", record)


def select_plans(config: dict, variant: dict, ctx: Context, nodes: Path, edges: Path, count: int) -> list[ScenePlan]:
    flt = [("room_type", "=", ctx.room_type)]
    if variant["graphs"] == "sampled":
        node_df = tables.read(nodes, "generated_nodes", filters=flt).to_pandas()
        edge_df = tables.read(edges, "generated_edges", filters=flt).to_pandas()
    else:
        held = [("room_id", "in", ctx.heldout_ids)]
        node_df = tables.read(nodes, "final_nodes", filters=flt + held).to_pandas()
        edge_df = tables.read(edges, "final_edges", filters=flt + held).to_pandas()
    return plans_from_tables(node_df, edge_df, variant["pruning"], config["seed"], limit=count)


def scene_count(ic: dict, variant: dict) -> int:
    """Scenes a variant places: ``scenes`` for sampled graphs, ``table3_scenes`` for held-out ones, capped by the
    variant's own ``scenes`` (``ic``: the ``instantiate`` config section)."""
    n = ic["scenes"] if variant["graphs"] == "sampled" else ic["table3_scenes"]
    return min(n, variant.get("scenes", n))


def run(config: dict, inp: Files, out: Files, room_type: str, variant: str, count: int | None = None,
        threads: int = 1) -> dict:
    """Place ``count`` scenes (default ``instantiate.scenes`` for sampled graphs, ``table3_scenes`` for held-out ones,
    at most the variant's own ``scenes``) with
    ``threads`` CPU threads for the networks (more than the job's cores oversubscribe them: 4x slower)."""
    import torch

    variant_name = variant
    torch.set_num_threads(threads)
    ic = config["instantiate"]
    if variant_name not in ic["variants"]:
        raise InputError(f"--variant: '{variant_name}' is not in instantiate.variants ({', '.join(ic['variants'])})")
    variant = ic["variants"][variant_name]
    from ..learning import checkpoint
    from ..methods.planit.nets.train import KIND

    saved = checkpoint.load(inp.model, KIND)
    ctx = load_context(config, room_type, saved, inp.rooms, inp.architecture, inp.objects, inp.models, inp.symmetry,
                       inp.category_sizes)
    n = count or scene_count(ic, variant)
    plans = select_plans(config, variant, ctx, inp.nodes, inp.edges, n)
    if not plans:
        log.warning("%s: no graph of room type '%s' to instantiate: writing empty tables", inp.nodes, room_type)
    proposer = make_proposer(variant["location"], saved, config["instantiate"])
    return write_outputs(config, ctx, plans, proposer, variant, variant_name, out)


def write_outputs(config: dict, ctx: Context, plans: list[ScenePlan], proposer, variant: dict, variant_name: str,
                  out: Files, keep: int = 0) -> dict:
    records, room_rows, arch_rows, obj_rows = [], [], [], []
    for plan in progress(plans, total=len(plans), desc=f"instantiate {ctx.room_type} ({variant_name})"):
        seed = zlib.crc32(f"{config['seed']}/{variant_name}/{plan.scene_id}".encode())
        outcome, walls = place_scene(plan, ctx, proposer, config["instantiate"], variant, seed, keep)
        record, r, a, o = scene_rows(plan, ctx, outcome, walls, variant_name)
        if outcome.status != "placed":
            log.warning("scene %s %s: %s", plan.scene_id, outcome.status, outcome.reason)
        write_scene_files(out.files, plan, ctx, outcome, walls, record)
        records.append(record)
        room_rows += r
        arch_rows += a
        obj_rows += o
    objs = pd.DataFrame(obj_rows, columns=[*tables.SCHEMAS["generated_objects"].names, "_yaw"]).drop(columns="_yaw")
    used = set(objs["model_id"])
    tables.write(out.rooms, "rooms", tables.from_rows("rooms", room_rows))
    tables.write(out.architecture, "architecture", tables.from_rows("architecture", arch_rows))
    tables.write(out.objects, "generated_objects", tables.from_rows("generated_objects", tables.records(objs)))
    model_rows = pd.concat([tables.read(p, "models", filters=[("model_id", "in", sorted(used))]).to_pandas()
                            for p in (ctx.models if used else [])] + [tables.empty("models").to_pandas()])
    tables.write(out.models, "models", tables.from_rows("models", tables.records(model_rows.drop_duplicates("model_id"))))
    Path(out.files).mkdir(parents=True, exist_ok=True)
    scenes = pd.DataFrame(records, columns=tables.SCHEMAS["scenes"].names)
    tables.write(out.scenes, "scenes", tables.from_rows("scenes", records))
    summary = summarise(scenes)
    tables.write_json(out.summary, {"room_type": ctx.room_type, "variant": variant_name, **variant, **summary})
    return summary


def summarise(scenes: pd.DataFrame) -> dict:
    """Table 3's figures over a variant's scenes (violation and consistency over the placed and partial ones)."""
    if scenes.empty:
        return {"scenes": 0, "placed": 0, "partial": 0, "failed": 0}
    scored = scenes["status"].isin(SCORED)
    return {"scenes": int(len(scenes)), "placed": int((scenes["status"] == "placed").sum()),
            "partial": int((scenes["status"] == "partial").sum()), "failed": int((~scored).sum()),
            "restarted": int((scenes["attempts"] > 1).sum()),
            "rejections_per_scene": round(float(scenes["rejections"].mean()), 3),
            "backtracks_per_insertion": round(float(scenes["backtracks"].sum() / max(scenes["insertions"].sum(), 1)), 4),
            "violation": round(float(scenes.loc[scored, "violation"].mean()), 4) if scored.any() else None,
            "consistency": round(float(scenes.loc[scored, "consistency"].mean()), 4) if scored.any() else None,
            "collision_rate": round(float(scenes["colliding_objects"].sum() / max(scenes["placed_objects"].sum(), 1)), 4),
            "median_seconds": round(float(scenes["seconds"].median()), 3),
            "unplanned_adjacent_per_scene": round(float(scenes["unplanned_adjacent"].mean()), 3)}
