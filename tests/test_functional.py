"""Functional checks learned from hand-built training rooms and scored on hand-built test rooms with known answers
(a nightstand at the foot of the bed fails, one at its head passes; a chair facing away from its desk fails); the
known-bad perturbations of the classifier's power check; bootstrap intervals that see a real difference and no
false one."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import shapely

from pipeline.evaluation import functional, intervals, perturb, power
from pipeline.geometry.boxes import footprint_corners
from pipeline.geometry.function import REGIONS, back_to_wall, faces_wall, facing_angles, footprint_gaps, in_front, plan_gaps, regions

from conftest import Room, default_config

SQUARE = [(0, 0), (4, 0), (4, 4), (0, 4)]


def bedroom(dx=0.0, nightstand_y=3.8, chair_yaw=180.0, beds=1, nightstands=2, room_id="r0"):
    """A bed with its head against the top wall between two nightstands, a desk against the bottom wall with its
    chair facing it; ``dx`` shifts everything along the walls."""
    room = Room(SQUARE, room_id=room_id)
    for k in range(beds):
        room.add(f"bed{k}", "bed", (1.6, 2.0, 0.5), (2.0 + dx - 1.7 * k, 3.0), 180)
    for k, x in enumerate((0.975, 3.025)[:nightstands]):
        room.add(f"ns{k}", "nightstand", (0.45, 0.4, 0.55), (x + dx, nightstand_y), 180)
    room.add("desk", "desk", (1.2, 0.6, 0.75), (2.0 + dx, 0.3), 0)
    room.add("chair", "chair", (0.5, 0.5, 0.9), (2.0 + dx, 0.85), chair_yaw)
    return room.room_input()


@pytest.fixture(scope="module")
def learned():
    cfg = {**default_config()["evaluate"]["functional"], "min_share": 0.85}  # 25 rooms: Wilson bound 0.87 at best
    train = [bedroom(dx, room_id=f"t{k}") for k, dx in enumerate(np.linspace(-0.6, 0.6, 25))]
    return functional.learn_checks(train, cfg), cfg


def test_footprint_gaps_match_shapely_distances():
    """The NumPy footprint gaps are shapely's polygon distances (0 where footprints overlap or touch)."""
    rng = np.random.default_rng(3)
    n = 12
    b = np.c_[rng.uniform(-3, 3, (n, 2)), rng.uniform(0, 1, n), rng.uniform(0.1, 1, (n, 3)),
              rng.choice([0.0, np.pi / 2, 0.3, -2.0], n)]
    b[1] = [b[0, 0] + b[0, 3] + 0.4, b[0, 1], 0.5, 0.4, b[0, 4], 0.5, 0.0]  # flush against box 0's right side
    b[0, 6] = 0.0
    polys = shapely.polygons(footprint_corners(b[:, 0], b[:, 1], b[:, 3], b[:, 4], b[:, 6]))
    want = shapely.distance(polys[:, None], polys[None, :])
    assert footprint_gaps(b[:4], b) == pytest.approx(want[:4], abs=1e-12)
    assert plan_gaps(b) == pytest.approx(want, abs=1e-12)
    assert footprint_gaps(b[0], b[1])[0, 0] == pytest.approx(0.0, abs=1e-12)


def test_a_pose_faces_a_wall_only_squarely_and_within_the_walls_extent():
    """A wall (0, 0)-(4, 0) facing +y: faced from above it squarely or turned 30 degrees (also from just beyond its
    end, the ray still meeting it); not turned along it, not from beyond its end facing straight down (the sofa of an
    L-shaped living room beyond the inner corner's short wall), not from behind it."""
    a, b, normal, limit = np.array([0.0, 0.0]), np.array([4.0, 0.0]), np.array([0.0, 1.0]), np.pi / 4
    xy = np.array([[2.0, 2.0], [2.0, 2.0], [2.0, 2.0], [6.0, 2.0], [2.0, -1.0], [4.5, 2.0]])
    yaw = np.radians([180.0, 150.0, 90.0, 180.0, 180.0, 150.0])  # front -y, or turned 30 degrees toward -x; 90: -x
    assert faces_wall(xy, yaw, a, b, normal, limit).tolist() == [True, True, False, False, False, True]
    assert not faces_wall(xy[:1], np.radians(120.0), a, b, normal, limit)[0]  # 60 degrees off square


def test_in_front_is_facing_each_others_view_test_for_a_whole_grid():
    # a stand at the origin facing +y (yaw 0): a point is in its view when the stand's front lies within 45 degrees of
    # the direction to it (43.5 and 46.4 degrees at x = 1.9 and 2.1); a second stand at (5, 0) facing -x sees more;
    # the answer is facing_each_other's second test, a zero-extent box standing at the point
    stands = np.array([[0.0, 0.0, 0.3, 0.6, 0.2, 0.3, 0.0], [5.0, 0.0, 0.3, 0.6, 0.2, 0.3, np.pi / 2]])
    points = np.array([[0.0, 2.0], [1.9, 2.0], [2.1, 2.0], [0.0, -1.0], [3.0, 0.5], [3.0, 2.5], [5.0, 3.0]])
    limit = np.radians(45)
    assert in_front(stands[:1], points, limit).tolist() == [True, True, False, False, False, False, False]
    assert in_front(stands, points, limit).tolist() == [True, True, True, True, True, False, False]
    for k, p in enumerate(points):
        centres = np.vstack([stands, [p[0], p[1], 0.0, 0.0, 0.0, 0.0, 0.0]])
        centres[:, 3:6] = 0.0
        seen = facing_angles(centres).T[:2, 2] <= limit  # stand i's front within the limit of the point's direction
        assert bool(seen.any()) == in_front(stands, p[None], limit)[0], k


def test_the_predicates_place_a_nightstand_at_the_head_and_a_chair_facing_its_desk():
    room = bedroom()
    cats = room.categories
    bed, ns, desk, chair = (cats.index(c) for c in ("bed", "nightstand", "desk", "chair"))
    assert REGIONS[regions(room.boxes)[bed, ns]] == "side_back"
    assert REGIONS[regions(bedroom(nightstand_y=2.2).boxes)[bed, ns]] == "side_front"  # at the foot
    assert plan_gaps(room.boxes)[bed, ns] == pytest.approx(0.0, abs=1e-9)  # flush
    assert plan_gaps(room.boxes)[desk, chair] == pytest.approx(0.0, abs=1e-9)  # tucked in: touching
    assert np.degrees(facing_angles(room.boxes)[desk, chair]) == pytest.approx(0.0, abs=1e-6)
    assert np.degrees(facing_angles(bedroom(chair_yaw=0.0).boxes)[desk, chair]) == pytest.approx(180.0, abs=1e-6)
    walls = back_to_wall(room.boxes, room.outline, 0.1, np.radians(15))
    assert walls[[bed, ns, desk]].all() and not walls[chair]


def test_checks_are_learned_from_the_training_rooms(learned):
    checks, _ = learned
    pairs = {(c["anchor"], c["target"]): c for c in checks["checks"] if c["kind"] == "pair"}
    assert pairs[("bed", "nightstand")]["region"] == "side_back" and pairs[("bed", "nightstand")]["gap"] == 0.15
    assert pairs[("desk", "chair")]["facing"] == "faces"
    assert {"bed", "desk", "nightstand"} <= {c["target"] for c in checks["checks"] if c["kind"] == "wall"}
    assert checks["contents"]["max_count"]["bed"] == 1 and "nightstand" in checks["contents"]["required"]


def test_a_nightstand_at_the_foot_and_a_chair_facing_away_fail_their_checks(learned):
    checks, cfg = learned
    good = functional.score_room(bedroom(0.1), checks, cfg)
    assert good["fn:nightstand@bed"] == 1.0 and good["fn:chair@desk"] == 1.0 and good["functional_all"] == 1.0
    foot = functional.score_room(bedroom(0.1, nightstand_y=2.2), checks, cfg)
    assert foot["fn:nightstand@bed"] == 0.0 and foot["functional_all"] == 0.0
    away = functional.score_room(bedroom(0.1, chair_yaw=0.0), checks, cfg)
    assert away["fn:chair@desk"] == 0.0 and away["fn:nightstand@bed"] == 1.0
    # the scenes table names them: none for the good room, the chair's for the turned one, flags for odd contents
    from pipeline.evaluation.evaluate import failed_checks

    assert failed_checks(good) == [] and "nightstand@bed" in failed_checks(foot)
    assert "chair@desk" in failed_checks(away) and "nightstand@bed" not in failed_checks(away)
    assert failed_checks(functional.score_room(bedroom(0.1, beds=2), checks, cfg))[-1] == "contents_excess"


def test_implausible_contents_are_flagged(learned):
    checks, cfg = learned
    two_beds = functional.score_room(bedroom(0.3, beds=2, nightstands=1), checks, cfg)
    assert two_beds["contents_excess"] == 1.0 and two_beds["contents_missing"] == 0.0
    none = functional.score_room(bedroom(0.0, nightstands=0), checks, cfg)
    assert none["contents_missing"] == 1.0 and np.isnan(none["fn:nightstand@bed"]) and none["functional_all"] == 0.0


def test_the_perturbations_do_what_they_say():
    room = bedroom()
    rng = np.random.default_rng(0)
    moved = perturb.jitter(room, 0.3, rng)
    assert np.allclose(np.linalg.norm(moved.boxes[:, :2] - room.boxes[:, :2], axis=1), 0.3)
    assert np.allclose(moved.poses[:, :2] - room.poses[:, :2], moved.boxes[:, :2] - room.boxes[:, :2])
    turned = perturb.turns(room, rng)
    assert np.allclose(turned.boxes[:, :2], room.boxes[:, :2]) and not np.allclose(turned.boxes[:, 6], room.boxes[:, 6])
    shuffled = perturb.shuffle(room, np.random.default_rng(3))
    assert sorted(shuffled.categories) == sorted(room.categories) and shuffled.categories != room.categories
    placed = perturb.placement(room, rng)
    assert np.all((placed.boxes[:, :2] > 0) & (placed.boxes[:, :2] < 4))
    assert np.allclose(np.mod(placed.boxes[:, 6], np.pi / 2), 0) or np.allclose(np.mod(placed.boxes[:, 6], np.pi / 2), np.pi / 2)
    copies = perturb.perturbed([room, bedroom(room_id="r1")], "turns", 0.0, 3, seed=0)
    assert [r.room_id for r in copies] == [f"r{k}~turns{c}" for k in range(2) for c in range(3)]
    assert room.boxes[0, 6] == bedroom().boxes[0, 6]  # the originals are untouched


def test_the_power_check_fails_on_a_missed_perturbation_or_a_biased_control():
    cfg = default_config()["evaluate"]["power"]
    score = lambda a: {"accuracy": a}
    good = {"jitter_0.1": score(55), "jitter_0.3": score(70), "shuffle": score(80), "turns": score(95),
            "placement": score(92), power.CONTROL: score(52)}
    assert power.verdict(good, cfg)["passed"]
    assert power.verdict({**good, "placement": score(85)}, cfg)["missed"] == ["placement"]
    assert not power.verdict({**good, power.CONTROL: score(58)}, cfg)["passed"]


def _rows(n, colliding, rng):
    """Per-room rows: ``colliding`` is each room's chance of one colliding object (of 5)."""
    return pd.DataFrame({"objects": 5, "colliding_objects": (rng.random(n) < colliding).astype(int),
                         "out_of_bounds": 0, "walkable_share": rng.uniform(0.8, 1.0, n), "reachable": 1.0,
                         f"{intervals.CATEGORY}bed": 1, f"{intervals.CATEGORY}nightstand": rng.integers(1, 3, n)})


def test_bootstrap_differences_see_a_real_difference_and_no_false_one():
    rng = np.random.default_rng(1)
    sets = {"a": _rows(150, 0.1, rng), "same": _rows(150, 0.1, rng), "worse": _rows(150, 0.6, rng),
            "real": _rows(80, 0.1, rng)}
    reps = intervals.bootstrap(sets, "real", lambda f, r: intervals.figures(f, r, 1e-6, []), 200, seed=0)
    sizes = {k: len(v) for k, v in sets.items()}
    diff = intervals.differences(reps, "a", sizes, 10, "real")
    assert not intervals.differences(reps, "a", sizes, 200, "real")["worse"]["object_collision_rate"]["excludes_zero"]
    to_real = intervals.differences(reps, "real", sizes, 10, "real")
    assert "category_kl" not in to_real["a"] and "object_collision_rate" in to_real["a"]  # a distance to itself is 0
    assert "category_kl" in diff["worse"] and "category_kl" not in diff["real"]
    assert diff["worse"]["object_collision_rate"]["excludes_zero"]
    assert diff["worse"]["object_collision_rate"]["low"] > 0
    assert not diff["same"]["object_collision_rate"]["excludes_zero"]
    low, high = intervals.intervals(reps)["worse"]["object_collision_rate"]
    assert low < intervals.figures(sets["worse"], sets["real"], 1e-6, [])["object_collision_rate"] < high


def test_a_set_with_no_rooms_scores_to_empty_rows_and_undefined_figures(learned):
    """Every scene of a method failed: its rows are empty (with every column), its figures NaN, nothing crashes."""
    from pipeline import tables
    from pipeline.evaluation.evaluate import EXTRA, room_rows
    from pipeline.evaluation.sets import RoomSet

    checks, cfg = learned
    config = default_config()
    config["evaluate"]["functional"] = cfg
    index = {c: k for k, c in enumerate(["bed", "chair", "desk", "nightstand"])}
    empty = room_rows(RoomSet("none", [], []), checks, index, ({}, set(), {}), np.zeros((0, 64, 64), np.int16), [], config)
    real = room_rows(RoomSet("real", [bedroom()], [[None] * 5]), checks, index, ({}, set(), {}),
                     np.zeros((0, 64, 64), np.int16), [], config)
    assert len(empty) == 0 and set(tables.SCHEMAS["eval_scenes"].names) <= set(empty.columns)
    names = [functional.check_name(c) for c in checks["checks"]]
    figures = intervals.figures(empty, real, 1e-6, EXTRA + names)
    assert np.isnan(figures["walkable_share"]) and np.isnan(figures["fn:nightstand@bed"])
    assert intervals.figures(real, real, 1e-6, EXTRA + names)["fn:nightstand@bed"] == 1.0
