"""Learn one room type's readable program (the ``program`` wildcard: Infinigen's constraint program or S-AOG's
grammar) from its training rooms and final graphs; one job per room type and learner."""
from __future__ import annotations

from .. import tables
from ..errors import InputError
from ..graphs.files import read_split
from ..room import load_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, program: str) -> dict:
    from .. import methods

    fit = methods.program_fit(program)
    flt = [("room_type", "=", room_type)]
    node_df = tables.read(inp.nodes, "final_nodes", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{inp.nodes}: no graph of room type '{room_type}'")
    edge_df = tables.read(inp.edges, "final_edges", filters=flt).to_pandas()
    _, _, _, rooms = load_rooms(inp.rooms, inp.architecture, inp.objects, set(node_df["room_id"]))
    text, summary = fit(config, room_type, node_df, edge_df, rooms, read_split(inp.split))
    tables.write_text(out.program, text)
    tables.write_json(out.summary, summary)
    return summary
