"""Load and validate the pipeline configuration against the package's ``schema.yaml`` (JSON Schema 2020-12).

The same validator runs in the Snakefile (``rules/common.smk``) and in the CLI, so a stage run by hand sees
exactly the defaults a Snakemake run sees, and a bad value gives the same one-line message in both. The
schema is package data (``importlib.resources``), so an installed wheel validates without the source tree;
``config/schema.yaml`` links to it.
"""
from __future__ import annotations

import hashlib
import json
from importlib import resources
from pathlib import Path
from typing import Any, Iterable

import jsonschema
import yaml

from .errors import PlanitError


class ConfigError(PlanitError):
    """The configuration is invalid; the message names the file and the offending key."""


def _with_defaults(validator_class):
    validate_properties = validator_class.VALIDATORS["properties"]

    def set_defaults(validator, properties, instance, schema):
        if isinstance(instance, dict):
            for name, sub in properties.items():
                if "default" in sub and name not in instance:
                    instance[name] = json.loads(json.dumps(sub["default"]))
        yield from validate_properties(validator, properties, instance, schema)

    return jsonschema.validators.extend(validator_class, {"properties": set_defaults})


_Validator = _with_defaults(jsonschema.Draft202012Validator)
_SCHEMA: dict | None = None


def load_schema() -> dict:
    """The configuration schema shipped inside the package."""
    global _SCHEMA
    if _SCHEMA is None:
        _SCHEMA = yaml.safe_load(resources.files("pipeline").joinpath("schema.yaml").read_text())
    return _SCHEMA


def deep_merge(base: dict, override: dict) -> dict:
    """Return ``base`` updated recursively by ``override`` (neither is modified)."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = value
    return out


def _one_line(message: str, limit: int = 160) -> str:
    message = " ".join(message.split())
    return message if len(message) <= limit else message[: limit - 3] + "..."


def validate(config: dict, origin: str = "<config>") -> dict:
    """Validate ``config`` in place, filling defaults; raise ConfigError naming the offending key in one line."""
    validator = _Validator(load_schema())
    errors = sorted(validator.iter_errors(config), key=lambda e: list(e.absolute_path))
    if errors:
        err = errors[0]
        key = ".".join(str(p) for p in err.absolute_path) or "<top level>"
        raise ConfigError(f"{origin}: invalid config at key '{key}': {_one_line(err.message)}")
    return config


def load(path: str | Path | None = None, overrides_json: str | None = None) -> dict:
    """Load the YAML config at ``path`` (or the defaults), apply a JSON override string, validate."""
    config: dict[str, Any] = {}
    origin = "<defaults>"
    if path is not None:
        origin = str(path)
        try:
            with open(path) as fh:
                config = yaml.safe_load(fh) or {}
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read config: {exc.strerror}") from exc
        except yaml.YAMLError as exc:
            raise ConfigError(f"{path}: not valid YAML: {_one_line(str(exc))}") from exc
        if not isinstance(config, dict):
            raise ConfigError(f"{path}: the config must be a mapping at the top level")
    if overrides_json:
        try:
            overrides = json.loads(overrides_json)
        except json.JSONDecodeError as exc:
            raise ConfigError(f"--config-json: not valid JSON: {exc}") from exc
        config = deep_merge(config, overrides)
        origin += " + --config-json"
    return validate(config, origin)


def pick(config: dict, keys: Iterable[str]) -> dict:
    """The nested sub-config holding exactly the dotted ``keys`` (``"extract.support"``, ``"seed"``).

    A Snakemake rule passes this as its params, so the rule reruns exactly when a key it reads changes.
    """
    out: dict = {}
    for key in keys:
        parts = key.split(".")
        value: Any = config
        for p in parts:
            if not isinstance(value, dict) or p not in value:
                raise ConfigError(f"no config key '{key}'")
            value = value[p]
        node = out
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        node[parts[-1]] = value
    return out


def restrict(config: dict, shape: dict) -> dict:
    """``config`` cut down to the keys that ``shape`` (a nested dict, e.g. a rule's params) holds."""
    return {k: restrict(config[k], v) if isinstance(v, dict) and v and isinstance(config.get(k), dict) else config[k]
            for k, v in shape.items()}


def config_hash(section: Any) -> str:
    """Short stable hash of a config section, stored in every output table's metadata."""
    return hashlib.sha256(json.dumps(section, sort_keys=True).encode()).hexdigest()[:12]


def candidate_room_types(config: dict) -> list[str]:
    """Room types to learn: ``graph_model.room_types``; else, for the procedural corpus, the types it builds rooms
    of; else every type the filter knows. A type whose rooms are too few is skipped by the ``room_types`` rule."""
    if config["graph_model"]["room_types"]:
        return list(config["graph_model"]["room_types"])
    if config["source"] == "procedural":
        return [t for t, n in config["procedural"]["rooms"].items() if n > 0]
    return list(config["filter"]["min_floor_objects"])
