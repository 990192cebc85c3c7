"""Place the held-out rooms' own final graphs under one of PlanIT's Table 3 ablations (``instantiate.variants`` of
held-out graphs): PlanIT's layout generator with the variant's settings, written like every method's rooms."""
from __future__ import annotations

from ..methods import Task
from ..methods.corpus import load_corpus
from ..methods.scenes import generate_rooms
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str, variant: str, count: int | None = None,
        threads: int = 1) -> dict:
    from ..methods.planit.layout import PlanitLayout

    corpus = load_corpus(room_type, inp)
    task = Task(config, variant, corpus, (inp.nodes, inp.edges), inp.model, count=count, threads=threads)
    return generate_rooms(PlanitLayout(config, variant), variant, task, out)
