"""Generate rooms of one room type with one method (the ``method`` wildcard): its layout generator places objects
into the corpus's room architectures, from its graph generator's graphs or without; the rooms are written as
canonical tables with a record per scene and a GLB / PNG / JSON per scene."""
from __future__ import annotations

from .. import methods
from ..methods.corpus import load_corpus, load_generated
from ..methods.scenes import generate_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, method: str, count: int | None = None,
        threads: int = 1) -> dict:
    methods.load_plugins(config["generation"]["plugins"])
    spec = methods.get(method)
    corpus = load_corpus(room_type, inp)
    reference = inp.reference_rooms and load_generated(inp.reference_rooms, inp.reference_architecture,
                                                       inp.reference_objects, inp.reference_scenes)
    graphs = (inp.nodes, inp.edges) if inp.nodes else None
    task = methods.Task(config, method, corpus, graphs, inp.model, reference, count, threads, inp.program)
    return generate_rooms(methods.layout_of(spec, config), method, task, out)
