"""Complete a partial relation graph (a YAML spec, examples in config/specs/) with its room type's graph model:
every object and relation of the spec is kept, the model adds the rest."""
from __future__ import annotations

from ..graphs.files import room_graphs, spec_room_type, write_graphs
from ..methods import graph_generator
from ..methods.interface import GraphRequest
from ..stage import Files


def run(config: dict, inp: Files, out: Files, spec: str, count: int | None = None, threads: int = 1) -> dict:
    room_type = spec_room_type(inp.spec_file)
    _, graphs = room_graphs(inp.nodes, inp.edges, room_type)
    count = count or config["graph_model"]["sample"]["spec_graphs"]
    request = GraphRequest(inp.model, graphs, inp.nodes, inp.edges, room_type, inp.spec_file, count, f"spec_{spec}")
    rows_n, rows_e, summary = graph_generator("planit").sample(config, request, threads)
    write_graphs(out, rows_n, rows_e, summary)
    return summary
