"""The solver's state: a room's architecture and objects, each posed inside its degrees of freedom (Infinigen's
projection onto the object's assigned planes): ``floor`` (free x, y and yaw), ``wall`` (its back flush against one
wall, sliding along it, facing into the room) or ``on`` (on its support parent's top, inside its footprint). The
boxes are realised from those parameters, parents before children."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ...geometry.boxes import rotation
from ...placement.layout import with_objects
from ...placement.retrieval import Instance, place
from ...room import RoomInput, Walls

DOFS = ("floor", "wall", "on")


@dataclass(frozen=True)
class Item:
    """One object: its category, model instance and degrees of freedom. ``u``: its parameters (floor: world x, y;
    wall: the along-wall coordinate of its centre and 0; on: x, y in the parent's frame); ``yaw``: world yaw
    (floor), ignored (wall: it faces the room) or yaw relative to the parent (on)."""
    object_id: str
    category: str
    inst: Instance
    dof: str
    stage: str
    u: tuple[float, float]
    yaw: float = 0.0
    wall: int = -1
    parent: int = -1  # index of the support parent in the state's items (always before this one)


@dataclass
class State:
    """Objects in one room (its architecture: ``room`` without objects) and their realised boxes and poses."""
    room: RoomInput
    walls: Walls
    items: list[Item]
    boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 7)))  # (n, 7) BOX_COLUMNS
    poses: np.ndarray = field(default_factory=lambda: np.zeros((0, 7)))  # (n, 7) POSE_COLUMNS

    def realise(self) -> "State":
        """The state with every item's box and pose computed from its parameters."""
        boxes, poses = np.zeros((len(self.items), 7)), np.zeros((len(self.items), 7))
        for k, it in enumerate(self.items):
            boxes[k], poses[k] = item_box(it, self.walls, boxes[it.parent] if it.parent >= 0 else None)
        return State(self.room, self.walls, self.items, boxes, poses)

    def with_items(self, items: list[Item]) -> "State":
        return State(self.room, self.walls, items).realise()

    def as_room(self) -> RoomInput:
        """The room with the state's objects, as the canonical tables hold it."""
        return replace(self.room, object_ids=[i.object_id for i in self.items],
                       categories=[i.category for i in self.items], model_ids=[i.inst.model_id for i in self.items],
                       boxes=self.boxes.reshape(-1, 7), poses=self.poses.reshape(-1, 7))

    def count(self, category: str) -> int:
        return sum(i.category == category for i in self.items)


def wall_yaw(walls: Walls, w: int) -> float:
    """The yaw that turns an object's front (local +y) to wall ``w``'s inward normal."""
    n = walls.normal[w]
    return float(np.arctan2(-n[0], n[1]))


def item_box(it: Item, walls: Walls, parent_box: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Box ``(7,)`` and pose ``(7,)`` of an item (``parent_box``: its support parent's realised box, for ``on``)."""
    if it.dof == "wall":
        w = it.wall
        yaw = wall_yaw(walls, w)
        xy = walls.a[w] + walls.dir[w] * it.u[0] + walls.normal[w] * it.inst.half[1]
        return place(it.inst, xy[0], xy[1], None, yaw)
    if it.dof == "on":
        p = parent_box
        xy = p[:2] + rotation(p[6]) @ np.asarray(it.u)
        return place(it.inst, xy[0], xy[1], float(p[2] + p[5]), float(p[6] + it.yaw))
    return place(it.inst, it.u[0], it.u[1], None, it.yaw)


def empty_state(room: RoomInput, walls: Walls) -> State:
    """The room's architecture with no objects."""
    return State(with_objects(room, []), walls, [])


def wall_range(walls: Walls, w: int, inst: Instance) -> tuple[float, float]:
    """The along-wall coordinates an item's centre may take on wall ``w`` (its half width from either end)."""
    hx = inst.half[0]
    return hx, max(float(walls.length[w]) - hx, hx)


def top_range(parent: Instance, child: Instance, yaw: float = 0.0) -> np.ndarray:
    """``(2,)`` half extents of the region of the parent's top where the child's centre keeps its footprint on it,
    the child turned by ``yaw`` relative to the parent (0 where the child is the larger)."""
    half = np.abs(rotation(yaw)) @ np.asarray(child.half[:2])
    return np.maximum(np.asarray(parent.half[:2]) - half, 0.0)
