"""YAML documents a user may write (room programs, grammars) read and checked against a JSON Schema (jsonschema, as
the config is), every error an :class:`~pipeline.errors.InputError` ``<source>:<line>: <field>: <what>``: the field
as a dotted path (``objects.bed.count``, ``groups[2].mu``) and the line of the file it stands on."""
from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import jsonschema
import yaml
from yaml.nodes import MappingNode, Node, SequenceNode

from .errors import InputError

T = TypeVar("T")
FieldPath = Sequence[str | int]  # mapping keys and list indices, from the root
FORMATS = jsonschema.FormatChecker()  # "format": "finite": no NaN or infinity (YAML's .nan, .inf)
FORMATS.checks("finite")(lambda x: not isinstance(x, float) or math.isfinite(x))


def fail(source: str, line: int, field: str, what: str) -> InputError:
    """The error for a bad field: ``<source>:<line>: <field>: <what>``."""
    return InputError(f"{source}:{line}: {field}: {what}")


def _parsed(read: Callable[..., T], text: str, source: str, loader: type) -> T:
    """``read(text, Loader=loader)``; a syntax error is an InputError naming its line."""
    try:
        return read(text, Loader=loader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else 1
        raise fail(source, line, "yaml", f"syntax error: {exc.problem or exc}") from exc
    except yaml.YAMLError as exc:
        raise fail(source, 1, "yaml", f"syntax error: {exc}") from exc


def compose(text: str, source: str, loader: type = yaml.SafeLoader) -> Node | None:
    """The document's node tree, which keeps every line (None for an empty document)."""
    return _parsed(yaml.compose, text, source, loader)


def load(text: str, source: str, loader: type = yaml.SafeLoader) -> Any:
    """The document's value."""
    return _parsed(yaml.load, text, source, loader)


def field_name(path: FieldPath, root: str) -> str:
    """``objects.bed.count``, ``groups[2].mu``: mapping keys dotted, list indices in brackets, a trailing index left
    out (the list is the field); ``root`` for the empty path."""
    steps = list(path)
    while steps and isinstance(steps[-1], int):
        steps.pop()
    out = "".join(f"[{s}]" if isinstance(s, int) else f".{s}" for s in steps).lstrip(".")
    return out or root


def node_at(root: Node, path: FieldPath) -> tuple[Node | None, Node]:
    """The key node (None for the root and list items) and the value node at ``path``."""
    key, node = None, root
    for step in path:
        if isinstance(node, MappingNode):
            key, node = next((k, v) for k, v in node.value if k.value == step)
        else:
            key, node = None, node.value[step]
    return key, node


def line_of(root: Node, path: FieldPath, key: bool = False) -> int:
    """The 1-based line of the value at ``path`` (of its key with ``key``, where it has one)."""
    key_node, node = node_at(root, path)
    return ((key_node if key and key_node is not None else node).start_mark.line) + 1


def check_keys(node: Node, source: str, root: str, path: tuple = ()) -> None:
    """Every mapping key a non-empty string, none twice (a loaded value would silently keep the last)."""
    if isinstance(node, SequenceNode):
        for k, item in enumerate(node.value):
            check_keys(item, source, root, (*path, k))
    if not isinstance(node, MappingNode):
        return
    seen: set[str] = set()
    for key, value in node.value:
        where = field_name((*path, key.value), root)
        if key.tag != "tag:yaml.org,2002:str" or not key.value:
            raise fail(source, key.start_mark.line + 1, where, "a key must be a non-empty name")
        if key.value in seen:
            raise fail(source, key.start_mark.line + 1, where, "duplicate key")
        seen.add(key.value)
        check_keys(value, source, root, (*path, key.value))


def _located(err: jsonschema.ValidationError, root: Node, root_name: str) -> tuple[int, str, str]:
    """(line, field, what) of a schema error."""
    path = list(err.absolute_path)
    if err.validator == "additionalProperties":
        extra = next(k for k in err.instance if k not in err.schema.get("properties", {}))
        known = ", ".join(err.schema.get("properties", {}))
        where = [*path, extra]
        return line_of(root, where, key=True), field_name(where, root_name), f"unknown field (known: {known})"
    if err.validator == "required":
        missing = next(k for k in err.validator_value if k not in err.instance)
        return (line_of(root, path, key=True) if path else 1), field_name([*path, missing], root_name), "missing"
    what = f"expected a finite number, got {err.instance}" if err.validator == "format" else err.message
    return line_of(root, path), field_name(path, root_name), " ".join(what.split())[:160]


def validate(value: Any, schema: dict, source: str, root: Node | Callable[[], Node | None], root_name: str) -> None:
    """Raise the InputError of the first schema error of ``value`` in the file's order; ``root``: its node tree, or
    a function that composes it (only called on an error, as a large file composes slowly)."""
    errors = list(jsonschema.Draft202012Validator(schema, format_checker=FORMATS).iter_errors(value))
    if errors:
        tree = root if isinstance(root, Node) else root()
        if tree is None:
            raise fail(source, 1, root_name, "empty")
        line, field, what = min((_located(e, tree, root_name) for e in errors), key=lambda e: e[0])
        raise fail(source, line, field, what)
