"""Partial graphs written by hand: a readable YAML spec, validated, turned into a sampling :class:`Plan`.

    room_type: bedroom
    architecture: heldout          # or {room: <room_id>}: grow in that room's walls, doors and windows
    objects:                       # a category, or {name: category}
      - bed
      - desk
      - lamp: table_lamp
    relations:                     # <object>: {<relation>: <object>, distance: adjacent | proximal | distant}
      desk: {left_of: bed, distance: adjacent}
      lamp: {on_top_of: desk}

Relations read as English: ``desk: {left_of: bed}`` puts the desk on the bed's left (the edge bed -> desk,
direction left); ``in_front_of`` and ``behind`` likewise; ``on_top_of`` is support (desk -> lamp). A list of such
mappings gives an object several relations. Every given object and relation is kept; the model adds the rest.
"""
from __future__ import annotations

from pathlib import Path

import jsonschema
import yaml

from ....errors import InputError
from ....graphs.data import OBJECT_EDGES, Vocab
from .sampler import Plan

DIRECTION_OF = {"left_of": "left", "right_of": "right", "in_front_of": "front", "behind": "back"}
RELATIONS = (*DIRECTION_OF, "on_top_of")  # not "on": YAML reads on / off / yes / no as booleans
_RELATION = {"type": "object", "minProperties": 1, "properties": {"distance": {"enum": ["adjacent", "proximal", "distant"]}},
             "additionalProperties": {"type": "string"}}
SCHEMA = {
    "type": "object", "additionalProperties": False, "required": ["room_type", "objects"],
    "properties": {
        "room_type": {"type": "string"},
        "architecture": {"oneOf": [{"const": "heldout"}, {"type": "object", "required": ["room"], "additionalProperties": False,
                                                          "properties": {"room": {"type": "string"}}}]},
        "objects": {"type": "array", "minItems": 1, "items": {"oneOf": [
            {"type": "string"}, {"type": "object", "minProperties": 1, "maxProperties": 1, "additionalProperties": {"type": "string"}}]}},
        "relations": {"type": "object", "additionalProperties": {"oneOf": [_RELATION, {"type": "array", "items": _RELATION}]}},
    },
}


def load_spec(path: Path, room_type: str, vocab: Vocab) -> tuple[Plan, str | None]:
    """The plan of a spec file and the room whose architecture it asks for (None: the held-out rooms)."""
    try:
        spec = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as exc:
        raise InputError(f"{path}: cannot read the spec ({exc})") from exc
    try:
        jsonschema.validate(spec, SCHEMA)
    except jsonschema.ValidationError as exc:
        where = ".".join(map(str, exc.absolute_path)) or "(top level)"
        raise InputError(f"{path}: {where}: {exc.message}") from None
    if spec["room_type"] != room_type:
        raise InputError(f"{path}: room_type: '{spec['room_type']}', but the model is for '{room_type}'")
    names = _objects(path, spec["objects"], vocab)
    plan = Plan(objects=[(vocab.categories.index(c), None, None) for c in names.values()])
    index = {name: k for k, name in enumerate(names)}
    for target, rels in (spec.get("relations") or {}).items():
        for rel in rels if isinstance(rels, list) else [rels]:
            plan.edges.append(_edge(path, target, rel, index))
    arch = spec.get("architecture", "heldout")
    return plan, (arch["room"] if isinstance(arch, dict) else None)


def _objects(path, entries: list, vocab: Vocab) -> dict[str, str]:
    """Name -> category, in the spec's order (a repeated plain category is named bed, bed_2, ...)."""
    out: dict[str, str] = {}
    for k, entry in enumerate(entries):
        name, cat = (entry, entry) if isinstance(entry, str) else next(iter(entry.items()))
        if cat not in vocab.categories:
            raise InputError(f"{path}: objects.{k}: unknown category '{cat}' for this room type "
                             f"(known: {', '.join(vocab.categories)})")
        base, n = name, 2
        while name in out:
            name, n = f"{base}_{n}", n + 1
        out[name] = cat
    return out


def _edge(path, target: str, rel: dict, index: dict[str, int]) -> tuple[int, int, int, int]:
    """A plan edge ``(earlier, direction, type, later)`` from one relation mapping of ``target``."""
    if target not in index:
        raise InputError(f"{path}: relations.{target}: no object named '{target}' (objects: {', '.join(index)})")
    kinds = [k for k in rel if k != "distance"]
    for k in kinds:
        if not isinstance(k, str):
            raise InputError(f"{path}: relations.{target}: relation {k!r} is not a name (YAML reads on, off, yes and no "
                             f"as booleans; write on_top_of)")
        if k not in RELATIONS:
            raise InputError(f"{path}: relations.{target}: unknown relation '{k}' (one of: {', '.join(RELATIONS)})")
    if len(kinds) != 1:
        raise InputError(f"{path}: relations.{target}: one relation per mapping (use a list for several), got {kinds}")
    kind, anchor = kinds[0], rel[kinds[0]]
    if anchor not in index:
        raise InputError(f"{path}: relations.{target}.{kind}: no object named '{anchor}' (objects: {', '.join(index)})")
    if kind == "on_top_of":
        if "distance" in rel:
            raise InputError(f"{path}: relations.{target}: 'on_top_of' (support) takes no distance")
        cls = OBJECT_EDGES.index("support")
    else:
        cls = OBJECT_EDGES.index(f"{DIRECTION_OF[kind]}/{rel.get('distance', 'adjacent')}")
    a, t = index[anchor], index[target]
    if a == t:
        raise InputError(f"{path}: relations.{target}.{kind}: an object cannot relate to itself")
    return (a, 0, cls, t) if a < t else (t, 1, cls, a)



