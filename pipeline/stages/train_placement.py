"""Train the placement networks (location CFCN, or the unconditional FCN, and orientation) of one room type on its
training rooms; one job per room type and net."""
from __future__ import annotations

from .. import tables
from ..errors import InputError
from ..graphs.files import read_split
from ..room import load_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, net: str, threads: int = 1) -> dict:
    from ..learning.fitted import write_fitted
    from ..methods.planit.nets.fit import fit_room_type, training_rooms

    flt = [("room_type", "=", room_type)]
    node_df = tables.read(inp.nodes, "final_nodes", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{inp.nodes}: no graph of room type '{room_type}'")
    edge_df = tables.read(inp.edges, "final_edges", filters=flt).to_pandas()
    _, _, _, rooms = load_rooms(inp.rooms, inp.architecture, inp.objects, set(node_df["room_id"]))
    cats, train_rooms, held_rooms, held_ids = training_rooms(rooms, node_df, edge_df, read_split(inp.split))
    fitted = fit_room_type(config, room_type, net, cats, train_rooms, held_rooms, held_ids,
                           out.model.with_name("checkpoint.pt"), threads)
    return write_fitted(out, fitted)
