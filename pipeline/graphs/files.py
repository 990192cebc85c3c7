"""Relation-graph files of one room type: reading final graphs and splits (every learner and metric), writing sampled
graphs (every graph generator), the room type a partial-graph spec names."""
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


def graphs_and_rooms(nodes: Path, edges: Path, rooms: list[Path], architecture: list[Path], objects: list[Path],
                     room_type: str):
    """The room type's final graph rows (nodes, edges frames) and its graphed rooms (room id -> RoomInput): what
    every learner of a room type's rooms reads."""
    from ..room import load_rooms

    flt = [("room_type", "=", room_type)]
    node_df = tables.read(nodes, "final_nodes", filters=flt).to_pandas()
    if node_df.empty:
        raise InputError(f"{nodes}: no graph of room type '{room_type}'")
    edge_df = tables.read(edges, "final_edges", filters=flt).to_pandas()
    _, _, _, inputs = load_rooms(rooms, architecture, objects, set(node_df["room_id"]))
    return node_df, edge_df, inputs


def read_split(path: Path) -> dict[str, str]:
    """Room id -> fit | validation | heldout, from a room type's split table."""
    rows = tables.read(path, "splits", columns=["room_id", "split"]).to_pylist()
    return {r["room_id"]: r["split"] for r in rows}


def split_graphs(graphs: list[data.Graph], split: dict[str, str], room_type: str) -> dict[str, list[data.Graph]]:
    """The room type's graphs in each part of its split (``fit``, ``validation``, ``heldout``, sorted by room id); an
    :class:`InputError` when a part is empty (a learner needs all three)."""
    by_id = {g.room_id: g for g in graphs}
    parts = {s: [by_id[r] for r in sorted(by_id) if split.get(r) == s] for s in ("fit", "validation", "heldout")}
    if not all(parts.values()):
        raise InputError(f"room type '{room_type}' has {len(graphs)} graph(s); training needs 3 or more "
                         "(fitted, validation and held-out)")
    return parts


def write_graphs(out, nodes: list[dict], edges: list[dict], summary: dict) -> None:
    """Sampled graphs as generated_nodes / generated_edges tables and their sampling summary (``out``: nodes, edges,
    summary)."""
    tables.write(out.nodes, "generated_nodes", tables.from_rows("generated_nodes", nodes))
    tables.write(out.edges, "generated_edges", tables.from_rows("generated_edges", edges))
    tables.write_json(out.summary, summary)


def spec_room_type(spec: Path) -> str:
    """The room type a partial-graph spec names (the spec is validated in full when sampling)."""
    import yaml

    try:
        value = (yaml.safe_load(Path(spec).read_text()) or {}).get("room_type")
    except (OSError, yaml.YAMLError, AttributeError) as exc:
        raise InputError(f"{spec}: cannot read the spec ({exc})") from exc
    if not isinstance(value, str):
        raise InputError(f"{spec}: room_type: missing (a room type such as bedroom)")
    return value
