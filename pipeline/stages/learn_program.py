"""Learn one room type's readable program (the ``program`` wildcard: Infinigen's constraint program or S-AOG's
grammar) from its training rooms and final graphs; one job per room type and learner."""
from __future__ import annotations

from ..graphs.files import graphs_and_rooms, read_split
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, program: str) -> dict:
    from .. import methods, tables

    fit = methods.program_fit(program)
    node_df, edge_df, rooms = graphs_and_rooms(inp.nodes, inp.edges, inp.rooms, inp.architecture, inp.objects,
                                               room_type)
    text, summary = fit(config, room_type, node_df, edge_df, rooms, read_split(inp.split))
    tables.write_text(out.program, text)
    tables.write_json(out.summary, summary)
    return summary
