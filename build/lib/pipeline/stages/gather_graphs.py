"""Gather (per corpus): the refined shards in one ``nodes`` / ``edges`` / ``superstructures`` table each."""
from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc

from .. import tables

SCHEMA_OF = {"nodes": "final_nodes", "edges": "final_edges", "superstructures": "superstructures"}


def run(inputs: dict[str, list[Path]], outputs: dict[str, Path]) -> dict:
    """Concatenate each table's shards, sorted by room type then room (so ``filters=[('room_type', '=', t)]`` skips
    row groups of other types; the order within a room is kept)."""
    counts = {}
    for name, schema in SCHEMA_OF.items():
        table = tables.read_many(inputs[name], schema)
        if table.num_rows:
            keys = pa.table({"t": table["room_type"].cast(pa.string()), "r": table["room_id"],
                             "i": pa.array(range(table.num_rows))})
            table = table.take(pc.sort_indices(keys, sort_keys=[("t", "ascending"), ("r", "ascending"), ("i", "ascending")]))
        tables.write(outputs[name], schema, table, {"shards": str(len(inputs[name]))})
        counts[name] = table.num_rows
    return counts
