"""How far a supported object may overhang its support, learned from the training rooms: PlanIT's check asks every
supported object to keep ``checks.min_support`` (0.9) of its footprint over its support, but real rooms hold
televisions wider than their stands and plants wider than their shelves. Per category, the share a training room
shows at its low end (the ``quantile`` of the shares seen, over at least ``min_pairs`` supported objects) lowers the
check for that category, never raises it, and never below ``least`` (0.5: half the footprint over the support)
(docs/departures.md).

A training object's support is geometric: the object whose box top lies within ``tolerance`` m of its bottom and
whose footprint holds the most of it; the share is the check's own :func:`~pipeline.placement.checks.support_share`.

Where on its support an object stands, learned the same way (:func:`learn_centring`): per (support category, object
category), the share of the training pairs whose object stands near the support's centre line across it (local x)
and along it (local y), and their offsets from it; the search's proposers draw a place at the resolution of their
grid or network (PlanIT's location network: 0.15 m per pixel at the default preset), coarser than the centimetres by
which a television stands off its stand's middle or an office chair off its desk's."""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple, cast

import numpy as np

from ..geometry.boxes import on_floor
from ..geometry.frames import to_local
from ..geometry.function import REGIONS, facing_each_other, offsets, regions
from ..room import RoomInput
from .checks import support_share
from .layout import box_frame

FRONT, BACK, SIDE_FRONT, SIDE_BACK = (REGIONS.index(r) for r in ("front", "back", "side_front", "side_back"))


class CentreLine(NamedTuple):
    """Where the training pairs of one (anchor category, object category, kind) stand about the anchor's centre
    lines: the shares ``across`` and ``along`` of the pairs whose object's centre lies in the :class:`Window` about the
    line (local x = 0, local y = 0), and those pairs' signed offsets (m), which the search draws from (0: on the
    line)."""

    across: float
    along: float
    across_offsets: tuple[float, ...] = (0.0,)
    along_offsets: tuple[float, ...] = (0.0,)


def support_pairs(room: RoomInput, tolerance: float, floor_contact: float) -> list[tuple[int, int, float]]:
    """(object, its support, share of its footprint over it) for every object of the room standing on another
    (indices into the room's objects)."""
    b = room.boxes.reshape(-1, 7)
    bottom, top = b[:, 2] - b[:, 5], b[:, 2] + b[:, 5]
    out = []
    for k in np.flatnonzero(bottom > floor_contact):
        below = np.flatnonzero((np.abs(top - bottom[k]) <= tolerance) & (np.arange(len(b)) != k))
        shares = [support_share(b[k], b[j]) for j in below]
        if shares and max(shares) > 0:
            out.append((int(k), int(below[int(np.argmax(shares))]), max(shares)))
    return out


def supported_shares(room: RoomInput, tolerance: float, floor_contact: float) -> list[tuple[str, float]]:
    """(category, share of its footprint over its support) for every object of the room standing on another."""
    return [(room.categories[k], share) for k, _, share in support_pairs(room, tolerance, floor_contact)]


def learn_support_floor(rooms: list[RoomInput], cfg: dict, floor_contact: float) -> dict[str, float]:
    """Category -> the lowest support share the check accepts for it, where the training rooms show one below
    ``min_support`` (``cfg``: the ``instantiate.checks`` section; its ``learned_support`` settings)."""
    learned = cfg["learned_support"]
    if not learned["enabled"]:
        return {}
    seen: dict[str, list[float]] = {}
    for room in rooms:
        for category, share in supported_shares(room, learned["tolerance"], floor_contact):
            seen.setdefault(category, []).append(share)
    floor = {c: max(float(np.quantile(s, learned["quantile"])), learned["least"])
             for c, s in seen.items() if len(s) >= learned["min_pairs"]}
    return {c: round(f, 3) for c, f in sorted(floor.items()) if f < cfg["min_support"]}


def half_depth_on(support: np.ndarray, half, yaw: float) -> float:
    """m: half the extent along ``support (7,)``'s depth (its local y) of a footprint of half extents ``half (2,)``
    turned ``yaw``."""
    turn = yaw - support[6]
    return float(abs(np.sin(turn)) * half[0] + abs(np.cos(turn)) * half[1])


EDGES = {"back": -1.0, "front": 1.0}  # an edge of a support's top: the sign of its side on the support's local y
OFF_EDGE = "off_edge"  # kind of the centre lines of the pairs of a (support, object) edge rule that stand off its edge


def edge_gap(support: np.ndarray, obj: np.ndarray, edge: str = "back") -> float:
    """m between the ``edge`` of ``support (7,)``'s top (:data:`EDGES`: ``back`` its local -y side, ``front`` +y) and
    the nearest point of ``obj (7,)``'s footprint, measured along the support (negative: the object overhangs it)."""
    local_y = to_local(box_frame(support), obj[:2])[1]
    return float(support[4] - half_depth_on(support, obj[3:5], obj[6]) - EDGES[edge] * local_y)


class EdgeRule(NamedTuple):
    """Where the training pairs of one (support category, object category) stand at an edge of the support
    (:func:`_edge_rule`): the ``share`` of pairs at the edge, their median ``gap`` to it (m), the ``low`` and
    ``high`` signed offset of any pair's centre from the support's centre line along its depth (m), and the same
    across its width (``across_low``, ``across_high``; a monitor never farther off its desk's middle than any training
    monitor stood)."""

    share: float
    gap: float
    low: float
    high: float
    across_low: float = -np.inf
    across_high: float = np.inf


Key = tuple[str, str, str]


@dataclass(frozen=True)
class Window:
    """What counts as near an anchor's centre line: within ``within`` m of it and within ``fraction`` of the anchor's
    half extent on that axis; a share of pairs near it needs ``min_pairs`` pairs and ``concentration`` times the share
    an even spread over the anchor gives (``instantiate.snap``'s ``centre_*`` settings)."""
    within: float
    min_pairs: int = 10
    concentration: float = 0.0
    fraction: float = 1.0


def centre_offsets(rooms: list[RoomInput], tolerance: float, floor_contact: float,
                   facing: float) -> tuple[dict[Key, tuple[np.ndarray, np.ndarray]], dict[Key, list[tuple[float, float]]]]:
    """The pairs :func:`learn_centring` reads: (anchor category, object category, kind) -> ``(across (n, 2), along
    (m, 2))``, each row an object's signed offset from the anchor's centre line and the anchor's half extent on that
    axis (m); and (support category, object category, ``edge``) -> the pairs' :func:`edge_gap` to the back and the front
    edge (m), in the order of the support rows."""
    seen: dict[Key, tuple[list[tuple[float, float]], list[tuple[float, float]]]] = {}
    gaps: dict[Key, list[tuple[float, float]]] = {}
    for room in rooms:
        b, cats = room.boxes.reshape(-1, 7), room.categories
        for k, j, _ in support_pairs(room, tolerance, floor_contact):
            u, v = to_local(box_frame(b[j]), b[k, :2])
            lines = seen.setdefault((cats[j], cats[k], "support"), ([], []))
            lines[0].append((float(u), float(b[j, 3])))
            lines[1].append((float(v), float(b[j, 4])))
            gaps.setdefault((cats[j], cats[k], "edge"), []).append((edge_gap(b[j], b[k]), edge_gap(b[j], b[k], "front")))
        floor = np.flatnonzero(on_floor(b, floor_contact))
        fb, fcats = b[floor], [cats[k] for k in floor]
        off, region = offsets(fb), regions(fb)  # (a, t, 2) m, (a, t) index into REGIONS
        lined = ((np.isin(region, (FRONT, BACK)), "spatial", 0), (np.isin(region, (SIDE_FRONT, SIDE_BACK)), "spatial", 1),
                 (facing_each_other(fb, facing), "facing", 0))
        for pairs, kind, axis in lined:
            for a, t in zip(*np.nonzero(pairs)):
                seen.setdefault((fcats[a], fcats[t], kind), ([], []))[axis].append((float(off[a, t, axis]),
                                                                                    float(fb[a, 3 + axis])))
    as_rows = lambda rows: np.array(rows, float).reshape(-1, 2)
    return {key: (as_rows(across), as_rows(along)) for key, (across, along) in seen.items()}, gaps


def learn_centring(rooms: list[RoomInput], window: Window, tolerance: float, floor_contact: float, facing: float,
                   flush: float = 0.0) -> dict[Key, tuple]:
    """(anchor category, object category, ``support`` | ``spatial`` | ``facing``) -> the :class:`CentreLine` of the
    training rooms' pairs: the shares whose object's centre lies in the ``window`` about the anchor's centre line
    across it (local x = 0) and along it (local y = 0) (a lamp on a nightstand: 10 cm is nearly half its top, so the
    window is also a fraction of the anchor), with those pairs' offsets. ``support``: an object and the support it
    stands on (both lines); ``spatial``: two floor objects, across over the pairs whose object stands in the anchor's
    front or back region, along over those in its side regions; ``facing``: two floor objects facing each other within
    ``facing`` rad (:func:`~pipeline.geometry.function.facing_each_other`: a sofa and the television stand across the
    room), across. ``back`` | ``front`` (:func:`_edge_rule`): an :class:`EdgeRule`, the share of an object's pairs
    with its support whose footprint stands within ``flush`` m of the commonest gap to that edge of the support
    (:func:`edge_gap`: a monitor at the back of its desk, a keyboard 5 cm from its front), their median gap (m) and the
    lowest and highest offset of any pair's centre from the support's centre line along its depth (m, signed: a thin
    television at the back of a deep stand stands farther behind it than any training television did, one in front
    of it where none did). A share
    needs the window's pairs and concentration (:class:`Window`), else it is 0: plants stand within 10 cm of a
    narrow anchor's centre line by chance; rules whose shares are both 0 are left out."""
    seen, gaps = centre_offsets(rooms, tolerance, floor_contact, facing)
    rules: dict[Key, tuple] = {}
    for key, axes in sorted(seen.items()):
        found = [_near_line(pairs, window) for pairs in axes]
        if any(share for share, _ in found):
            rules[key] = CentreLine(found[0][0], found[1][0], found[0][1], found[1][1])
    for key, pair_gaps in sorted(gaps.items()):
        rules.update(_edge_rule(key[:2], np.asarray(pair_gaps), seen[(*key[:2], "support")], rules, window, flush))
    return rules


def _edge_rule(pair: tuple[str, str], gaps: np.ndarray, lines: tuple[np.ndarray, np.ndarray], rules: dict[Key, tuple],
               window: Window, flush: float) -> dict[Key, tuple]:
    """The edge rule of one (support, object) ``pair`` from its pairs' ``gaps (n, 2)`` to the back and front edge (m)
    and their ``lines`` (:func:`centre_offsets`'s across and along rows, in the same order): at the edge whose gaps
    gather most within ``flush`` of one gap (:func:`_densest`; ties: the nearer edge), if more than the pair's share on
    the support's middle gather there (a vase centred on a table stands as far from either edge); with the
    :class:`CentreLine` of the pairs off that edge (:data:`OFF_EDGE`) where those pass the window on their own: the
    11% of the procedural offices' monitors not at the back of their desk stand on its centre, both ways, which the
    lines over all pairs do not say. Empty without such an edge."""
    line = CentreLine(*rules.get((*pair, "support"), (0.0, 0.0)))
    near = np.stack([_densest(gaps[:, 0], flush), _densest(gaps[:, 1], flush)], axis=1)  # (n, 2)
    gap = [float(np.median(gaps[near[:, k], k])) for k in range(2)]
    side = min(range(2), key=lambda k: (-near[:, k].mean(), abs(gap[k])))  # ties: the nearer edge
    flat = near[:, side]
    if len(gaps) < window.min_pairs or flat.mean() <= line.along:
        return {}
    span = lambda v: (float(np.floor(v.min() * 1000) / 1000), float(np.ceil(v.max() * 1000) / 1000))
    out: dict[Key, tuple] = {(*pair, list(EDGES)[side]): EdgeRule(round(float(flat.mean()), 3), round(gap[side], 3),
                                                                  *span(lines[1][:, 0]), *span(lines[0][:, 0]))}
    rest = [_near_line(axis[~flat], window) for axis in lines]
    if any(share for share, _ in rest):
        out[(*pair, OFF_EDGE)] = CentreLine(rest[0][0], rest[1][0], rest[0][1], rest[1][1])
    return out


def _densest(gaps: np.ndarray, flush: float) -> np.ndarray:
    """``(n,)`` bool: the ``gaps (n,)`` within ``flush`` of the gap that has the most others within ``flush`` of it
    (the first such: a mode, where a median falls between the two kinds of a bimodal set)."""
    close = np.abs(gaps[:, None] - gaps[None, :]) <= flush
    return cast(np.ndarray, close[int(np.argmax(close.sum(axis=1)))])


def _near_line(pairs: np.ndarray, window: Window) -> tuple[float, tuple[float, ...]]:
    """The share of ``pairs (n, 2)`` (offset from the anchor's centre line, the anchor's half extent on that axis; m)
    in the ``window`` and their offsets (rounded to mm); ``(0, (0,))`` with fewer than its ``min_pairs`` pairs or a
    share under its ``concentration`` times the share an even spread over the anchor gives."""
    half = np.maximum(pairs[:, 1], 1e-9)
    reach = np.minimum(window.within, window.fraction * half)
    near = np.abs(pairs[:, 0]) <= reach
    if len(pairs) < window.min_pairs or not near.any():
        return 0.0, (0.0,)
    chance = float(np.mean(np.minimum(1.0, reach / half)))
    share = float(near.mean())
    if share < window.concentration * chance:
        return 0.0, (0.0,)
    return round(share, 3), tuple(float(o) for o in np.round(pairs[near, 0], 3))
