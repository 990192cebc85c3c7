"""Retrieval, the memorisation floor: each of a reference method's rooms replaced by its nearest training room under
the evaluation's layout similarity (top-down category renders, best over turns and mirrors), kept whole."""
from __future__ import annotations

from typing import Iterator

import numpy as np

from ..evaluation import render
from ..placement.layout import walls_of
from ..room import RoomInput, room_inputs
from ..tables import SCORED
from .interface import Scene, Task


class Retrieval:
    def __init__(self, config: dict, name: str):
        self.render = config["evaluate"]["render"]
        self.info = {}

    def generate(self, task: Task) -> Iterator[Scene]:
        ref, corpus = task.reference, task.corpus
        placed = set(ref.scenes.loc[ref.scenes["status"].astype(str).isin(SCORED), "scene_id"])
        queries = list(room_inputs(ref.rooms[ref.rooms["room_id"].isin(placed)], ref.architecture,
                                   ref.objects.sort_values("room_id", kind="stable")))
        train_ids = [r for r in corpus.rooms["room_id"] if corpus.split.get(r) in ("fit", "validation")]
        train = [corpus.inputs[r] for r in train_ids if r in corpus.inputs]
        parents = _parents(corpus.objects)
        index = {c: k for k, c in enumerate(sorted({c for r in (*train, *queries) for c in r.categories}))}
        label = lambda r: render.label_map(r, index, self.render["size"], self.render["mpp"])
        maps = np.stack([label(r) for r in train]) if train else np.zeros((0, 1, 1), np.int16)
        for query in queries[:task.count]:
            sim = render.similarity(label(query), maps)
            if not len(sim):
                continue
            hit = train[int(np.argmax(sim))]
            room = RoomInput(**{**vars(hit), "room_id": query.room_id})
            yield Scene(query.room_id, hit.room_id, room, walls_of(hit),
                        parents=dict(zip(hit.object_ids, parents.get(hit.room_id, []))))


def _parents(objects) -> dict[str, list]:
    """Room id -> its objects' support parents, in the objects' order."""
    objs = objects.sort_values("room_id", kind="stable")
    return {k: g["source_parent_id"].tolist() for k, g in objs.groupby("room_id", sort=False)}
