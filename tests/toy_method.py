"""A toy generation method, registered through the interface alone (docs/adding-a-method.md walks through it): per
held-out room, a uniform random number of objects drawn from the training rooms' objects, each at a uniform random
position and turn inside the room's bounding box. It learns nothing and checks nothing."""
from __future__ import annotations

import numpy as np

from pipeline import methods
from pipeline.geometry.boxes import rotation
from pipeline.placement.layout import walls_of
from pipeline.room import RoomInput


class UniformRandom:
    def __init__(self, config: dict, name: str):
        self.seed, self.info = config["seed"], {"counts": "uniform", "positions": "uniform"}

    def generate(self, task: methods.Task):
        rng = np.random.default_rng([self.seed, 77])
        train = task.corpus.training()
        pool = [(c, m, b, p) for r in train for c, m, b, p in zip(r.categories, r.model_ids, r.boxes, r.poses)]
        counts = [len(r.object_ids) for r in train]
        for room in task.corpus.heldout()[:task.count]:
            picks = [pool[i] for i in rng.integers(len(pool), size=int(rng.integers(min(counts), max(counts) + 1)))]
            xy = rng.uniform(room.outline.min(0), room.outline.max(0), size=(len(picks), 2))
            turn = rng.uniform(0, 2 * np.pi, len(picks))
            boxes = np.array([[*at, b[2], *b[3:6], b[6] + t] for (_, _, b, _), at, t in zip(picks, xy, turn)])
            poses = np.array([[*(at + rotation(t) @ (p[:2] - b[:2])), p[2], p[3] + t, *p[4:]]
                              for (_, _, b, p), at, t in zip(picks, xy, turn)])
            scene = f"toy_{room.room_id}"
            placed = RoomInput(**{**vars(room), "room_id": scene, "object_ids": [f"o{k}" for k in range(len(picks))],
                                  "categories": [c for c, *_ in picks], "model_ids": [m for _, m, *_ in picks],
                                  "boxes": boxes.reshape(-1, 7), "poses": poses.reshape(-1, 7)})
            yield methods.Scene(scene, room.room_id, placed, walls_of(room))


methods.register(methods.Method("toy", "toy_method:UniformRandom",
                                description="uniform random objects from the training rooms, no training"))
