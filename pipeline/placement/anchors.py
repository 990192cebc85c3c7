"""What constrains the object being placed: its anchors, the placed nodes (objects or walls) with a planned edge to or
from it (PlanIT section 6 conditions on inbound neighbours; here every planned edge to what is already placed counts:
spatial edges into it, spatial edges out of it to a placed object, and the support edge from its parent)."""
from __future__ import annotations

from dataclasses import dataclass

from ..geometry.frames import Frame
from ..room import RoomInput, Walls
from .layout import box_frame, wall_frame
from .plan import PlanEdge, ScenePlan

SUPPORT = "support"


@dataclass
class Anchor:
    """A placed node with a planned edge to (or, ``reverse``, from) the object being placed. ``direction`` and
    ``distance`` are the edge's labels (None for a support edge, ``kind`` "support"): in the anchor's frame for an
    edge from the anchor, in the placed object's frame for a reverse one."""
    node: str
    frame: Frame
    symmetry: str
    direction: str | None
    distance: str | None
    obj: int | None = None  # index among the room's objects
    wall: int | None = None  # index among the room's walls
    target_half: tuple[float, float] = (0.0, 0.0)  # half extents (x, y) of the object being placed
    kind: str = "spatial"  # spatial | support
    reverse: bool = False  # the edge runs from the placed object to the anchor

    @property
    def edge(self) -> str:
        """The edge's type name: ``direction/distance`` or ``support``."""
        return SUPPORT if self.kind == SUPPORT else f"{self.direction}/{self.distance}"


def anchors_of(v: str, plan: ScenePlan, room: RoomInput, walls: Walls, sym: dict[str, str],
               half: tuple[float, float] = (0.0, 0.0), reverse: bool = True) -> list[Anchor]:
    """The placed objects and walls with a planned edge to ``v`` (whose half extents are ``half``): spatial edges into
    ``v``, its support edge, and (``reverse``) spatial edges from ``v`` to a placed object."""
    obj = {o: k for k, o in enumerate(room.object_ids)}
    wall = {w: k for k, w in enumerate(walls.ids)}
    out = []
    for e in plan.edges:
        if e.target == v and e.source in obj:
            k = obj[e.source]
            out.append(Anchor(e.source, box_frame(room.boxes[k]), sym.get(e.source, "none"), e.direction, e.distance,
                              obj=k, target_half=half, kind=e.edge_type))
        elif e.target == v and e.source in wall and e.edge_type == "spatial":
            k = wall[e.source]
            out.append(Anchor(e.source, wall_frame(walls, k), "none", e.direction, e.distance, wall=k, target_half=half))
        elif reverse and e.source == v and e.target in obj and e.edge_type == "spatial":
            k = obj[e.target]
            out.append(Anchor(e.target, box_frame(room.boxes[k]), sym.get(e.target, "none"), e.direction, e.distance,
                              obj=k, target_half=half, reverse=True))
    return out


def planned_edges(v: str, plan: ScenePlan, present: set[str]) -> list[PlanEdge]:
    """Planned support and spatial edges between ``v`` and nodes already present (objects or walls)."""
    return [e for e in plan.edges if (e.target == v and e.source in present) or (e.source == v and e.target in present)]
