"""The GRAINS method: hierarchies decoded from the VAE's prior (a depth cap), each laid onto a held-out room: the
decoded walls' groups go onto the room's bounding rectangle's walls (GRAINS decodes its own walls; the re-anchoring
is a departure), each leaf takes the training instance of its label nearest to its decoded size (retrieval as
PlanIT's). GRAINS checks no collisions; our repair (``grains.resolve``, :mod:`.resolve`) moves colliding floor objects
apart and leaves out one it cannot clear, and the evaluation measures what is left.

:class:`GrainsDecoded` is the faithful mode (method ``grains_decoded``): each tree furnishes the rectangle its own
root decodes (:func:`.hierarchy.decoded_room`: no doors or windows), written as the scene's own architecture, with
GRAINS's retrieval and no repair: the raw decoder's rooms."""
from __future__ import annotations

import json
import time
from typing import Iterator

import numpy as np
import torch

from ...learning import checkpoint
from ...log import progress
from ...placement.layout import add_object, walls_of, with_objects
from ...placement.retrieval import ModelPool, nearest, nearest_within, place
from ...room import RoomInput
from ...seeding import seed_of
from ..interface import Scene, Task
from ..placing import load_context
from .hierarchy import Node, anchor, decoded_room, layout, leaves, room_rect
from .resolve import kept_clear, separated
from .train import KIND, build_model


def supports(tree: Node) -> dict[int, int]:
    """Leaf index (depth first, as ``layout`` lists them) -> the index of the leaf it stands on."""
    out: dict[int, int] = {}
    order: dict[int, int] = {}

    def walk(node: Node) -> None:
        if node.kind == "leaf":
            order[id(node)] = len(order)
            return
        for child in node.children:
            walk(child)
        if node.kind == "support":
            out[id(anchor(node.children[1]))] = id(anchor(node.children[0]))

    walk(tree)
    return {order[c]: order[p] for c, p in out.items() if c in order and p in order}


def retrieved_boxes(placed: list, insts: list, on: dict[int, int]) -> np.ndarray:
    """``(n, 7)`` the decoded leaves' boxes with the half extents of the instance each retrieved (a floor object's
    bottom kept on the floor; a leaf with none keeps its decoded box)."""
    boxes = np.array([box for _, _, box in placed], float).reshape(-1, 7)
    for k, inst in enumerate(insts):
        if inst is not None:
            boxes[k, 3:6] = inst.half
            if k not in on:
                boxes[k, 2] = inst.half[2]
    return boxes


def root_of(k: int, on: dict[int, int]) -> int:
    """The floor leaf under leaf ``k``'s stack of supports (``k`` itself on the floor)."""
    while k in on:
        k = on[k]
    return k


def furnish(tree: Node, room, pool: ModelPool, prefix: str, snap: bool = False, retrieval: str = "nearest",
            resolve: dict | None = None):
    """The room (its architecture) with the tree's leaves laid onto its bounding rectangle, each object's support
    parent id, and the objects left out (``drops`` rows). Leaves whose label has no training instance are left out
    unrecorded (the training split lacks them). ``snap``: the codes' bits win over their reals
    (:func:`.relpos.decode`); ``retrieval``: ``nearest`` (GRAINS's) or ``within`` (the nearest whose footprint fits the
    decoded one, :func:`~pipeline.placement.retrieval.nearest_within`); ``resolve``: ``grains.resolve`` with the
    collision depth as ``margin`` and the door clearance as ``door_clearance`` (enabled: floor objects moved inside the
    room's rectangle and off each other, off what of the rectangle lies outside the room and, with ``doors``, off the
    zone inside each door, :func:`.resolve.separated`; one still colliding is left out, cause ``overlap``, with what
    stands on it, cause ``support_dropped``)."""
    rect = room_rect(room)
    placed = layout(tree, rect, snap)
    on = supports(tree)
    pick = nearest_within if retrieval == "within" else nearest
    insts = [pick(pool, label, box[3:6]) for label, _, box in placed]
    moves, overlapping = np.zeros((len(placed), 2)), []
    if resolve and resolve["enabled"]:
        floor = [k for k, inst in enumerate(insts) if inst is not None and k not in on]
        fixed = kept_clear(room, rect, resolve["door_clearance"] if resolve["doors"] else 0.0)
        moves, overlapping = separated(retrieved_boxes(placed, insts, on), floor, rect, resolve["margin"],
                                       resolve["max_moves"], fixed)
    out, ids, parents, drops = with_objects(room, []), {}, {}, []
    for k, (label, _, box) in enumerate(placed):
        inst = insts[k]
        if inst is None:
            continue
        if k in overlapping or (k in on and on[k] not in ids):
            drops.append({"id": f"{prefix}_{k:02d}_{label}", "category": label,
                          "cause": "overlap" if k in overlapping else "support_dropped", "check": None})
            continue
        top = None
        if k in on:
            pb = out.boxes[out.object_ids.index(ids[on[k]])]
            top = float(pb[2] + pb[5])
        ids[k] = f"{prefix}_{k:02d}_{label}"
        parents[ids[k]] = ids[on[k]] if k in on else None
        x, y = box[:2] + moves[root_of(k, on)]
        out = add_object(out, ids[k], label, inst.model_id, *place(inst, x, y, top, box[6]))
    return out, parents, drops


class GrainsLayout:
    """``grains.scenes`` hierarchies decoded from the prior, laid onto the held-out rooms in turn."""
    rooms_info = "held-out rooms' bounding rectangles"
    own_architecture = False
    faithful = False  # the faithful mode retrieves GRAINS's way (the nearest size) and repairs nothing, whatever
    # grains.retrieval and grains.resolve say

    def __init__(self, config: dict, name: str):
        self.config, self.name, self.cfg = config, name, config["grains"]
        self.retrieval = "nearest" if self.faithful else self.cfg["retrieval"]
        checks = config["instantiate"]["checks"]
        self.resolve = None if self.faithful else {**self.cfg["resolve"], "margin": checks["collision"],
                                                    "door_clearance": checks["door_clearance"]}
        self.info = {"max_depth": self.cfg["max_depth"], "snap": self.cfg["snap"], "rooms": self.rooms_info,
                     "retrieval": self.retrieval, "resolve": self.resolve}

    def room_for(self, tree: Node, k: int, scene_id: str, rooms: list[RoomInput]) -> RoomInput:
        """The architecture scene ``k`` is laid onto: the held-out ``rooms`` in turn."""
        return rooms[k % len(rooms)]

    def generate(self, task: Task) -> Iterator[Scene]:
        torch.set_num_threads(task.threads)
        saved = checkpoint.load(task.model, KIND)
        model = build_model(saved.record["labels"], saved.record["preset"])
        model.load_state_dict(saved.state["model"])
        model.eval()
        ctx = load_context(self.config, task.corpus)
        rooms, count = task.corpus.heldout(), task.count or self.cfg["scenes"]
        if not rooms:
            return
        # one seed for both modes: grains and grains_decoded furnish the same trees, in different rooms
        gen = torch.Generator().manual_seed(seed_of(self.config["seed"], "grains"))
        start = time.perf_counter()
        trees = model.decode(torch.randn(count, model.sizes.root_feature, generator=gen), self.cfg["max_depth"])
        decode_s = (time.perf_counter() - start) / count  # decoded in one batch: each scene's share
        for i, tree in enumerate(progress(trees, total=count, desc=f"{self.name} {task.corpus.room_type}")):
            start = time.perf_counter()
            sid = f"gen_{task.corpus.room_type}_{i:05d}"
            room = self.room_for(tree, i, sid, rooms)
            placed, parents, drops = furnish(tree, room, ctx.pool, sid, self.cfg["snap"], self.retrieval, self.resolve)
            record = {"seconds": decode_s + time.perf_counter() - start, "planned_objects": len(leaves(tree)),
                      "drops": json.dumps(drops)}
            own = self.own_architecture
            status, reason = ("partial", "left out: " + ", ".join(d["id"] for d in drops)) if drops else ("placed", None)
            yield Scene(sid, None if own else room.room_id, placed, walls_of(placed), status, reason, record=record,
                        parents=parents, own_architecture=own)


class GrainsDecoded(GrainsLayout):
    """GRAINS's faithful mode: each tree furnishes the room its own root and walls decode."""
    rooms_info = "the rooms the trees decode (own walls, no doors or windows)"
    own_architecture = True
    faithful = True

    def room_for(self, tree: Node, k: int, scene_id: str, rooms: list[RoomInput]) -> RoomInput:
        """The room ``tree`` decodes, of the held-out rooms' type."""
        return decoded_room(tree, scene_id, rooms[0].room_type)
