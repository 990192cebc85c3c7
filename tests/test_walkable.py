"""A floor object may not close the floor off from the door (pipeline/placement/walkable.py): hand-built rooms
with known answers, the real extraction and collision checks of PlanIT's search, and the evaluation's measure."""
from __future__ import annotations

from dataclasses import replace

import pytest

from pipeline.geometry.raycast import intersector_class
from pipeline.placement.checks import Checker, check, checks_config
from pipeline.placement.walkable import FloorKept, learn_walkable_floor
from pipeline.room.walkability import Walk, walkability, walkable_share

from conftest import Room, default_config

SOFA, ARMCHAIR = (0.9, 2.2, 0.8), (1.0, 0.8, 0.8)
WALK = Walk.of(default_config()["evaluate"]["walk"])


def pocket_room(armchair_at: tuple[float, float] | None) -> Room:
    """A 4 x 3.5 m room, its door in the left wall near the floor's corner (y 0.2-1.0), a sofa standing along x = 1.5
    from the bottom wall up to y = 2.2, and an armchair at ``armchair_at``: at (0.7, 2.65) it closes the gap between
    the sofa's end and the left wall, and the door opens onto a 1 m wide pocket."""
    r = Room([(0, 0), (4, 0), (4, 3.5), (0, 3.5)]).door("d0", (0, 0.2), (0, 1.0), "wall_3")
    r.add("sofa", "sofa", SOFA, (1.5, 1.1))
    if armchair_at is not None:
        r.add("armchair", "armchair", ARMCHAIR, armchair_at)
    return r


def checker_for(r: Room, least: float) -> Checker:
    cfg = default_config()
    ext = {"floor_contact": cfg["floor_contact"], **cfg["extract"]}
    kept = FloorKept(WALK, least, 0.01) if least > 0 else None
    return Checker(r.models, set(r.models), {}, ext, intersector_class("embree"), checks_config(cfg), floor_kept=kept)


def test_an_armchair_that_walls_the_door_into_a_pocket_is_refused_and_one_elsewhere_is_not():
    open_room = pocket_room(None).room_input()
    closed = pocket_room((0.7, 2.65))
    assert walkable_share(open_room, WALK) > 0.99
    share = walkable_share(closed.room_input(), WALK)
    assert share < 0.35  # only the pocket (about 1 x 2 m of some 12 m^2) is reached from the door
    assert share == pytest.approx(walkability(closed.room_input(), WALK)["walkable_share"])  # one measure
    verdict = check(closed.room_input(), 1, None, set(), [], 0.0, checker_for(closed, 0.8))
    assert not verdict.ok and verdict.reason.startswith("closes the floor off from the door")
    aside = pocket_room((3.3, 2.9))
    assert check(aside.room_input(), 1, None, set(), [], 0.0, checker_for(aside, 0.8)).ok
    assert check(closed.room_input(), 1, None, set(), [], 0.0, checker_for(closed, 0.0)).ok  # no floor: no check


def test_a_room_already_under_the_floor_takes_an_object_that_does_not_make_it_worse():
    closed = pocket_room((0.7, 2.65)).add("stool", "stool", (0.4, 0.4, 0.45), (3.2, 0.6))  # in the walled-off part
    room, kept = closed.room_input(), FloorKept(WALK, 0.8, 0.01)
    assert walkable_share(room, WALK) < 0.8
    assert kept.closes(room, 2) is None
    before, after = kept.closes(room, 1)  # the armchair still closes the pocket
    assert after < 0.35 < 0.99 < before


def test_the_least_share_is_the_training_rooms_quantile():
    cfg = default_config()
    walk, settings = cfg["evaluate"]["walk"], cfg["instantiate"]["checks"]["walkable"]
    rooms = [pocket_room(None).room_input(), pocket_room((0.7, 2.65)).room_input(), pocket_room((3.3, 2.9)).room_input()]
    shares = sorted(walkable_share(r, WALK) for r in rooms)
    assert learn_walkable_floor(rooms, WALK, 0.0) == pytest.approx(shares[0], abs=1e-3)
    assert learn_walkable_floor(rooms, WALK, 0.5) == pytest.approx(shares[1], abs=1e-3)
    kept = FloorKept.learn(rooms, walk, {**settings, "quantile": 0.5})
    assert kept is not None and kept.least == pytest.approx(shares[1], abs=1e-3) and kept.walk == WALK
    assert FloorKept.learn(rooms, walk, {**settings, "enabled": False}) is None
    assert FloorKept.learn([], walk, settings) is None
    no_door = replace(rooms[1], openings=[])  # no door: the largest free component stands in for the door's
    assert walkable_share(no_door, WALK) > 0.6
    # rooms without a door (AI2-THOR's) teach no least share, and a room without one is never refused
    assert FloorKept.learn([no_door, replace(rooms[0], openings=[])], walk, settings) is None
    assert FloorKept(WALK, 0.99, 0.01).closes(no_door, 1) is None and FloorKept(WALK, 0.99, 0.01).closes(rooms[1], 1)


def test_a_turned_bench_closes_the_gap_only_when_the_agent_cannot_pass_it():
    """Turned 10 degrees just beyond the sofa's end, a bench 1.0 m long spans the 1.05 m between the left wall and the
    sofa's side with under 2 cm to spare (narrower than the 0.3 m agent) and walls the door's pocket in: refused;
    0.4 m long it leaves over 0.3 m either side: kept."""
    kept = FloorKept(WALK, 0.8, 0.01)
    for length, refused in ((1.0, True), (0.4, False)):
        r = pocket_room(None).add("bench", "bench", (length, 0.3, 0.45), (0.525, 2.4), yaw_deg=10.0)
        closed = kept.closes(r.room_input(), 1)
        assert (closed is not None) == refused, (length, closed)
