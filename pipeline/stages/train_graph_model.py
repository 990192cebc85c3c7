"""Train a graph generator (PlanIT's graph model, the string VAE) of one room type on the final graphs of its fit split
(kept edges); one job per room type."""
from __future__ import annotations

from ..graphs.files import read_split, room_graphs
from ..methods import graph_generator
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, generator: str = "planit", threads: int = 1) -> dict:
    """Write the best weights (with vocabulary, split, the test NLL and seen edge types), the loss curves and a
    summary. The checkpoint beside ``out.model`` resumes an interrupted run with the same settings."""
    from ..learning.fitted import write_fitted

    vocab, graphs = room_graphs(inp.nodes, inp.edges, room_type)
    fitted = graph_generator(generator).fit(config, vocab, graphs, read_split(inp.split), room_type,
                                           out.model.with_name("checkpoint.pt"), threads)
    return write_fitted(out, fitted)
