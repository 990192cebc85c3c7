"""Gather (per corpus): the refined shards in one ``nodes`` / ``edges`` / ``superstructures`` table each."""
from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc

from .. import tables
from ..stage import Files

SCHEMA_OF = {"nodes": "final_nodes", "edges": "final_edges", "superstructures": "superstructures"}


def _room_types(paths: list[Path]) -> list[str]:
    types: set[str] = set()
    for p in paths:
        types |= set(pc.unique(tables.read(p, None, columns=["room_type"]).column("room_type").cast(pa.string()))
                     .drop_null().to_pylist())
    return sorted(types)


def _parts(paths: list[Path], schema: str):
    """One part per (room type, shard), in room-type order: a row group never mixes room types, so readers
    filtering on ``room_type`` skip the others, and only one shard's rows of one type are in memory at a time."""
    for t in _room_types(paths):
        for p in paths:
            part = tables.read(p, schema, filters=[("room_type", "=", t)])
            if part.num_rows:
                yield part


def run(config: dict, inp: Files, out: Files) -> dict:
    """Stream each table's shards into one file, room type by room type (each shard keeps its room order)."""
    counts = {}
    for name, schema in SCHEMA_OF.items():
        counts[name] = tables.write_parts(out[name], schema, _parts(inp[name], schema),
                                          {"shards": str(len(inp[name]))})
    return counts
