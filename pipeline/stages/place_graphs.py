"""Place given relation graphs (a spec's completions) into their rooms with PlanIT's search (variant planit)."""
from __future__ import annotations

from .. import tables
from ..methods import Task
from ..methods.corpus import load_corpus
from ..methods.scenes import generate_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, threads: int = 1) -> dict:
    from ..methods.planit.layout import PlanitLayout

    types = tables.read(inp.nodes, "generated_nodes", columns=["room_type"]).column("room_type").unique().to_pylist()
    corpus = load_corpus(str(types[0]) if types else "", inp)
    task = Task(config, "planit", corpus, (inp.nodes, inp.edges), inp.model, threads=threads)
    return generate_rooms(PlanitLayout(config, "planit"), "planit", task, out)
