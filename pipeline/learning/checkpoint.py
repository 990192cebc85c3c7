"""Typed checkpoints: the one place that saves and loads a learner's weights.

A checkpoint holds its ``kind`` (which learner wrote it, and whether it is a finished model or a training
progress file), the ``config_hash`` of the settings it was trained with, its ``state`` (tensors: state dicts of
networks and optimisers) and its ``record`` (JSON: ids, presets, categories, history). Files are written
atomically and read with ``torch.load(weights_only=True)``, so loading runs no pickled code. A file of another
kind, or (when asked) of other settings, is refused with one line naming the file.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from .. import tables
from ..errors import InputError

FORMAT = 1


@dataclass
class Checkpoint:
    kind: str  # e.g. "graph_model", "graph_model.progress", "placement_nets", "placement_nets.progress"
    config_hash: str
    state: dict = field(default_factory=dict)  # name -> state dict (tensors) or list of state dicts
    record: dict = field(default_factory=dict)  # JSON-serialisable training record


def save(path: Path, ckpt: Checkpoint) -> Path:
    """Write ``ckpt`` atomically to ``path``."""
    payload = {"format": FORMAT, "kind": ckpt.kind, "config_hash": ckpt.config_hash, "state": ckpt.state,
               "record": json.dumps(ckpt.record, default=_plain)}
    return tables.write_atomic(path, lambda tmp: torch.save(payload, tmp))


def load(path: Path, kind: str, config_hash: str | None = None, device: str = "cpu") -> Checkpoint:
    """The checkpoint at ``path``; an :class:`InputError` naming the file if it is unreadable, of another ``kind``,
    or (``config_hash`` given) trained with other settings."""
    ckpt = _read(Path(path), device)
    if ckpt.kind != kind:
        raise InputError(f"{path}: a '{ckpt.kind}' checkpoint, not a '{kind}' one")
    if config_hash is not None and ckpt.config_hash != config_hash:
        raise InputError(f"{path}: trained with other settings (config hash {ckpt.config_hash}, expected {config_hash}); "
                         "retrain it")
    return ckpt


def resume(path: Path, kind: str, config_hash: str, device: str = "cpu") -> Checkpoint | None:
    """A training progress file to resume from: None when there is none, or it is of other settings or another kind
    (training then starts afresh)."""
    path = Path(path)
    if not path.exists():
        return None
    try:
        return load(path, kind, config_hash, device)
    except InputError:
        return None


def _plain(value):
    """NumPy scalars and arrays in a record as plain JSON values."""
    if isinstance(value, (np.generic, np.ndarray)):
        return value.tolist()
    raise TypeError(f"a checkpoint record holds a {type(value).__name__}, which is not JSON")


def _read(path: Path, device: str) -> Checkpoint:
    try:
        raw = torch.load(path, map_location=device, weights_only=True)
    except FileNotFoundError:
        raise InputError(f"{path}: no such checkpoint; train it first") from None
    except Exception as exc:  # noqa: BLE001 (torch raises many kinds for a foreign or damaged file)
        raise InputError(f"{path}: not a readable planit checkpoint ({type(exc).__name__}: "
                         f"{str(exc).splitlines()[0][:200]})") from None
    if not isinstance(raw, dict) or raw.get("format") != FORMAT or not {"kind", "config_hash", "state", "record"} <= set(raw):
        raise InputError(f"{path}: not a planit checkpoint (format {FORMAT}); retrain it")
    return Checkpoint(raw["kind"], raw["config_hash"], raw["state"], json.loads(raw["record"]))
