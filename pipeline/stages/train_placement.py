"""Train one placement learner of one room type on its training rooms and final graphs (the ``net`` wildcard: PlanIT's
location CFCN or unconditional FCN with the orientation network, or the string method's edge tagger); one job per
room type and learner."""
from __future__ import annotations

from .. import tables
from ..errors import InputError
from ..graphs.files import read_split
from ..room import load_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, net: str, threads: int = 1) -> dict:
    from .. import methods
    from ..learning.fitted import write_fitted

    fit = methods.placement_fit(net)
    flt = [("room_type", "=", room_type)]
    node_df = tables.read(inp.nodes, "final_nodes", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{inp.nodes}: no graph of room type '{room_type}'")
    edge_df = tables.read(inp.edges, "final_edges", filters=flt).to_pandas()
    _, _, _, rooms = load_rooms(inp.rooms, inp.architecture, inp.objects, set(node_df["room_id"]))
    fitted = fit(config, room_type, net, node_df, edge_df, rooms, read_split(inp.split),
                 out.model.with_name("checkpoint.pt"), threads)
    return write_fitted(out, fitted)
