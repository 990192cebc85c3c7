"""Train the graph model of one room type on the final graphs of its fit split (kept edges); one job per room type."""
from __future__ import annotations

from .. import tables
from ..graphs.load import read_split, room_graphs
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, threads: int = 1) -> dict:
    """Write the best weights (with vocabulary, split, the test NLL and seen edge types), the loss curves and a
    summary. The checkpoint beside ``out.model`` resumes an interrupted run with the same settings."""
    from ..learning import checkpoint
    from ..methods.planit.graph_model.fit import fit_room_type

    vocab, graphs = room_graphs(inp.nodes, inp.edges, room_type)
    fitted = fit_room_type(config, vocab, graphs, read_split(inp.split), room_type,
                           out.model.with_name("checkpoint.pt"), threads)
    checkpoint.save(out.model, fitted.checkpoint)
    tables.write_csv(out.history, fitted.history)
    tables.write_figure(out.curve, fitted.curve)
    tables.write_json(out.summary, fitted.summary)
    return fitted.summary
