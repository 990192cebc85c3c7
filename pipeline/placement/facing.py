"""Which floor objects face an object of another category, learned from the training rooms by the predicates the
search and the evaluation share (:mod:`pipeline.geometry.function`).

Anchors (:func:`learn_anchor_facing`): a plan's "in front of the desk" edge says where an office chair stands, not
which way it turns, and PlanIT's orientation network, which sees a crop and none of the planned relations, turned 6
of the 8 failing chairs of a default run's offices 90-180 degrees from their desk. Per (anchor category, object
category), the share of the training rooms' floor objects standing within a gap of a floor object of the anchor
category that face it (:func:`~pipeline.geometry.function.facing_angles`), and how far those are turned off square
to it (training chairs stand a few degrees off their desk; turned square, 0-6% of generated office chairs stood off
the walls' axes against 43% of the training ones).

Partners (:func:`learn_facing_partners`), whether or not the graph joins them: a television stand faces the sofa
across the room in every training living room, but extraction finds the sofa -> stand edge in only 76% of them (a
coffee table hides the stand from the sofa's front in the rest), so a sampled graph often plans the stand against a
wall and nothing more. Per (partner category, object category), the share of the training rooms' floor objects of
the category that face an object of the partner category (:func:`~pipeline.geometry.function.facing_each_other`,
the predicate the search's centre lines use), over the rooms that hold both on the floor."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..geometry.boxes import on_floor
from ..geometry.frames import wrap
from ..geometry.function import facing_angles, facing_each_other, facing_turn, plan_gaps
from ..room import RoomInput

Pair = tuple[str, str]  # (partner category, object category)


def facing_partner_distances(room: RoomInput, facing: float, floor_contact: float) -> dict[Pair, list[float]]:
    """(partner category, object category) -> per floor object of the category, the centre distance (m) to the
    nearest floor object of the partner category it faces within ``facing`` rad, inf where it faces none (only
    categories the room holds both of on the floor)."""
    b = room.boxes.reshape(-1, 7)
    floor = np.flatnonzero(on_floor(b, floor_contact))
    cats = np.array([room.categories[k] for k in floor], object)
    faces = facing_each_other(b[floor], facing)  # (partner, object)
    apart = np.linalg.norm(b[floor, None, :2] - b[None, floor, :2], axis=-1)
    out: dict[Pair, list[float]] = {}
    for partner in sorted(set(cats)):
        rows = np.where(faces[cats == partner], apart[cats == partner], np.inf)
        for k in range(len(floor)):
            if (cats == partner).sum() - (cats[k] == partner) > 0:
                out.setdefault((partner, cats[k]), []).append(float(rows[:, k].min()))
    return out


def learn_facing_partners(rooms: list[RoomInput], facing: float, min_pairs: int, min_share: float,
                          floor_contact: float) -> dict[Pair, float]:
    """(partner category, object category) -> the share of the training floor objects of the category that face a
    partner (:func:`facing_partner_distances`), kept where at least ``min_pairs`` objects show it and the share is at
    least ``min_share``."""
    seen: dict[Pair, list[bool]] = {}
    for room in rooms:
        for pair, apart in facing_partner_distances(room, facing, floor_contact).items():
            seen.setdefault(pair, []).extend(np.isfinite(apart).tolist())
    shares = {pair: round(float(np.mean(f)), 3) for pair, f in sorted(seen.items()) if len(f) >= min_pairs}
    return {pair: s for pair, s in shares.items() if s >= min_share}


def learn_partner_distances(rooms: list[RoomInput], facing: float, quantile: float,
                            floor_contact: float) -> dict[Pair, float]:
    """(partner category, object category) -> the ``quantile`` of the centre distances (m) between the training floor
    objects that face a partner and that partner: how close a sofa stands to the television stand it faces."""
    seen: dict[Pair, list[float]] = {}
    for room in rooms:
        for pair, apart in facing_partner_distances(room, facing, floor_contact).items():
            seen.setdefault(pair, []).extend(d for d in apart if np.isfinite(d))
    return {pair: round(float(np.quantile(d, quantile)), 3) for pair, d in sorted(seen.items()) if d}


class AnchorFacing(NamedTuple):
    """One (anchor category, object category)'s training pairs: the ``share`` whose object faces the anchor, and
    those objects' turns from squarely facing the side of the anchor they stand beyond (rad; a chair a few degrees
    off square to its desk)."""

    share: float
    residuals: tuple[float, ...] = (0.0,)


def learn_anchor_facing(rooms: list[RoomInput], gap: float, facing: float, min_pairs: int, min_share: float,
                        floor_contact: float) -> dict[Pair, AnchorFacing]:
    """(anchor category, object category) -> the :class:`AnchorFacing` of the training pairs of floor objects
    standing within ``gap`` m of each other: the share whose object faces the anchor within ``facing`` rad (literal
    fronts) and their turns from :func:`~pipeline.geometry.function.facing_turn`, where at least ``min_pairs`` pairs
    show it and the share is at least ``min_share``."""
    seen: dict[Pair, list[bool]] = {}
    off: dict[Pair, list[float]] = {}
    for room in rooms:
        b = room.boxes.reshape(-1, 7)
        floor = on_floor(b, floor_contact)
        fb, cats = b[floor], [c for c, k in zip(room.categories, floor) if k]
        near, faces = plan_gaps(fb) <= gap, facing_angles(fb) <= facing  # (anchor, object)
        np.fill_diagonal(near, False)
        for a, t in zip(*np.nonzero(near)):
            seen.setdefault((cats[a], cats[t]), []).append(bool(faces[a, t]))
            if faces[a, t]:
                off.setdefault((cats[a], cats[t]), []).append(float(wrap(fb[t, 6] - facing_turn(fb[a], fb[t, :2]))))
    shares = {pair: round(float(np.mean(f)), 3) for pair, f in sorted(seen.items()) if len(f) >= min_pairs}
    return {pair: AnchorFacing(s, tuple(np.round(off[pair], 4).tolist())) for pair, s in shares.items()
            if s >= min_share and s > 0}
