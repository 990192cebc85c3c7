"""Generated rooms as canonical tables (every stage reads them unchanged), one record per scene (failed ones
included, with their reason), and per scene a GLB, a top-down PNG with the planned graph and a JSON summary (entries
of one zip archive, ``scenes.zip``): the one writer of every method's rooms. The canonical tables hold the scored
scenes only (placed, or partial with what they dropped named in their record): a failed scene's unfinished room is
kept in its archive entries alone, so no reader of the tables can take it for a room."""
from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from .. import tables
from ..corpus.rows import room_row, wall_rows
from ..errors import InputError
from ..placement import export
from ..room import BOX_COLUMNS
from ..tables import SCORED
from .interface import Corpus, Scene

log = logging.getLogger("planit.generate")


@dataclass
class Rows:
    """The tables of a method's scenes, gathered scene by scene."""
    records: list[dict] = field(default_factory=list)
    rooms: list[dict] = field(default_factory=list)
    architecture: list[dict] = field(default_factory=list)
    objects: list[dict] = field(default_factory=list)

    def add(self, scene: Scene, corpus: Corpus, method: str) -> dict:
        """Add one scene's record and, when it is scored, its canonical rows (its room id is the scene id); returns
        its record."""
        room = scene.room
        record = {"scene_id": scene.scene_id, "room_type": corpus.room_type, "variant": method,
                  "source_room_id": scene.source_room_id, "status": scene.status, "reason": scene.reason,
                  "planned_objects": len(room.object_ids), "placed_objects": len(room.object_ids), **scene.record}
        self.records.append(record)
        if scene.status not in SCORED:
            return record
        if scene.own_architecture:
            self._add_own_architecture(scene, corpus)
        else:
            src = tables.records(corpus.rooms[corpus.rooms["room_id"] == scene.source_room_id])[0]
            self.rooms.append({**src, "room_id": scene.scene_id, "n_objects": len(room.object_ids), "shard": 0})
            arch = corpus.architecture[corpus.architecture["room_id"] == scene.source_room_id]
            self.architecture += tables.records(arch.assign(room_id=scene.scene_id))
        self.objects += [{"room_id": scene.scene_id, "scene_id": scene.scene_id, "object_id": o, "category": c,
                          "model_id": m, **dict(zip(BOX_COLUMNS, map(float, b))),
                          **dict(zip(["px", "py", "pz", "_yaw", "sx", "sy", "sz"], map(float, p))),
                          "source_parent_id": scene.parents.get(o)}
                         for o, c, m, b, p in zip(room.object_ids, room.categories, room.model_ids, room.boxes,
                                                  room.poses)]
        return record

    def _add_own_architecture(self, scene: Scene, corpus: Corpus) -> None:
        """The rooms row and wall rows of a scene whose method decoded its own walls (``scene.room``'s outline)."""
        room = scene.room
        source = str(corpus.rooms["source"].iloc[0]) if len(corpus.rooms) else "generated"
        self.rooms.append(room_row(scene.scene_id, source, (corpus.room_type, corpus.room_type), room.outline,
                                   room.height, len(room.object_ids), shard=0))
        self.architecture += wall_rows(scene.scene_id, room.outline, room.height,
                                       float(np.median(room.wall_thickness)))


def write_scene_files(archive: tables.Archive, scene: Scene, record: dict, mesh_of) -> None:
    """The scene's GLB, top-down PNG (with its planned graph) and JSON record, as entries of the method's archive."""
    archive.add(f"{scene.scene_id}.glb", export.glb(scene.room, scene.walls, mesh_of))
    consistency = record.get("consistency")
    title = f"{scene.scene_id} ({record['status']}" + (
        f", consistency {consistency:.2f})" if consistency is not None else ")")
    archive.add_figure(f"{scene.scene_id}.png", export.plan_figure(scene.room, scene.walls, scene.edges, title))
    archive.add_json(f"{scene.scene_id}.json", record)


def write_tables(rows: Rows, corpus: Corpus, out) -> pd.DataFrame:
    """The canonical tables, the scenes table and the used models (``out``: rooms, architecture, objects, models,
    scenes); returns the scenes as a frame."""
    objs = pd.DataFrame(rows.objects, columns=[*tables.SCHEMAS["generated_objects"].names, "_yaw"]).drop(columns="_yaw")
    used = set(objs["model_id"])
    tables.write(out.rooms, "rooms", tables.from_rows("rooms", rows.rooms))
    tables.write(out.architecture, "architecture", tables.from_rows("architecture", rows.architecture))
    tables.write(out.objects, "generated_objects", tables.from_rows("generated_objects", tables.records(objs)))
    model_rows = pd.concat([tables.read(p, "models", filters=[("model_id", "in", sorted(used))]).to_pandas()
                            for p in (corpus.models if used else [])] + [tables.empty("models").to_pandas()])
    tables.write(out.models, "models", tables.from_rows("models", tables.records(model_rows.drop_duplicates("model_id"))))
    tables.write(out.scenes, "scenes", tables.from_rows("scenes", rows.records))
    return pd.DataFrame(rows.records, columns=tables.SCHEMAS["scenes"].names)


def summarise(scenes: pd.DataFrame) -> dict:
    """Table 3's figures over a method's scenes (violation and consistency over the placed and partial ones)."""
    if scenes.empty:
        return {"scenes": 0, "placed": 0, "partial": 0, "failed": 0}
    scored = scenes["status"].isin(SCORED)
    mean = lambda col: round(float(scenes.loc[scored, col].mean()), 4) if scored.any() and scenes[col].notna().any() else None
    total = lambda col: scenes[col].fillna(0).sum()
    return {"scenes": int(len(scenes)), "placed": int((scenes["status"] == "placed").sum()),
            "partial": int((scenes["status"] == "partial").sum()), "failed": int((~scored).sum()),
            "restarted": int((scenes["attempts"].fillna(1) > 1).sum()),
            "rejections_per_scene": _round(scenes["rejections"].mean(), 3),
            "backtracks_per_insertion": _round(total("backtracks") / max(total("insertions"), 1), 4),
            "violation": mean("violation"), "consistency": mean("consistency"),
            "collision_rate": _round(total("colliding_objects") / max(total("placed_objects"), 1), 4),
            "median_seconds": _round(scenes["seconds"].median(), 3),
            "unplanned_adjacent_per_scene": _round(scenes["unplanned_adjacent"].mean(), 3),
            "relaxed_share": relaxed_share(scenes[scored]), "relaxed": relaxed(scenes.loc[scored, "relaxed"]),
            "plan_loss": plan_loss(scenes.loc[scored, "plan_loss"]), "drops": drops(scenes.loc[scored, "drops"])}


def plan_loss(rows: pd.Series) -> dict:
    """Relation -> planned edges over the scenes' ``plan_loss`` JSON rows and each cause's share of them."""
    total: dict = {}
    for row in rows.dropna():
        for relation, counts in json.loads(row).items():
            acc = total.setdefault(relation, {})
            for k, n in counts.items():
                acc[k] = acc.get(k, 0) + n
    return {r: {"planned": c["planned"], **{k: round(n / c["planned"], 4) for k, n in c.items() if k != "planned"}}
            for r, c in sorted(total.items())}


def drops(rows: pd.Series) -> dict:
    """Category -> cause (``no_place:<check>`` for an object no candidate of which passed) -> objects left out,
    over the scenes' ``drops`` JSON rows."""
    total: dict = {}
    for row in rows.dropna():
        for d in json.loads(row):
            cause = f"{d['cause']}:{d['check']}" if d.get("check") else d["cause"]
            acc = total.setdefault(d["category"], {})
            acc[cause] = acc.get(cause, 0) + 1
    return {c: dict(sorted(v.items())) for c, v in sorted(total.items())}


def relaxed_share(scenes: pd.DataFrame):
    """Share of the placed objects kept with a broken planned relation (None where no scene records it)."""
    if scenes.empty or scenes["relaxed_objects"].isna().all():
        return None
    return _round(scenes["relaxed_objects"].fillna(0).sum() / max(scenes["placed_objects"].sum(), 1), 4)


def relaxed(rows: pd.Series) -> dict:
    """Category -> cause (the check that refused the object most before it was kept broken) -> objects, over the
    scenes' ``relaxed`` JSON rows."""
    total: dict = {}
    for row in rows.dropna():
        for r in json.loads(row):
            acc = total.setdefault(r["category"], {})
            acc[str(r["cause"])] = acc.get(str(r["cause"]), 0) + 1
    return {c: dict(sorted(v.items())) for c, v in sorted(total.items())}


def _round(value, digits: int):
    return None if pd.isna(value) else round(float(value), digits)


def named(scene: Scene, method: str, corpus: Corpus) -> Scene:
    """The scene under its id in the method's tables: the method's name first (no two methods' rooms share an id),
    its origin (the sampled graph it placed, the reference scene it retrieved for) kept as ``origin_id``."""
    sid = scene.scene_id if scene.scene_id.startswith(f"{method}_") else f"{method}_{scene.scene_id}"
    if sid in corpus.inputs:
        raise InputError(f"generated scene id '{sid}' is the id of a {corpus.room_type} room of the corpus")
    return replace(scene, scene_id=sid, record={"origin_id": scene.scene_id, **scene.record})


def write_generated(scenes, corpus: Corpus, method: str, out, meshes: dict, desc: str = "") -> dict:
    """Write every scene of ``scenes`` (an iterator, consumed here) and the method's tables; returns the summary
    (``out``: rooms, architecture, objects, models, scenes, summary, archive)."""
    rows = Rows()
    with tables.write_archive(out.archive) as archive:
        for scene in scenes:
            scene = named(scene, method, corpus)
            record = rows.add(scene, corpus, method)
            if scene.status != "placed":
                log.warning("scene %s %s: %s", scene.scene_id, scene.status, scene.reason)
            write_scene_files(archive, scene, record, meshes.get)
    frame = write_tables(rows, corpus, out)
    return summarise(frame)


def generate_rooms(layout, name: str, task, out) -> dict:
    """Run a layout generator on a task and write everything (``out``: the generated tables, ``summary``, ``archive``):
    what the ``generate`` and ``instantiate`` stages share."""
    summary = write_generated(layout.generate(task), task.corpus, name, out, task.corpus.meshes)
    tables.write_json(out.summary, {"room_type": task.corpus.room_type, "variant": name, **layout.info, **summary})
    return summary
