"""The seeded split of one room type's rooms (fit, validation, held-out), written once and read by every learner,
every generation method and the evaluation."""
from __future__ import annotations

from .. import tables
from ..errors import InputError
from ..graphs.data import room_splits
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str) -> dict:
    ids = tables.read(inp.nodes, "final_nodes", columns=["room_id"], filters=[("room_type", "=", room_type)])
    ids = sorted(set(ids.column("room_id").to_pylist()))
    if not ids:
        raise InputError(f"{inp.nodes}: no graph of room type '{room_type}' to split")
    gm = config["graph_model"]
    split = room_splits(ids, gm["heldout_fraction"], gm["validation_fraction"], config["seed"])
    rows = [{"room_id": r, "room_type": room_type, "split": split[r]} for r in ids]
    tables.write(out.split, "splits", tables.from_rows("splits", rows))
    return {s: sum(v == s for v in split.values()) for s in ("fit", "validation", "heldout")}
