"""Sample relation graphs of one room type from a trained graph generator, in held-out rooms' architectures; invalid
graphs are resampled (a budget), never written."""
from __future__ import annotations

from ..graphs.files import room_graphs, write_graphs
from ..methods import graph_generator
from ..methods.interface import GraphRequest
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, count: int | None = None, generator: str = "planit",
        threads: int = 1) -> dict:
    _, graphs = room_graphs(inp.nodes, inp.edges, room_type)
    request = GraphRequest(inp.model, graphs, inp.nodes, inp.edges, room_type, inp.spec, count)
    rows_n, rows_e, summary = graph_generator(generator).sample(config, request, threads)
    write_graphs(out, rows_n, rows_e, summary)
    return summary
