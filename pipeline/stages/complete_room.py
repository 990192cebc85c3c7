"""Keep the first objects (of the placement order) of a real room where they are and place the rest of its graph
with PlanIT's search (the held-out graphs' variant)."""
from __future__ import annotations

from ..methods import Task
from ..methods.corpus import load_corpus
from ..methods.scenes import generate_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, room: str, keep: int, threads: int = 1) -> dict:
    from ..methods.planit.layout import CompleteRoom

    corpus = load_corpus(room_type, inp)
    task = Task(config, "complete", corpus, (inp.nodes, inp.edges), inp.model, threads=threads)
    return generate_rooms(CompleteRoom(config, room, keep), "complete", task, out)
