"""A repair of GRAINS's laid-out rooms, its own option (``grains.resolve``; method ``grains`` only, the faithful
``grains_decoded`` keeps the raw decoder's layout).

Why (issue 42, docs/benchmarks.md): GRAINS's hierarchy groups the floor objects by the wall they stand against and
codes each one's place against its group only; no code relates two walls' groups, and the decoder lays each group
against its wall alone. On the default run's bedrooms 51 of 64 colliding floor-object pairs belonged to two walls'
groups (a wardrobe of one wall in the corner a dresser of the next wall also takes), 8 to pairs a code places one
against the other; and a fifth of its floor objects reach through the walls. The repair moves objects, largest
footprint first: each is first moved inside the room's rectangle, then, if it penetrates what is already kept (or
the part of the rectangle outside an L-shaped room), takes the shortest of the clearing moves
(:func:`~pipeline.geometry.boxes.clearing_moves`) that leaves the least penetration with everything kept and takes it
no further out of the rectangle; an object still colliding after ``max_moves`` moves is left out (recorded by the
caller). Objects on a support move with it. GRAINS's own rooms have no doors; laid onto a held-out room's walls, a
group can stand in front of its door, so the zone inside each door (the placement checks' door clearance) is kept
clear the same way (``grains.resolve.doors``)."""
from __future__ import annotations

import numpy as np

from ...geometry.boxes import clearing_moves, footprint_corners, from_corners, penetration_depths
from ...geometry.polygon import outside_pieces
from ...room import RoomInput, door_zones_of


def bound(box: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(2,)`` lower and upper corners (m) of the axis-aligned bound of the footprint of ``box (7,)``."""
    c = footprint_corners(box[0], box[1], box[3], box[4], box[6])[0]
    return c.min(0), c.max(0)


def outside(box: np.ndarray, rect: tuple[float, float, float, float]) -> float:
    """How far (m) the footprint of ``box (7,)`` reaches beyond ``rect = (xmin, ymin, xmax, ymax)`` (0: inside)."""
    lo, hi = bound(box)
    return float(max((np.array(rect[:2]) - lo).max(), (hi - np.array(rect[2:])).max(), 0.0))


def inside_move(box: np.ndarray, rect: tuple[float, float, float, float]) -> np.ndarray:
    """``(2,)`` the shortest move that brings the footprint of ``box (7,)`` inside ``rect`` on each axis it fits along
    (centred on an axis it does not fit along)."""
    (lo, hi), rlo, rhi = bound(box), np.array(rect[:2]), np.array(rect[2:])
    fits = hi - lo <= rhi - rlo
    return np.where(fits, np.maximum(rlo - lo, 0.0) - np.maximum(hi - rhi, 0.0), (rlo + rhi - lo - hi) / 2)


def kept_clear(room: RoomInput, rect: tuple[float, float, float, float], door_clearance: float) -> np.ndarray:
    """``(m, 7)`` what :func:`separated` keeps objects off, as boxes twice the room's height: the parts of ``rect``
    outside the room (:func:`~pipeline.geometry.polygon.outside_pieces`) and the zones ``door_clearance`` m deep inside
    its doors (:func:`~pipeline.room.door_zones_of`, the placement checks' door clearance; 0: none)."""
    pieces = np.concatenate([outside_pieces(room.outline, rect).reshape(-1, 4, 2), door_zones_of(room, door_clearance)])
    return from_corners(pieces, 0.0, 2 * float(room.height))


def beyond(room: RoomInput, rect: tuple[float, float, float, float]) -> np.ndarray:
    """``(m, 7)`` the parts of ``rect`` outside the room alone (:func:`kept_clear` with no door zones)."""
    return kept_clear(room, rect, 0.0)


def depths(kept: np.ndarray, box: np.ndarray) -> np.ndarray:
    """``(k,)`` penetration depth (m) of ``box (7,)`` into each of the ``kept (k, 7)`` boxes."""
    if not len(kept):
        return np.zeros(0)
    return penetration_depths(np.vstack([kept, box]))[-1, :-1]


def best_move(kept: np.ndarray, box: np.ndarray, rect: tuple[float, float, float, float],
              margin: float) -> np.ndarray | None:
    """``(2,)`` the move of ``box`` off the kept box it penetrates deepest (to touching) that leaves the least total
    penetration with ``kept (k, 7)`` (the shorter on a tie) and reaches no further out of ``rect`` than ``box`` does
    (or ``margin`` m); None when every move would."""
    reach = max(outside(box, rect), margin)
    best, score = None, None
    for move in clearing_moves(kept[int(np.argmax(depths(kept, box)))], box):
        moved = box.copy()
        moved[:2] += move
        if outside(moved, rect) > reach:
            continue
        key = (round(float(depths(kept, moved).sum()), 6), float(np.linalg.norm(move)))
        if score is None or key < score:
            best, score = move, key
    return best


def separated(boxes: np.ndarray, floor: list[int], rect: tuple[float, float, float, float], margin: float,
              max_moves: int, fixed: np.ndarray | None = None) -> tuple[np.ndarray, list[int]]:
    """``(n, 2)`` the floor move of each of ``boxes (n, 7)``'s ``floor`` objects (0 for the rest) and the floor objects
    left out, so that each kept floor box lies inside ``rect`` where it fits and no two kept floor boxes, nor a kept
    one and a ``fixed (m, 7)`` box (what of the rectangle lies outside the room), penetrate deeper than ``margin`` m
    (the placement checks' collision depth: a nightstand flush with its bed stays); the largest footprints are kept
    first."""
    moves = np.zeros((len(boxes), 2))
    kept: list[int] = []
    dropped: list[int] = []
    fixed = np.zeros((0, 7)) if fixed is None else np.asarray(fixed, float).reshape(-1, 7)
    for k in sorted(floor, key=lambda k: -4 * boxes[k, 3] * boxes[k, 4]):
        placed = np.vstack([fixed, boxes[kept]])
        placed[len(fixed):, :2] += moves[kept]
        box = boxes[k].copy()
        box[:2] += inside_move(box, rect)
        for _ in range(max_moves):
            move = best_move(placed, box, rect, margin) if (depths(placed, box) > margin).any() else None
            if move is None:
                break
            box[:2] += move
        if (depths(placed, box) > margin).any():
            dropped.append(k)
            continue
        moves[k] = box[:2] - boxes[k, :2]
        kept.append(k)
    return moves, dropped
