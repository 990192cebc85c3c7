"""Infinigen-style room programs (Raistrick et al. 2024): the small YAML file that says, per room type, which
categories a room holds, how many of each, in which stage the annealing solver places them (large, medium, small:
the paper's Alg. 1) and the hard and soft relations each one keeps, plus the weights of the solver's soft terms.

This module holds the data classes (:class:`ObjectRule`, :class:`Program`), the parser with line-numbered
:class:`~pipeline.errors.InputError` messages (``<source>:<line>: <field>: <what>``), the loader and the writer
(``parse_program(dump_program(p)) == p``; line numbers take no part in equality). No torch."""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from yaml.constructor import SafeConstructor
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from ...errors import InputError

STAGES = ("large", "medium", "small")
TERMS = ("against_wall", "next_to", "facing", "accessibility", "alignment", "symmetry", "free_floor")
DEFAULT_WEIGHTS: dict[str, float] = {"against_wall": 2.0, "next_to": 2.0, "facing": 1.0, "accessibility": 1.0,
                                     "alignment": 0.5, "symmetry": 1.0, "free_floor": 1.0}
TOP_KEYS = ("room_type", "objects", "weights")
RELATIONS = ("on", "next_to", "facing")
OBJECT_FIELDS = ("count", "stage", "against_wall", *RELATIONS)


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
class Program:
    """A room type's program: its object rules in file order and the soft terms' weights (every term present)."""
    room_type: str
    objects: dict[str, ObjectRule]   # category -> rule, in file order
    weights: dict[str, float]        # soft term -> weight, every key of TERMS present
    source: str = field(default="<program>", compare=False)


# ---------------------------------------------------------------- parsing helpers

class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 booleans: only true / false are booleans, so the ``on`` key (and a
    category named ``yes`` or ``no``) stays a string."""


_BOOL = "tag:yaml.org,2002:bool"
_Loader.yaml_implicit_resolvers = {first: [(tag, rx) for tag, rx in resolvers if tag != _BOOL]
                                   for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
_Loader.add_implicit_resolver(_BOOL, re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF"))


def _line(node: Node) -> int:
    """The 1-based line a YAML node starts on."""
    return node.start_mark.line + 1


def _fail(source: str, line: int, what_field: str, what: str) -> InputError:
    """The error for a bad field: ``<source>:<line>: <field>: <what>``."""
    return InputError(f"{source}:{line}: {what_field}: {what}")


def _value(node: Node) -> Any:
    """The Python value of a YAML node (safe types only)."""
    return SafeConstructor().construct_object(node, deep=True)


def _compose(text: str, source: str) -> Node:
    """The document's root node; a syntax error or an empty file is an InputError naming the line."""
    try:
        root = yaml.compose(text, Loader=_Loader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        raise _fail(source, line, "yaml", f"syntax error: {exc.problem or exc}") from exc
    except yaml.YAMLError as exc:
        raise _fail(source, 1, "yaml", f"syntax error: {exc}") from exc
    if root is None:
        raise _fail(source, 1, "program", "empty (expected room_type, objects and weights)")
    return root


def _pairs(node: Node, source: str, name: str) -> list[tuple[str, Node, Node]]:
    """A mapping node's (key, key node, value node) triples; keys must be unique strings."""
    if not isinstance(node, MappingNode):
        raise _fail(source, _line(node), name, "expected a mapping")
    out, seen = [], set()
    for key_node, value_node in node.value:
        key = _value(key_node)
        where = f"{name}.{key}" if name != "program" else str(key)
        if not isinstance(key, str) or not key:
            raise _fail(source, _line(key_node), where, "a key must be a non-empty name")
        if key in seen:
            raise _fail(source, _line(key_node), where, "duplicate key")
        seen.add(key)
        out.append((key, key_node, value_node))
    return out


def _count(node: Node, source: str, name: str) -> tuple[int, int]:
    """``[min, max]``: two ints with 0 <= min <= max."""
    values = _value(node) if isinstance(node, SequenceNode) else None
    if (not isinstance(values, list) or len(values) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) for v in values)):
        raise _fail(source, _line(node), name, "expected [min, max], two integers")
    low, high = values
    if not 0 <= low <= high:
        raise _fail(source, _line(node), name, f"expected 0 <= min <= max, got [{low}, {high}]")
    return low, high


def _scalar(node: Node, source: str, name: str, kind: type, what: str) -> Any:
    """A scalar of one Python type (bool is no int), else an InputError saying ``what`` was expected."""
    value = _value(node) if isinstance(node, ScalarNode) else None
    if not isinstance(value, kind) or (kind is not bool and isinstance(value, bool)) or value == "":
        raise _fail(source, _line(node), name, f"expected {what}")
    return value


# ---------------------------------------------------------------- objects

def _object(category: str, key_node: Node, node: Node, source: str) -> tuple[ObjectRule, dict[str, int]]:
    """One object rule (relations not yet checked against the other objects) and the line of each field."""
    base = f"objects.{category}"
    fields: dict[str, Any] = {}
    lines = {"": _line(key_node)}
    for key, field_key, value_node in _pairs(node, source, base):
        name = f"{base}.{key}"
        lines[key] = _line(value_node)
        if key not in OBJECT_FIELDS:
            raise _fail(source, _line(field_key), name, f"unknown field (known: {', '.join(OBJECT_FIELDS)})")
        if key == "count":
            fields[key] = _count(value_node, source, name)
        elif key == "stage":
            fields[key] = _scalar(value_node, source, name, str, f"one of {', '.join(STAGES)}")
            if fields[key] not in STAGES:
                raise _fail(source, _line(value_node), name, f"'{fields[key]}' is not one of {', '.join(STAGES)}")
        elif key == "against_wall":
            fields[key] = _scalar(value_node, source, name, bool, "true or false")
        elif not (isinstance(value_node, ScalarNode) and _value(value_node) is None):
            fields[key] = _scalar(value_node, source, name, str, "a category name of this program")
    for required in ("count", "stage"):
        if required not in fields:
            raise _fail(source, _line(key_node), f"{base}.{required}", "missing")
    return ObjectRule(category=category, line=_line(key_node), **fields), lines


def _check_relations(objects: dict[str, ObjectRule], lines: dict[str, dict[str, int]], source: str) -> None:
    """Every on / next_to / facing names another category of the program."""
    for cat, rule in objects.items():
        for rel in RELATIONS:
            other = getattr(rule, rel)
            if other is None:
                continue
            where = (source, lines[cat][rel], f"objects.{cat}.{rel}")
            if other == cat:
                raise _fail(*where, "names the object itself")
            if other not in objects:
                raise _fail(*where, f"'{other}' is not an object of this program")


def _check_stages(objects: dict[str, ObjectRule], lines: dict[str, dict[str, int]], source: str) -> None:
    """A support parent is not staged after its child (the solver places the parent first)."""
    for cat, rule in objects.items():
        parent = objects[rule.on] if rule.on is not None else None
        if parent is not None and STAGES.index(parent.stage) > STAGES.index(rule.stage):
            what = f"its parent '{parent.category}' is staged {parent.stage}, after its own stage {rule.stage}"
            raise _fail(source, lines[cat]["on"], f"objects.{cat}.on", what)


def _check_cycles(objects: dict[str, ObjectRule], lines: dict[str, dict[str, int]], source: str) -> None:
    """No support cycle (a on b, b on a, or longer)."""
    for cat, rule in objects.items():
        chain, current = [cat], rule.on
        while current is not None:
            if current == cat:
                loop = " on ".join([*chain, cat])
                raise _fail(source, lines[cat]["on"], f"objects.{cat}.on", f"support cycle: {loop}")
            if current in chain:
                break  # a cycle not through cat: reported from one of its members
            chain.append(current)
            current = objects[current].on


def _objects(node: Node, source: str) -> dict[str, ObjectRule]:
    """The ``objects`` mapping: category -> rule, validated, in file order."""
    objects: dict[str, ObjectRule] = {}
    lines: dict[str, dict[str, int]] = {}
    for cat, key_node, value_node in _pairs(node, source, "objects"):
        objects[cat], lines[cat] = _object(cat, key_node, value_node, source)
    if not objects:
        raise _fail(source, _line(node), "objects", "empty (list at least one category)")
    _check_relations(objects, lines, source)
    _check_cycles(objects, lines, source)
    _check_stages(objects, lines, source)
    return objects


# ---------------------------------------------------------------- weights and the whole program

def _weights(node: Node | None, source: str) -> dict[str, float]:
    """The soft terms' weights: known terms, finite non-negative numbers; missing terms take the defaults."""
    weights = dict(DEFAULT_WEIGHTS)
    if node is None:
        return weights
    for term, key_node, value_node in _pairs(node, source, "weights"):
        name = f"weights.{term}"
        if term not in TERMS:
            raise _fail(source, _line(key_node), name, f"unknown term (known: {', '.join(TERMS)})")
        value = _value(value_node) if isinstance(value_node, ScalarNode) else None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise _fail(source, _line(value_node), name, "expected a finite number")
        if value < 0:
            raise _fail(source, _line(value_node), name, f"negative weight {value}")
        weights[term] = float(value)
    return weights


def parse_program(text: str, source: str = "<program>") -> Program:
    """A program from YAML text; every error is an InputError ``<source>:<line>: <field>: <what>``."""
    root = _compose(text, source)
    top: dict[str, tuple[Node, Node]] = {}
    for key, key_node, value_node in _pairs(root, source, "program"):
        if key not in TOP_KEYS:
            raise _fail(source, _line(key_node), key, f"unknown key (known: {', '.join(TOP_KEYS)})")
        top[key] = (key_node, value_node)
    for required in ("room_type", "objects"):
        if required not in top:
            raise _fail(source, 1, required, "missing")
    room_type = _scalar(top["room_type"][1], source, "room_type", str, "a room type name such as bedroom")
    objects = _objects(top["objects"][1], source)
    weights = _weights(top["weights"][1] if "weights" in top else None, source)
    return Program(room_type=room_type, objects=objects, weights=weights, source=source)


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
    return "\n".join(lines) + "\n"
