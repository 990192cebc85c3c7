"""Finding what the inspector shows in a run's results: an ingested room (canonical tables, meshes, its final graph
with pruned edges and superstructures) or a generated scene (a method's tables, the graph it was planned from,
and the graph the project's extraction finds in it, with their difference)."""
from __future__ import annotations

import glob
from pathlib import Path

import pandas as pd

from .. import tables
from ..errors import InputError
from ..extraction import extract_room
from ..geometry.raycast import intersector_class
from ..placement.layout import walls_of
from ..room import load_rooms, room_inputs
from . import payload


def _shards(results: Path, pattern: str) -> list[Path]:
    return [Path(p) for p in sorted(glob.glob(str(results / pattern)))]


def _final_graph(nodes: Path | None, edges: Path | None, room_id: str) -> tuple[list[dict], dict[str, str]]:
    """The room's final edges (kept and pruned, with their rules) and its objects' roles; empty without graphs."""
    if edges is None or not Path(edges).exists():
        return [], {}
    flt = [("room_id", "=", room_id)]
    rows = tables.read(edges, "final_edges", filters=flt).to_pandas()
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    return payload.edge_rows(rows), dict(zip(node_df["node_id"].astype(str), node_df["role"].astype(str)))


def corpus_room(shards: dict[str, list[Path]], graphs: tuple[Path, Path] | None, room_id: str, where: str,
                title: str | None = None) -> dict:
    """The viewer's payload of a corpus room: ``shards`` maps rooms, architecture, objects and models to their shard
    files; ``graphs``: the final nodes and edges (its graph, where there is one)."""
    _, _, objs, inputs = load_rooms(shards["rooms"], shards["architecture"], shards["objects"], {room_id})
    if room_id not in inputs:
        raise InputError(f"{where}: no room '{room_id}'")
    room = inputs[room_id]
    meshes, box_models = tables.read_meshes_of(shards["models"], objs["model_id"].dropna())
    edges, roles = _final_graph(*(graphs or (None, None)), room_id)
    return payload.room_payload(title or f"{room_id} ({room.room_type})", room, walls_of(room), meshes.get,
                                {"final": edges} if edges else {}, roles, box_models)


def ingested_room(results: Path, room_id: str) -> dict:
    """The viewer's payload of an ingested room of a run's ``results`` (its final graph where the run has one)."""
    shards = {t: _shards(results, f"ingest/shards/{t}-*.parquet") for t in ("rooms", "architecture", "objects", "models")}
    if not shards["rooms"]:
        raise InputError(f"{results}/ingest/shards: no ingested rooms (run the pipeline first, or pass --results)")
    graphs = results / "graphs" / "ingested"
    return corpus_room(shards, (graphs / "nodes.parquet", graphs / "edges.parquet"), room_id,
                       f"{results}/ingest/shards/rooms-*.parquet")


def _scene_id(scenes: pd.DataFrame, scene: str, folder: Path) -> str:
    """A scene id given as itself or as its index among the folder's scored scenes."""
    ids = scenes.loc[scenes["status"].astype(str).isin(tables.SCORED), "scene_id"].astype(str).tolist()
    if scene in ids:
        return scene
    if scene.isdigit() and int(scene) < len(ids):
        return ids[int(scene)]
    raise InputError(f"{folder}/scenes.parquet: no placed scene '{scene}' ({len(ids)} placed: 0..{len(ids) - 1} or "
                     f"their ids, e.g. {ids[0] if ids else 'none'})")


def generated_room(folder: Path, scene: str, planned: tuple[Path, Path] | None, extract_cfg: dict) -> dict:
    """The viewer's payload of one generated scene of a method's folder: the planned graph (``planned``: the graph
    generator's sampled nodes and edges, when the method places one), the graph extraction finds in the placed room,
    and their difference."""
    need = [folder / f"{t}.parquet" for t in ("rooms", "architecture", "objects", "models", "scenes")]
    missing = [p for p in need if not p.exists()]
    if missing:
        raise InputError(f"{missing[0]}: not found ({folder} is not a generated method's folder)")
    scenes = tables.read(need[4], "scenes").to_pandas()
    sid = _scene_id(scenes, scene, folder)
    origin = scenes.set_index("scene_id").at[sid, "origin_id"]
    flt = [("room_id", "=", sid)]
    rooms, arch = (tables.read(p, s, filters=flt).to_pandas() for p, s in zip(need[:2], ("rooms", "architecture")))
    objs = tables.read(need[2], "generated_objects", filters=flt).to_pandas()
    room = next(room_inputs(rooms, arch, objs))
    meshes, box_models = tables.read_meshes_of([need[3]], objs["model_id"].dropna())
    found = extract_room(room, meshes.get, lambda c, m: ("none", "table"), extract_cfg,
                         intersector_class(extract_cfg["backend"]), box_models)
    extracted = [e for e in payload.edge_rows(pd.DataFrame(found.edges)) if e["edge_type"] in ("support", "spatial")]
    graphs = {"extracted": extracted}
    if planned is not None:
        edges = tables.read(planned[1], "generated_edges", filters=[("scene_id", "=", origin)]).to_pandas()
        plan = [e for e in payload.edge_rows(edges) if e["edge_type"] in ("support", "spatial")]
        placed = set(room.object_ids) | set(room.wall_ids)
        graphs = {"difference": payload.difference(plan, extracted, placed), "planned": plan, **graphs}
    walls = walls_of(room)
    return payload.room_payload(f"{sid} ({folder.parent.name}, {folder.name})", room, walls, meshes.get, graphs,
                                None, box_models)
