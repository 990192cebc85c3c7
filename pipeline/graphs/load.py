"""Reading final relation graphs of one room type from the gathered tables (for every learner and metric)."""
from __future__ import annotations

from pathlib import Path

from .. import tables
from ..errors import InputError
from . import data


def room_graphs(nodes: Path, edges: Path, room_type: str) -> tuple[data.Vocab, list[data.Graph]]:
    """The room type's final graphs and their vocabulary."""
    flt = [("room_type", "=", room_type)]
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    edge_df = tables.read(edges, "final_edges", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{nodes}: no graph of room type '{room_type}' (set graph_model.room_types)")
    vocab = data.vocab_of(node_df)
    return vocab, data.graphs_from_tables(node_df, edge_df, vocab)


def read_split(path: Path) -> dict[str, str]:
    """Room id -> fit | validation | heldout, from a room type's split table."""
    rows = tables.read(path, "splits", columns=["room_id", "split"]).to_pylist()
    return {r["room_id"]: r["split"] for r in rows}


def split_ids(split: dict[str, str], *names: str) -> list[str]:
    """The sorted room ids in any of the named parts of a split."""
    return sorted(r for r, s in split.items() if s in names)
