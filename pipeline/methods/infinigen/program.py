"""Infinigen-style room programs (Raistrick et al. 2024): the small YAML file that says, per room type, which
categories a room holds, how many of each, in which stage the annealing solver places them (large, medium, small:
the paper's Alg. 1) and the hard and soft relations each one keeps, plus the weights of the solver's soft terms,
and (optional) the room's contents drawn as a whole: ``recipes``, each a count per category that training rooms
held together (a bed with its two nightstands), drawn in proportion to its ``rooms``; a program without recipes
draws each category's count within its range.

This module holds the data classes (:class:`ObjectRule`, :class:`Program`), the format as a JSON Schema
(:data:`SCHEMA`), the parser with line-numbered :class:`~pipeline.errors.InputError` messages
(``<source>:<line>: <field>: <what>``, :mod:`pipeline.schemas`), the loader and the writer
(``parse_program(dump_program(p)) == p``; line numbers take no part in equality). No torch."""
from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from yaml.constructor import SafeConstructor
from yaml.nodes import Node

from ... import schemas
from ...errors import InputError
from ...geometry.relations import parent_cycles

STAGES = ("large", "medium", "small")
TERMS = ("against_wall", "next_to", "facing", "accessibility", "alignment", "symmetry", "free_floor")
DEFAULT_WEIGHTS: dict[str, float] = {"against_wall": 2.0, "next_to": 2.0, "facing": 1.0, "accessibility": 1.0,
                                     "alignment": 0.5, "symmetry": 1.0, "free_floor": 1.0}
RELATIONS = ("on", "next_to", "facing")


@dataclass(frozen=True)
class ObjectRule:
    """One category of a program: how many per room, its stage, and the relations it keeps."""
    category: str
    count: tuple[int, int]        # inclusive (min, max) instances per room
    stage: str                    # one of STAGES: solved large, then medium, then small (Infinigen's Alg. 1)
    against_wall: bool = False    # stands with its back flush against a wall
    on: str | None = None         # support parent category (None: the floor)
    next_to: str | None = None    # a category it stands beside (side by side, adjacent)
    facing: str | None = None     # a category it stands in front of, facing it
    line: int = field(default=0, compare=False)  # 1-based line in the source file (for messages)


@dataclass(frozen=True)
class Recipe:
    """One room's contents as a whole: how many training rooms held exactly these counts (categories of the program
    absent from ``counts`` hold 0)."""
    rooms: int
    counts: dict[str, int]   # category -> instances, categories of the program only


@dataclass(frozen=True)
class Program:
    """A room type's program: its object rules in file order, the soft terms' weights (every term present) and the
    recipes its contents are drawn from (empty: each count drawn within its rule's range)."""
    room_type: str
    objects: dict[str, ObjectRule]   # category -> rule, in file order
    weights: dict[str, float]        # soft term -> weight, every key of TERMS present
    source: str = field(default="<program>", compare=False)
    recipes: list[Recipe] = field(default_factory=list)

    def counts(self, rng) -> dict[str, tuple[int, int]]:
        """Category -> the (min, max) count of one scene: a recipe's exact counts drawn in proportion to its rooms,
        each held within its rule's range (a user who sets a count to [0, 0] gets none), or each rule's range when
        the program has no recipe."""
        if not self.recipes:
            return {c: r.count for c, r in self.objects.items()}
        weight = [r.rooms for r in self.recipes]
        recipe = self.recipes[int(rng.choice(len(weight), p=[w / sum(weight) for w in weight]))]
        held = {c: min(max(recipe.counts.get(c, 0), r.count[0]), r.count[1]) for c, r in self.objects.items()}
        return {c: (n, n) for c, n in held.items()}


# ---------------------------------------------------------------- parsing

class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 booleans: only true / false are booleans, so the ``on`` key (and a
    category named ``yes`` or ``no``) stays a string."""


_BOOL = "tag:yaml.org,2002:bool"
_Loader.yaml_implicit_resolvers = {first: [(tag, rx) for tag, rx in resolvers if tag != _BOOL]
                                   for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))

_NAME = {"type": ["string", "null"], "minLength": 1}  # a category of this program (null: none)
SCHEMA: dict[str, Any] = {  # the format; what a schema cannot say (names, cycles, stages, min <= max) is checked below
    "type": "object", "required": ["room_type", "objects"], "additionalProperties": False,
    "properties": {
        "room_type": {"type": "string", "minLength": 1},
        "objects": {"type": "object", "minProperties": 1, "additionalProperties": {
            "type": "object", "required": ["count", "stage"], "additionalProperties": False,
            "properties": {"count": {"type": "array", "items": {"type": "integer", "minimum": 0},
                                     "minItems": 2, "maxItems": 2},
                           "stage": {"enum": list(STAGES)}, "against_wall": {"type": "boolean"},
                           **{rel: _NAME for rel in RELATIONS}}}},
        "recipes": {"type": "array", "items": {
            "type": "object", "required": ["rooms", "counts"], "additionalProperties": False,
            "properties": {"rooms": {"type": "integer", "minimum": 1},
                           "counts": {"type": "object", "additionalProperties": {"type": "integer", "minimum": 0}}}}},
        "weights": {"type": "object", "additionalProperties": False,
                    "properties": {t: {"type": "number", "minimum": 0, "format": "finite"} for t in TERMS}},
    },
}


def _where(root: Node, source: str, category: str, key: str) -> tuple[str, int, str]:
    """(source, line, field) of an object's field, for :func:`schemas.fail`."""
    return source, schemas.line_of(root, ("objects", category, key)), f"objects.{category}.{key}"


def _rule(category: str, fields: dict[str, Any], root: Node, source: str) -> ObjectRule:
    """One object's rule, its fields valid by the schema (its relations not yet checked against the others)."""
    low, high = (int(n) for n in fields["count"])  # JSON Schema's integers take 2.0 too
    if low > high:
        raise schemas.fail(*_where(root, source, category, "count"), f"expected 0 <= min <= max, got [{low}, {high}]")
    given = {k: v for k, v in fields.items() if k != "count" and v is not None}
    return ObjectRule(category=category, count=(low, high), line=schemas.line_of(root, ("objects", category), key=True),
                      **given)


def _check_relations(objects: dict[str, ObjectRule], root: Node, source: str) -> None:
    """Every on / next_to / facing names another category of the program."""
    for cat, rule in objects.items():
        for rel in RELATIONS:
            other = getattr(rule, rel)
            if other == cat:
                raise schemas.fail(*_where(root, source, cat, rel), "names the object itself")
            if other is not None and other not in objects:
                raise schemas.fail(*_where(root, source, cat, rel), f"'{other}' is not an object of this program")


def _check_stages(objects: dict[str, ObjectRule], root: Node, source: str) -> None:
    """A support parent is not staged after its child (the solver places the parent first)."""
    for cat, rule in objects.items():
        parent = objects[rule.on] if rule.on is not None else None
        if parent is not None and STAGES.index(parent.stage) > STAGES.index(rule.stage):
            what = f"its parent '{parent.category}' is staged {parent.stage}, after its own stage {rule.stage}"
            raise schemas.fail(*_where(root, source, cat, "on"), what)


def _check_cycles(objects: dict[str, ObjectRule], root: Node, source: str) -> None:
    """No support cycle (a on b, b on a, or longer): one is reported from its member first in the file."""
    cycles = parent_cycles({cat: rule.on for cat, rule in objects.items()})
    if cycles:
        order = list(objects)
        cat = min((c for cycle in cycles for c in cycle), key=order.index)
        loop = next(cycle for cycle in cycles if cat in cycle)
        loop = loop[loop.index(cat):] + loop[:loop.index(cat)]
        raise schemas.fail(*_where(root, source, cat, "on"), "support cycle: " + " on ".join([*loop, cat]))


def _recipes(data: list[dict], objects: dict[str, ObjectRule], root: Node, source: str) -> list[Recipe]:
    """The recipes, each naming categories of the program only."""
    out = []
    for i, entry in enumerate(data):
        for cat in entry["counts"]:
            if cat not in objects:
                line = schemas.line_of(root, ("recipes", i, "counts", cat))
                raise schemas.fail(source, line, f"recipes[{i}].counts.{cat}", f"'{cat}' is not an object of this program")
        out.append(Recipe(int(entry["rooms"]), {c: int(n) for c, n in entry["counts"].items() if int(n) > 0}))
    return out


def parse_program(text: str, source: str = "<program>") -> Program:
    """A program from YAML text; every error is an InputError ``<source>:<line>: <field>: <what>``."""
    root = schemas.compose(text, source, _Loader)
    if root is None:
        raise schemas.fail(source, 1, "program", "empty (expected room_type, objects and weights)")
    schemas.check_keys(root, source, "program")
    data = SafeConstructor().construct_document(root)
    schemas.validate(data, SCHEMA, source, root, "program")
    objects = {cat: _rule(cat, fields, root, source) for cat, fields in data["objects"].items()}
    _check_relations(objects, root, source)
    _check_cycles(objects, root, source)
    _check_stages(objects, root, source)
    weights = {**DEFAULT_WEIGHTS, **{t: float(w) for t, w in data.get("weights", {}).items()}}
    recipes = _recipes(data.get("recipes", []), objects, root, source)
    return Program(room_type=data["room_type"], objects=objects, weights=weights, source=source, recipes=recipes)


def load_program(path: Path) -> Program:
    """A program file, parsed; errors name the file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read the program ({exc})") from exc
    return parse_program(text, source=str(path))


# ---------------------------------------------------------------- writing

_PLAIN = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]*$")


def _name(text: str) -> str:
    """A name as a YAML scalar: plain when it reads back as the same string, else double-quoted."""
    if _PLAIN.match(text) and yaml.safe_load(text) == text:
        return text
    return json.dumps(text)


def _number(value: float) -> str:
    """A float as YAML that PyYAML reads back as the same float (it wants a dot and a signed exponent)."""
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        mantissa = mantissa if "." in mantissa else mantissa + ".0"
        exponent = exponent if exponent[0] in "+-" else "+" + exponent
        text = f"{mantissa}e{exponent}"
    return text


def _rule_line(rule: ObjectRule) -> str:
    """One object as a flow-style line; fields at their defaults are left out."""
    parts = [f"count: [{rule.count[0]}, {rule.count[1]}]", f"stage: {rule.stage}"]
    if rule.against_wall:
        parts.append("against_wall: true")
    parts += [f"{rel}: {_name(getattr(rule, rel))}" for rel in RELATIONS if getattr(rule, rel) is not None]
    return f"  {_name(rule.category)}: {{{', '.join(parts)}}}"


def dump_program(program: Program, header: list[str]) -> str:
    """The program as YAML text: ``header`` as ``# `` comments, room_type, one line per object, then the weights."""
    lines = [f"# {part}".rstrip() for text in header for part in str(text).splitlines() or [""]]
    lines.append(f"room_type: {_name(program.room_type)}")
    lines.append("objects:")
    lines += [_rule_line(rule) for rule in program.objects.values()]
    weights = {**DEFAULT_WEIGHTS, **program.weights}
    terms = [t for t in TERMS if t in weights] + [t for t in weights if t not in TERMS]
    lines.append("weights: {" + ", ".join(f"{t}: {_number(weights[t])}" for t in terms) + "}")
    if program.recipes:
        lines.append("recipes:  # a scene's contents: one recipe, drawn in proportion to its rooms (delete to draw by count)")
        lines += ["  - {rooms: %d, counts: {%s}}" % (r.rooms, ", ".join(f"{_name(c)}: {n}" for c, n in r.counts.items()))
                  for r in program.recipes]
    return "\n".join(lines) + "\n"
