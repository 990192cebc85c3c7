"""Canonical Parquet tables: every schema defined once, written atomically with metadata.

Conventions for every table (docs/data-model.md): metres, radians, right-handed world frame with Z up;
an object's local frame has +Y as its front, +X as its right, and ``yaw`` rotates local to world
counter-clockwise about +Z.
"""
from __future__ import annotations

import io
import json
import os
import tempfile
import zipfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Iterator

import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from . import __version__
from .errors import PlanitError

COORDINATES = "metres; right-handed, Z up; object front = local +Y, right = local +X; yaw CCW about +Z (rad)"

_STR = pa.string()
_CAT = pa.dictionary(pa.int32(), pa.string())
_F64 = pa.float64()
_I32 = pa.int32()


_UMASK = os.umask(0)
os.umask(_UMASK)


class TableError(PlanitError):
    """A table file is unreadable or lacks a field; the message names the file and field."""


def _f(name: str, type_: pa.DataType, unit: str | None = None, doc: str = "", nullable: bool = True) -> pa.Field:
    meta = {"doc": doc}
    if unit:
        meta["unit"] = unit
    return pa.field(name, type_, nullable=nullable, metadata=meta)


def _box_fields() -> list[pa.Field]:
    return [
        _f("cx", _F64, "m", "oriented box centre, world x"),
        _f("cy", _F64, "m", "oriented box centre, world y"),
        _f("cz", _F64, "m", "oriented box centre, world z"),
        _f("hx", _F64, "m", "half extent along local x (right)"),
        _f("hy", _F64, "m", "half extent along local y (front)"),
        _f("hz", _F64, "m", "half extent along z"),
        _f("yaw", _F64, "rad", "rotation local->world about +Z, counter-clockwise"),
    ]


SCHEMAS: dict[str, pa.Schema] = {
    "rooms": pa.schema([
        _f("room_id", _STR, doc="unique room id", nullable=False),
        _f("source", _CAT, doc="procedural | front3d | ithor | suncg"),
        _f("room_type", _CAT, doc="canonical room type"),
        _f("source_room_type", _STR, doc="room label as the source gave it"),
        _f("floor_x", pa.list_(_F64), "m", "floor outline x, counter-clockwise, not repeated at the end"),
        _f("floor_y", pa.list_(_F64), "m", "floor outline y"),
        _f("height", _F64, "m", "floor to ceiling"),
        _f("floor_area", _F64, "m^2", "area of the floor outline"),
        _f("extent_x", _F64, "m", "axis-aligned floor extent along x"),
        _f("extent_y", _F64, "m", "axis-aligned floor extent along y"),
        _f("n_objects", _I32, doc="objects in the room at ingest"),
        _f("shard", _I32, doc="shard index, assigned by the filter stage (null before)"),
    ]),
    "architecture": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("element_id", _STR, doc="unique within the room: wall_<i>, door_<i>, window_<i>", nullable=False),
        _f("kind", _CAT, doc="wall | door | window"),
        _f("x0", _F64, "m", "segment start (walls: on the inner face, loop counter-clockwise)"),
        _f("y0", _F64, "m"),
        _f("x1", _F64, "m", "segment end"),
        _f("y1", _F64, "m"),
        _f("z0", _F64, "m", "bottom"),
        _f("z1", _F64, "m", "top"),
        _f("thickness", _F64, "m", "walls: thickness behind the inner face"),
        _f("wall_id", _STR, doc="doors and windows: the wall they sit in"),
    ]),
    "objects": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("object_id", _STR, doc="unique within the room", nullable=False),
        _f("category", _CAT),
        _f("model_id", _STR),
        *_box_fields(),
        _f("px", _F64, "m", "model origin, world x: world = Rz(yaw) (s * v) + p"),
        _f("py", _F64, "m"),
        _f("pz", _F64, "m"),
        _f("sx", _F64, doc="model scale along local x (negative = mirrored)"),
        _f("sy", _F64, doc="model scale along local y"),
        _f("sz", _F64, doc="model scale along z"),
        _f("source_parent_id", _STR, doc="support parent when the source records one"),
    ]),
    "models": pa.schema([
        _f("model_id", _STR, nullable=False),
        _f("category", _CAT),
        _f("source", _CAT),
        _f("vertices", pa.list_(pa.float32()), "m", "model-space vertices, flattened (n*3), front = +Y, Z up"),
        _f("faces", pa.list_(_I32), doc="triangles, flattened (m*3) vertex indices"),
        _f("mesh_kind", _CAT, doc="mesh | box_fallback"),
        _f("mesh_path", _STR, doc="where the mesh came from, if a file"),
        _f("min_x", _F64, "m"), _f("min_y", _F64, "m"), _f("min_z", _F64, "m"),
        _f("max_x", _F64, "m"), _f("max_y", _F64, "m"), _f("max_z", _F64, "m"),
    ]),
    "ground_truth": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("relation", _CAT, doc="support | adjacent | hub | chain | faces | defect"),
        _f("anchor_id", _STR, doc="parent / anchor / hub / chain start (object or element id)"),
        _f("target_id", _STR, doc="child / target / spoke / chain member"),
        _f("direction", _CAT, doc="front | back | left | right in the anchor's frame, when intended"),
        _f("group_id", _STR, doc="hub or chain group"),
        _f("label", _STR, doc="defect: the filter rule meant to reject the room; chain: adjacent | proximal"),
    ]),
    "filter_report": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("room_type", _CAT),
        _f("status", _CAT, doc="kept | rejected"),
        _f("rule", _CAT, doc="first rule that rejected the room (rule order in docs)"),
        _f("rules", pa.list_(_STR), doc="every rule the room fails"),
        _f("detail", _STR, doc="human-readable reason"),
        _f("shard", _I32),
    ]),
    "ingest_report": pa.schema([
        _f("source", _CAT),
        _f("item", _STR, doc="house / room / object / model the row is about"),
        _f("kind", _CAT, doc="house | room | wall | object | model | category"),
        _f("status", _CAT, doc="read | skipped | kept | dropped | fallback | found | backed | open | renamed | uid (item: a house uid "
                               "read, reason: its file) | duplicate uid"),
        _f("reason", _STR),
        _f("count", pa.int64()),
    ]),
    "drops": pa.schema([
        _f("source", _CAT),
        _f("file", _STR, doc="the source file"),
        _f("house_id", _STR, doc="house uid, where the source has houses"),
        _f("room_id", _STR, doc="the room (for rooms, objects: the id it would have had)"),
        _f("item_id", _STR, doc="object: furniture uid / object id; model: model id; mesh: mesh uid"),
        _f("level", _CAT, doc="house | room | object | model | mesh"),
        _f("status", _CAT, doc="dropped | skipped | fallback (a model replaced by its box) | kept (a mesh kept after a fix)"),
        _f("field", _STR, doc="JSON path of the field at fault, e.g. scene.room[2].children[5].pos"),
        _f("reason", _STR),
    ]),
    "symmetry": pa.schema([
        _f("model_id", _STR, nullable=False),
        _f("category", _CAT),
        _f("detected", _CAT, doc="symmetry type detected from the mesh (null when detection is off)"),
        _f("table", _CAT, doc="symmetry type from the config table for the category (null: no entry)"),
        _f("symmetry", _CAT, doc="the type used: the table's where it has an entry, else the detected one"),
        _f("origin", _CAT, doc="table | detected | default"),
    ]),
    "nodes": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("node_id", _STR, nullable=False, doc="object_id or architecture element_id"),
        _f("kind", _CAT, doc="object | wall | door | window"),
        _f("category", _CAT, doc="object category; 'wall', 'door', 'window' for architecture"),
        _f("model_id", _STR),
        _f("symmetry", _CAT, doc="functional symmetry type"),
        _f("symmetry_origin", _CAT, doc="table | detected | architecture"),
        _f("tier", _I32, doc="0 architecture, 1 on the floor, 2 supported by a tier-1 object, ...; -1 hanging"),
        _f("parent_id", _STR, doc="support parent (null: floor)"),
        *_box_fields(),
        _f("length", _F64, "m", "walls, doors, windows: segment length"),
        _f("room_type", _CAT),
        _f("shard", _I32),
    ]),
    "edges": pa.schema([
        _f("room_id", _STR, nullable=False),
        _f("source", _STR, nullable=False, doc="anchor node"),
        _f("target", _STR, nullable=False, doc="target node"),
        _f("edge_type", _CAT, doc="support | spatial | wall_adjacent | wall_opposite | opening"),
        _f("direction", _CAT, doc="front | back | left | right in the anchor's frame (null: support)"),
        _f("distance", _CAT, doc="adjacent | proximal | distant (null: support)"),
        _f("gap", _F64, "m", "smallest gap along the anchor's rays (negative: overlap)"),
        _f("target_visibility", _F64, doc="visible share of the target's projected interval"),
        _f("anchor_visibility", _F64, doc="share of the anchor side that sees the target"),
        _f("score_front", _F64, doc="visibility from the front side (max of the two shares)"),
        _f("score_back", _F64),
        _f("score_left", _F64),
        _f("score_right", _F64),
        _f("angle", _F64, "rad", "wall -> wall: interior angle at the shared corner"),
        _f("support_area", _F64, "m^2", "support: area of the grid cells resting on the parent"),
        _f("room_type", _CAT),
        _f("shard", _I32),
    ]),
}

# refinement adds columns to the raw graph tables
SCHEMAS["final_nodes"] = pa.schema([*SCHEMAS["nodes"], _f("role", _CAT, doc="hub | spoke | chain_start | chain_member | chain_end | none "
                                                                    "(chain roles may combine with hub roles: 'hub+chain_start')"),
                                    _f("group_id", _STR, doc="the hub or chain the node belongs to")])
SCHEMAS["final_edges"] = pa.schema([*SCHEMAS["edges"],
                                    _f("status", _CAT, doc="kept | pruned"),
                                    _f("rule", _CAT, doc="the rule that kept or pruned the edge (docs/data-model.md lists them)"),
                                    _f("origin", _CAT, doc="raw (extracted) | derived (added by hub/chain inheritance or connectivity)"),
                                    _f("group_id", _STR, doc="hub or chain whose edge this is")])
_GENERATED = [_f("scene_id", _STR, doc="generated scene (= room_id)"),
              _f("source_room_id", _STR, doc="the held-out room whose architecture the scene grew from"),
              _f("sample_seed", pa.int64(), doc="seed of the sampling batch")]
SCHEMAS["generated_nodes"] = pa.schema([*SCHEMAS["final_nodes"], *_GENERATED])
SCHEMAS["generated_edges"] = pa.schema([*SCHEMAS["final_edges"], *_GENERATED])
SCHEMAS["generated_objects"] = pa.schema([*SCHEMAS["objects"], _f("scene_id", _STR, doc="generated scene (= room_id)")])
SCORED = ("placed", "partial")  # the scene statuses that hold a room to score (a partial one lacks what it dropped)
SCHEMAS["scenes"] = pa.schema([
    _f("scene_id", _STR, nullable=False), _f("room_type", _CAT), _f("variant", _CAT, doc="instantiate.variants key"),
    _f("origin_id", _STR, doc="what the scene grew from: the sampled graph it placed (its scene_id in the graph "
       "generator's tables), or the reference scene it stands for (retrieval); the scene's id is the method's name "
       "and this"),
    _f("source_room_id", _STR, doc="the room whose architecture (and, for held-out graphs, graph) the scene uses"),
    _f("status", _CAT, doc="placed | partial (objects dropped: instantiate.on_exhausted) | failed"),
    _f("reason", _STR, doc="why the search failed, or which objects a partial scene dropped"),
    _f("seconds", _F64, "s"), _f("planned_objects", _I32), _f("placed_objects", _I32),
    _f("insertions", _I32, doc="accepted placements, those undone by backtracking included"),
    _f("rejections", _I32, doc="candidates that failed a check"), _f("backtracks", _I32),
    _f("attempts", _I32, doc="searches from scratch: 1 + the restarts used (instantiate.restarts); the counts add up over them"),
    _f("failures", _STR, doc="JSON: rejections per check, by the refusal's first word (outside, blocks: a door's zone, "
       "overhangs, violates, leaves: a planned wall, collides, closes: the floor off from the door, forecloses, nowhere)"),
    _f("drops", _STR, doc="JSON: per object a partial scene left out, its id, category, cause ('no_place': budget "
       "spent, 'no_model': no training instance, 'no_span': a wall-bound object planned against two facing walls "
       "no instance spans, 'support_dropped', 'overlap': GRAINS's repair could not clear it) and, for no_place, "
       "the check that refused it most "
       "('no_cell': no free cell left)"),
    _f("planned_edges", _I32, doc="planned support and spatial edges between placed nodes"),
    _f("found_edges", _I32, doc="of those, found again exactly by extraction"),
    _f("consistency", _F64, doc="found_edges / planned_edges"),
    _f("violation", _F64, doc="mean violation cost of the planned edges (0 found, 0.5 other distance, 1 missing)"),
    _f("plan_loss", _STR, doc="JSON: the planned edges not found, by relation (support, adjacent, proximal, "
       "distant) and cause: 'relaxed' (accepted broken once the search's tolerance grew), 'lost_later' (held when its "
       "object was placed, broken by a later one), 'unplaced' (an end left out); and by what extraction finds instead: "
       "'distance' (same side, other distance), 'direction' (another side), 'absent' (no such edge)"),
    _f("relaxed_objects", _I32, doc="objects the search kept with a broken planned relation (PlanIT's search and "
       "its layout modes; null for the other methods)"),
    _f("relaxed", _STR, doc="JSON: per object kept with a broken relation, its id, category, cost, the tolerance it "
       "was kept at, its failures before, the check that refused it most ('cause') and each broken edge: source, "
       "target, what was planned and what extraction found instead"),
    _f("unplanned_edges", _I32, doc="extracted support or spatial edges at an object that the plan lacks"),
    _f("unplanned_adjacent", _I32, doc="of those, support or adjacent ones"),
    _f("colliding_objects", _I32, doc="objects penetrating another deeper than instantiate.checks.collision"),
    _f("unanchored_objects", _I32, doc="objects the string method's assembly placed with no placed neighbour (on a "
       "random free cell); null for the other methods"),
    _f("violations", _I32, doc="annealing methods (infinigen, saog): hard violations of the best state before the "
       "objects in them were left out; null for the other methods"),
    _f("energy", _F64, doc="annealing methods: the best state's weighted soft energy"),
    _f("energy_trace", _STR, doc="annealing methods: JSON rows (stage, step, temperature, violations, energy, objects) "
       "every 10 steps"),
])
SCHEMAS["splits"] = pa.schema([
    _f("room_id", _STR, nullable=False), _f("room_type", _CAT),
    _f("split", _CAT, doc="fit | validation | heldout: the graph model fits on fit and stops on validation; every "
                          "other learner trains on fit and validation; every method generates into, and the "
                          "evaluation compares with, the held-out rooms"),
])
SCHEMAS["eval_scenes"] = pa.schema([
    _f("set", _CAT, nullable=False, doc="planit, a baseline variant, retrieval (nearest training room) or real_heldout"),
    _f("scene_id", _STR, nullable=False, doc="generated scene or real room id"), _f("room_type", _CAT),
    _f("objects", _I32), _f("colliding_objects", _I32, doc="objects penetrating another deeper than evaluate.collision"),
    _f("out_of_bounds", _I32, doc="objects whose eroded footprint leaves the floor"),
    _f("walkable_share", _F64, doc="door-connected share of the agent's free floor"),
    _f("reachable", _F64, doc="share of floor objects whose front an agent reaches from a door"),
    _f("nn_similarity", _F64, doc="layout similarity to the nearest training room (itself excluded)"),
    _f("nn_room_id", _STR, doc="that training room"),
    _f("consistency", _F64, doc="instantiation's graph consistency (null for real rooms)"),
    _f("violation", _F64, doc="instantiation's violation cost (null for real rooms)"),
    _f("contents_excess", _F64, doc="1: a category more often than in any training room of the type"),
    _f("contents_missing", _F64, doc="1: a category missing that the training rooms hold with confidence"),
    _f("functional_all", _F64, doc="1: every applicable functional check passes and the contents are plausible"),
    _f("failed_checks", pa.list_(_STR), doc="the functional checks the room fails (<target>@<anchor> or "
       "<target>@wall) and contents_excess / contents_missing where they hold"),
])
SCHEMAS["superstructures"] = pa.schema([
    _f("room_id", _STR, nullable=False), _f("room_type", _CAT),
    _f("group_id", _STR, doc="hub_<k> | chain_<k>, unique within the room"),
    _f("kind", _CAT, doc="hub | chain"),
    _f("anchor_id", _STR, doc="the hub, or the chain's start"),
    _f("member_id", _STR, doc="a spoke, or a chain member (the start included)"),
    _f("position", _I32, doc="chain: index along the chain"),
    _f("direction", _CAT, doc="hub: spoke direction from the hub; chain: direction of its edges"),
    _f("label", _CAT, doc="chain: adjacent | proximal"),
])
SCHEMAS["cooccurrence"] = pa.schema([
    _f("room_type", _CAT), _f("cat_a", _STR), _f("cat_b", _STR),
    _f("rooms", pa.int64(), doc="rooms holding both (a room counts once; a == b needs two instances)"),
])
SCHEMAS["relations"] = pa.schema([
    _f("room_type", _CAT), _f("cat_a", _STR, doc="anchor category"), _f("cat_b", _STR, doc="target category"),
    _f("direction", _CAT), _f("distance", _CAT),
    _f("rooms", pa.int64(), doc="rooms with at least one such raw edge"),
    _f("cooccur_rooms", pa.int64(), doc="rooms where both categories occur"),
    _f("freq", _F64, doc="rooms / cooccur_rooms: the share the pruning thresholds apply to"),
])
SCHEMAS["hub_patterns"] = pa.schema([
    _f("room_type", _CAT), _f("hub_category", _STR), _f("spoke_category", _STR),
    _f("count", pa.int64(), doc="candidate hub arrangements seen in the raw graphs"),
    _f("accepted", pa.bool_(), doc="count >= refine.hub_min_pattern_count"),
])
SCHEMAS["category_counts"] = pa.schema([
    _f("room_type", _CAT), _f("category", _STR),
    _f("rooms", pa.int64(), doc="ingested rooms of the type holding the category (a room counts once)"),
])
SCHEMAS["partial_counts"] = pa.schema([
    _f("kind", _CAT, doc="cooccurrence | relation | hub_pattern: one shard's share of a dataset-wide count"),
    _f("room_type", _CAT), _f("cat_a", _STR, doc="anchor (hub) category"), _f("cat_b", _STR, doc="target (spoke) category"),
    _f("direction", _CAT), _f("distance", _CAT),
    _f("count", pa.int64(), doc="rooms (cooccurrence, relation) or candidate hubs (hub_pattern) in the shard"),
])
SCHEMAS["category_sizes"] = pa.schema([
    _f("room_type", _CAT), _f("category", _STR), _f("instances", pa.int64()),
    _f("mean_area", _F64, "m^2", "mean projected (footprint) box area"),
    _f("mean_diag", _F64, "m", "mean footprint diagonal"),
])


# Rows are unique by these columns; the write refuses a duplicate.
KEYS = {"rooms": ["room_id"], "architecture": ["room_id", "element_id"], "objects": ["room_id", "object_id"],
        "models": ["model_id"], "symmetry": ["model_id"], "nodes": ["room_id", "node_id"],
        "final_nodes": ["room_id", "node_id"], "filter_report": ["room_id"], "generated_objects": ["room_id", "object_id"],
        "scenes": ["scene_id"], "eval_scenes": ["set", "scene_id"], "generated_nodes": ["room_id", "node_id"]}
# The rule that writes each kind of table: a missing or corrupt one is reported with the rule to rerun.
PRODUCERS = {"rooms": "ingest or filter_rooms", "architecture": "ingest", "objects": "ingest", "models": "ingest",
             "ground_truth": "ingest", "ingest_report": "ingest or ingest_summary", "drops": "ingest or ingest_summary",
             "category_counts": "ingest_summary", "filter_report": "filter_rooms or filter_report", "symmetry": "symmetry",
             "nodes": "extract_graphs", "edges": "extract_graphs", "partial_counts": "shard_statistics",
             "superstructures": "shard_statistics, refine_graphs or gather_graphs",
             "cooccurrence": "graph_statistics", "relations": "graph_statistics", "hub_patterns": "graph_statistics",
             "category_sizes": "graph_statistics", "final_nodes": "refine_graphs or gather_graphs",
             "final_edges": "refine_graphs or gather_graphs", "generated_nodes": "sample_graphs",
             "generated_edges": "sample_graphs", "generated_objects": "instantiate", "scenes": "instantiate",
             "eval_scenes": "evaluate"}


def _made_by(name: str | None) -> str:
    rule = PRODUCERS.get(name or "")
    return f" (written by rule {rule}: rerun it, e.g. snakemake --forcerun {rule.split()[0].rstrip(',')})" if rule else ""


def validate_rows(name: str, table: pa.Table) -> None:
    """Refuse non-finite numbers (any float column, lists included) and duplicate keys (:data:`KEYS`)."""
    for field in table.schema:
        t = field.type
        col = table.column(field.name)
        if pa.types.is_list(t) and pa.types.is_floating(t.value_type):
            col = pc.list_flatten(col)
        elif not pa.types.is_floating(t):
            continue
        bad = pc.sum(pc.invert(pc.is_finite(col))).as_py() if len(col) else 0
        if bad:
            raise TableError(f"table '{name}': column {field.name} holds {bad} value(s) that are not finite")
    keys = KEYS.get(name)
    if keys and table.num_rows:
        counts = table.group_by(keys).aggregate([([], "count_all")])
        dup = counts.filter(pc.greater(counts["count_all"], 1))
        if dup.num_rows:
            first = {k: dup[k][0].as_py() for k in keys}
            raise TableError(f"table '{name}': {dup.num_rows} duplicate key(s) ({', '.join(keys)}), e.g. {first}")


def empty(name: str) -> pa.Table:
    return SCHEMAS[name].empty_table()


def from_rows(name: str, rows: Iterable[dict]) -> pa.Table:
    """Build a table of the named schema from dict rows (missing columns are null)."""
    schema = SCHEMAS[name]
    rows = list(rows)
    cols = {f.name: [r.get(f.name) for r in rows] for f in schema}
    return pa.table({f.name: pa.array(cols[f.name], type=_plain(f.type)) for f in schema}).cast(schema)


def records(frame) -> list[dict]:
    """A pandas frame's rows as dicts with missing values as None, not NaN (what :func:`from_rows` takes)."""
    return frame.astype(object).where(frame.notna(), None).to_dict("records")


def _plain(t: pa.DataType) -> pa.DataType:
    return t.value_type if pa.types.is_dictionary(t) else t


def conform(name: str, table: pa.Table) -> pa.Table:
    """Cast ``table`` to the named schema (columns in schema order, dictionary types applied)."""
    schema = SCHEMAS[name]
    missing = [f.name for f in schema if f.name not in table.column_names]
    if missing:
        raise TableError(f"table '{name}' lacks fields {missing}")
    return table.select(schema.names).cast(schema)


def write(path: str | Path, name: str, table: pa.Table, extra: dict | None = None) -> Path:
    """Write ``table`` as schema ``name`` to ``path`` atomically (temp file in the same folder, then rename)."""
    path = Path(path)
    table = conform(name, table)
    validate_rows(name, table)
    table = table.replace_schema_metadata({**(table.schema.metadata or {}), **_metadata(name, extra)})
    return _atomic(path, lambda tmp: pq.write_table(table, tmp, compression="zstd"))


def _metadata(name: str, extra: dict | None) -> dict[str, str]:
    meta = {"pipeline.schema": f"{name}/v1", "pipeline.version": __version__, "pipeline.coordinates": COORDINATES}
    for key, value in (extra or {}).items():
        meta[f"pipeline.{key}"] = value if isinstance(value, str) else json.dumps(value)
    return meta


def write_parts(path: str | Path, name: str, parts, extra: dict | None = None) -> int:
    """Write an iterable of tables of schema ``name`` as one file, part by part (row groups), atomically, without
    holding more than one part in memory. Returns the number of rows."""
    schema = SCHEMAS[name]
    meta = {**(schema.metadata or {}), **_metadata(name, extra)}
    rows = 0

    def write_to(tmp):
        nonlocal rows
        with pq.ParquetWriter(tmp, schema.with_metadata(meta), compression="zstd") as writer:
            for part in parts:
                part = conform(name, part)
                validate_rows(name, part)
                writer.write_table(part.replace_schema_metadata(meta))
                rows += part.num_rows

    _atomic(Path(path), write_to)
    return rows


@contextmanager
def _temporary(path: Path) -> Iterator[str]:
    """A temporary path in ``path``'s folder, renamed onto ``path`` when the block ends; nothing is left on failure."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; shared (cluster) filesystems need the usual mode
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _atomic(path: Path, write_to) -> Path:
    """Call ``write_to(temporary path)`` in ``path``'s folder, then rename onto ``path``; nothing is left on failure."""
    with _temporary(path) as tmp:
        write_to(tmp)
    return path


class Archive:
    """A zip archive of side files (a GLB, PNG and JSON per generated scene): one output file instead of a folder.
    Entries carry a fixed date, so the same files give the same bytes."""

    def __init__(self, zipfile_: zipfile.ZipFile):
        self._zip = zipfile_

    def add(self, name: str, data: bytes) -> None:
        info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
        info.compress_type = zipfile.ZIP_DEFLATED
        self._zip.writestr(info, data)

    def add_figure(self, name: str, figure, **savefig) -> None:
        """A matplotlib figure as a PNG entry (``figure_png``)."""
        self.add(name, figure_png(figure, **savefig))

    def add_json(self, name: str, value) -> None:
        self.add(name, json.dumps(value, indent=2).encode())


@contextmanager
def write_archive(path: str | Path) -> Iterator[Archive]:
    """Open a zip archive to add entries to; written whole to a temporary file, renamed onto ``path`` at the end."""
    with _temporary(Path(path)) as tmp, zipfile.ZipFile(tmp, "w") as zf:
        yield Archive(zf)


def read_archive(path: str | Path) -> dict[str, bytes]:
    """Every entry of an archive written by ``write_archive``: name -> bytes."""
    try:
        with zipfile.ZipFile(path) as zf:
            return {name: zf.read(name) for name in zf.namelist()}
    except (OSError, zipfile.BadZipFile) as exc:
        raise PlanitError(f"{path}: not a readable scene archive ({exc})") from exc


def write_atomic(path: str | Path, write_to) -> Path:
    """Any file written atomically: ``write_to(temporary path)``, then a rename (checkpoints, model files)."""
    return _atomic(Path(path), write_to)


def write_json(path: str | Path, value) -> Path:
    """A JSON side file (summaries, metrics), written atomically."""
    text = json.dumps(value, indent=2)
    return _atomic(Path(path), lambda tmp: Path(tmp).write_text(text))


def write_text(path: str | Path, text: str) -> Path:
    """A text side file (a program, a grammar), written atomically."""
    return _atomic(Path(path), lambda tmp: Path(tmp).write_text(text))


def write_tsv(path: str | Path, frame) -> Path:
    """A tab-separated side file from a DataFrame, written atomically."""
    return _atomic(Path(path), lambda tmp: frame.to_csv(tmp, sep="\t", index=False))


def write_csv(path: str | Path, frame) -> Path:
    """A comma-separated side file from a DataFrame, written atomically."""
    return _atomic(Path(path), lambda tmp: frame.to_csv(tmp, index=False))


def write_figure(path: str | Path, figure, **savefig) -> Path:
    """A matplotlib figure, written atomically (the format follows ``path``'s suffix), then closed: pyplot keeps
    every figure it made alive until then, so a stage writing hundreds would grow without bound."""
    import matplotlib.pyplot as plt

    fmt = Path(path).suffix.lstrip(".") or "png"
    try:
        return _atomic(Path(path), lambda tmp: figure.savefig(tmp, format=fmt, **savefig))
    finally:
        plt.close(figure)


def figure_png(figure, **savefig) -> bytes:
    """A matplotlib figure as PNG bytes, then closed (as ``write_figure``)."""
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    try:
        figure.savefig(buffer, format="png", **savefig)
    finally:
        plt.close(figure)
    return buffer.getvalue()


def write_image(path: str | Path, pixels) -> Path:
    """An image from an (H, W, 3 or 4) array of floats in [0, 1], written atomically as PNG."""
    from matplotlib.image import imsave

    return _atomic(Path(path), lambda tmp: imsave(tmp, pixels, format="png"))


def read(path: str | Path, name: str | None = None, filters=None, columns: list[str] | None = None) -> pa.Table:
    """Read a pipeline table; with ``name``, check every field of that schema is present. ``filters`` (pyarrow
    DNF, e.g. ``[("room_id", "in", ids)]``) are pushed down to the row groups; ``columns`` reads only those."""
    if name is not None:
        check(path, name)
    try:
        wanted = columns if columns is not None else (SCHEMAS[name].names if name is not None else None)
        return pq.read_table(path, filters=_typed(filters, path), columns=wanted)
    except FileNotFoundError as exc:
        raise TableError(f"{path}: no such table file{_made_by(name)}") from exc
    except (pa.ArrowInvalid, OSError) as exc:
        raise TableError(f"{path}: not a readable Parquet file{_made_by(name)}: {exc}") from exc


def _typed(filters, path):
    """Filters whose ``in`` lists carry their column's type: an empty list (a shard with no rooms) is then a valid
    filter that matches nothing, where pyarrow cannot infer the type of ``[]``."""
    if not filters or not any(isinstance(f, tuple) and f[1] in ("in", "not in") for f in filters):
        return filters
    schema = pq.read_schema(path)
    out = []
    for f in filters:
        if isinstance(f, tuple) and f[1] in ("in", "not in") and f[0] in schema.names:
            kind = schema.field(f[0]).type
            kind = kind.value_type if pa.types.is_dictionary(kind) else kind
            f = (f[0], f[1], pa.array(list(f[2]), type=kind))
        out.append(f)
    return out


def check(path: str | Path, name: str) -> None:
    """Fail with a TableError naming the file unless it is a readable table holding every field of ``name``
    (reads the footer only)."""
    path = Path(path)
    if not path.exists():
        raise TableError(f"{path}: no such table file{_made_by(name)}")
    try:
        present = set(pq.read_schema(path).names)
    except (pa.ArrowInvalid, OSError) as exc:
        raise TableError(f"{path}: not a readable Parquet file{_made_by(name)}: {exc}") from exc
    missing = [f.name for f in SCHEMAS[name] if f.name not in present]
    if missing:
        raise TableError(f"{path}: table '{name}' lacks field(s) {', '.join(missing)}")


def read_many(paths, name: str, columns: list[str] | None = None, filters=None) -> pa.Table:
    """Concatenate tables of one schema (shards of a stage's output), in the given order."""
    parts = [read(p, name, filters=filters, columns=columns) for p in paths]
    if not parts:
        table = empty(name)
        return table.select(columns) if columns else table
    return pa.concat_tables(parts).combine_chunks()


def records_by_room(path: str | Path, name: str) -> dict[str, list[dict]]:
    """A table's rows as plain dicts (strings, floats, None for nulls), grouped by ``room_id`` in file order."""
    table = read(path, name)
    table = table.cast(pa.schema([pa.field(f.name, _plain(f.type)) for f in table.schema]))
    out: dict[str, list[dict]] = {}
    for row in table.to_pylist():
        out.setdefault(row["room_id"], []).append(row)
    return out


def read_meshes(path: str | Path, model_ids) -> tuple[dict, set]:
    """The meshes of the models ``model_ids`` from a ``models`` table (the filter is pushed into the read): model id
    -> ``(vertices, faces)``, and the ids whose mesh is only their box (``mesh_kind`` box_fallback)."""
    if not len(model_ids):  # pyarrow cannot type an empty "in" filter
        return {}, set()
    rows = read(path, "models", filters=[("model_id", "in", sorted(set(model_ids)))],
                columns=["model_id", "vertices", "faces", "mesh_kind"]).to_pylist()
    return {m["model_id"]: model_mesh(m) for m in rows}, {m["model_id"] for m in rows if m["mesh_kind"] == "box_fallback"}


def read_meshes_of(paths, model_ids) -> tuple[dict, set]:
    """:func:`read_meshes` over several ``models`` tables (the shards)."""
    meshes, box_models = {}, set()
    for p in paths:
        m, b = read_meshes(p, model_ids)
        meshes.update(m)
        box_models |= b
    return meshes, box_models


def model_mesh(row: dict):
    """(vertices (n, 3) float, faces (m, 3) int) of a ``models`` table row."""
    import numpy as np

    v = np.asarray(row["vertices"] if row["vertices"] is not None else [], dtype=float).reshape(-1, 3)
    f = np.asarray(row["faces"] if row["faces"] is not None else [], dtype=np.int64).reshape(-1, 3)
    return v, f


def metadata(path: str | Path) -> dict[str, str]:
    """The pipeline.* schema-level metadata of a table file."""
    raw = pq.read_schema(path).metadata or {}
    return {k.decode(): v.decode() for k, v in raw.items() if k.startswith(b"pipeline.")}
