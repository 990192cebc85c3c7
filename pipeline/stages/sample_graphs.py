"""Sample relation graphs of one room type from its trained graph model (from scratch in held-out rooms'
architectures, or completing the partial graph of ``--spec``); invalid graphs are resampled, never written."""
from __future__ import annotations

from .. import tables
from ..graphs.load import room_graphs
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, count: int | None = None, threads: int = 1) -> dict:
    from ..methods.planit.graph_model.sample import sample_room_type

    _, graphs = room_graphs(inp.nodes, inp.edges, room_type)
    rows_n, rows_e, summary = sample_room_type(config, inp.model, graphs, inp.nodes, inp.edges, room_type, inp.spec,
                                               count, threads)
    tables.write(out.nodes, "generated_nodes", tables.from_rows("generated_nodes", rows_n))
    tables.write(out.edges, "generated_edges", tables.from_rows("generated_edges", rows_e))
    tables.write_json(out.summary, summary)
    return summary
