"""Load and validate the pipeline configuration against ``config/schema.yaml``.

The same schema validates the config in the Snakefile (``snakemake.utils.validate``) and in the CLI, so a
stage run by hand sees exactly the defaults a Snakemake run sees.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import jsonschema
import yaml

SCHEMA_PATH = Path(__file__).resolve().parents[1] / "config" / "schema.yaml"


class ConfigError(ValueError):
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


_Validator = _with_defaults(jsonschema.Draft7Validator)


def load_schema() -> dict:
    with open(SCHEMA_PATH) as fh:
        return yaml.safe_load(fh)


def deep_merge(base: dict, override: dict) -> dict:
    """Return ``base`` updated recursively by ``override`` (neither is modified)."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = deep_merge(out[key], value)
        else:
            out[key] = value
    return out


def validate(config: dict, origin: str = "<config>") -> dict:
    """Validate ``config`` in place, filling defaults; raise ConfigError naming the offending key."""
    validator = _Validator(load_schema())
    errors = sorted(validator.iter_errors(config), key=lambda e: list(e.absolute_path))
    if errors:
        err = errors[0]
        key = ".".join(str(p) for p in err.absolute_path) or "<top level>"
        raise ConfigError(f"{origin}: invalid config at key '{key}': {err.message}")
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
            raise ConfigError(f"{path}: not valid YAML: {exc}") from exc
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


def config_hash(section: Any) -> str:
    """Short stable hash of a config section, stored in every output table's metadata."""
    return hashlib.sha256(json.dumps(section, sort_keys=True).encode()).hexdigest()[:12]
