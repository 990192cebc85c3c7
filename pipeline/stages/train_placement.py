"""Train one placement learner of one room type on its training rooms and final graphs (the ``net`` wildcard: PlanIT's
location CFCN or unconditional FCN with the orientation network, or the string method's edge tagger); one job per
room type and learner."""
from __future__ import annotations

from ..graphs.files import graphs_and_rooms, read_split
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, net: str, threads: int = 1) -> dict:
    from .. import methods
    from ..learning.fitted import write_fitted
    from ..methods.interface import RoomTypeRows

    fit = methods.placement_fit(net)
    node_df, edge_df, rooms = graphs_and_rooms(inp.nodes, inp.edges, inp.rooms, inp.architecture, inp.objects,
                                               room_type)
    data = RoomTypeRows(node_df, edge_df, rooms, read_split(inp.split))
    fitted = fit(config, room_type, net, data, out.model.with_name("checkpoint.pt"), threads)
    return write_fitted(out, fitted)
