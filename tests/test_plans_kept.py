"""Issue 28's pieces on hand-built cases: plausible contents learned from training rooms, pose rules learned from
training rooms and applied to a candidate's orientation, the planned edges a placed room lost classified by cause,
and failed scenes kept out of the canonical tables."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd

from pipeline.geometry.boxes import SIDES
from pipeline.geometry.frames import turn_error
from pipeline.geometry.function import facing_angles, facing_turn, sides
from pipeline.methods.interface import Scene
from pipeline.methods.scenes import Rows, drops, plan_loss
from pipeline.placement import scene_metrics
from pipeline.placement.plan import PlanEdge
from pipeline.room.contents import implausible, learn_contents

from conftest import default_config
from test_functional import bedroom


def test_contents_learned_from_training_rooms_flag_excess_and_missing_categories():
    rooms = [["bed", "nightstand", "nightstand"]] * 30 + [["bed", "desk"]] * 2
    learned = learn_contents(rooms, 0.75)  # 30 of 32 rooms: Wilson lower bound 0.80
    assert learned["max_count"] == {"bed": 1, "desk": 1, "nightstand": 2} and learned["required"] == ["bed", "nightstand"]
    assert implausible(["bed", "bed", "nightstand"], learned) == (["bed"], [])
    assert implausible(["sofa", "nightstand"], learned) == (["sofa"], ["bed"])


def test_sides_of_a_tucked_chair_a_flanking_nightstand_and_a_corner():
    room = bedroom()
    cats = room.categories
    bed, ns, desk, chair = (cats.index(c) for c in ("bed", "nightstand", "desk", "chair"))
    s = sides(room.boxes)
    assert SIDES[s[desk, chair]] == "front"  # tucked in: over the desk's footprint, nearest its front
    assert {SIDES[s[bed, ns]], SIDES[s[bed, ns + 1]]} == {"left", "right"}
    corner = np.array([room.boxes[desk], [3.0, 1.0, 0.0, 0.1, 0.1, 0.1, 0.0]])  # beyond the desk's right-front corner
    assert s[bed, bed] == -1 and sides(corner)[0, 1] == -1


def test_an_object_drawn_off_an_anchors_corner_faces_the_side_it_lies_farthest_beyond():
    # a sofa 2 m x 0.9 m facing +x (yaw 270 degrees); a coffee table drawn 1.0 m before it and 1.04 m off its centre
    # line lies beyond its front (2.2 half depths) more than beyond its side (1.04 half widths): it faces the sofa's
    # front (yaw 90), where the direction to the sofa's centre (44 degrees) is as near the side's turn as the front's
    sofa = np.array([0.55, 3.71, 0.4, 1.0, 0.45, 0.4, 1.5 * np.pi])
    corner = np.vstack([sofa, [1.55, 2.67, 0.2, 0.5, 0.3, 0.2, 0.0]])
    assert sides(corner)[0, 1] == -1 and SIDES[sides(corner, corners=False)[0, 1]] == "front"
    assert abs(turn_error(facing_turn(sofa, np.array([1.55, 2.67])) - np.pi / 2)) < 1e-9
    for side, xy, yaw in (("back", (-0.5, 3.7), 1.5 * np.pi), ("left", (0.5, 5.0), np.pi), ("right", (0.6, 2.0), 0.0)):
        turned = np.vstack([sofa, [*xy, 0.2, 0.5, 0.3, 0.2, facing_turn(sofa, np.array(xy))]])
        assert SIDES[sides(turned)[0, 1]] == side and abs(turn_error(turned[1, 6] - yaw)) < 1e-9
        assert facing_angles(turned)[0, 1] < 1e-6  # squarely at the sofa's footprint


def test_real_3d_front_objects_facing_a_near_anchor_mostly_take_the_turn_facing_its_side(tmp_path):
    # on the 3D-FRONT sample's rooms, of the floor objects within 0.5 m of a floor anchor and facing it (within 45
    # degrees), 89 of 114 stand within 15 degrees of facing_turn (the rest stand turned off their anchor's axes, which
    # no square turn gives); the anchor's axis turn nearest the direction to its centre, the rule it replaced, gives 89
    # too; a quarter turn from facing_turn matches 2 of them
    from pipeline.geometry.boxes import on_floor
    from pipeline.geometry.function import plan_gaps
    from pipeline.room import room_inputs

    from conftest import shared_data
    from test_sources import run_ingest

    sample = shared_data("3d-front-sample")
    t = run_ingest("front3d", {"houses": str(sample / "houses"), "future": str(sample / "3d-future"),
                               "cache_dir": str(tmp_path / "cache")}, tmp_path)
    errors, quarter = [], []
    for room in room_inputs(t["rooms"], t["architecture"], t["objects"]):
        b = room.boxes.reshape(-1, 7)
        b = b[on_floor(b, default_config()["floor_contact"])]
        near = (plan_gaps(b) <= 0.5) & (facing_angles(b) <= np.pi / 4)
        np.fill_diagonal(near, False)
        for a, o in zip(*np.nonzero(near)):
            errors.append(turn_error(b[o, 6] - facing_turn(b[a], b[o, :2])))
            quarter.append(turn_error(b[o, 6] - facing_turn(b[a], b[o, :2]) - np.pi / 2))
    assert len(errors) >= 100
    assert np.mean(np.array(errors) <= np.radians(15)) >= 0.75
    assert np.mean(np.array(quarter) <= np.radians(15)) <= 0.05


def test_lost_plan_edges_are_classified_by_when_and_what_extraction_found():
    e = lambda s, t, d, x: PlanEdge(s, t, "spatial", d, x)  # noqa: E731
    kept, relaxed, later, gone = e("a", "b", "front", "adjacent"), e("a", "c", "left", "adjacent"), \
        e("b", "c", "front", "proximal"), e("a", "d", "back", "distant")
    support = PlanEdge("a", "b", "support", None, None)
    found = {("a", "b"): [("spatial", "front", "adjacent")], ("a", "c"): [("spatial", "left", "proximal")],
             ("b", "c"): [("spatial", "back", "proximal")]}
    accepted = {kept: 0.0, relaxed: 0.5, later: 0.0, support: 0.0}
    planned = [kept, relaxed, later, gone, support]
    costs = np.array([1.0 if p is support else 0.0 if p is kept else 0.5 if p is relaxed else 1.0 for p in planned])
    loss = scene_metrics.plan_loss(planned, costs, found, {"d"}, accepted)
    assert loss["adjacent"] == {"planned": 2, "relaxed": 1, "distance": 1}
    assert loss["proximal"] == {"planned": 1, "lost_later": 1, "direction": 1}
    assert loss["distant"] == {"planned": 1, "unplaced": 1, "absent": 1}
    assert loss["support"] == {"planned": 1, "lost_later": 1, "absent": 1}
    shares = plan_loss(__import__("pandas").Series([json.dumps(loss), json.dumps(loss), None]))
    assert shares["adjacent"] == {"planned": 4, "relaxed": 0.5, "distance": 0.5}


def test_a_failed_scene_is_recorded_but_its_unfinished_room_stays_out_of_the_canonical_tables():
    room = bedroom()

    class Corpus:
        room_type = "bedroom"

    rows = Rows()
    record = rows.add(Scene("s0", "r0", room, None, "failed", "backtrack budget spent"), Corpus(), "planit")
    assert record["status"] == "failed" and record["placed_objects"] == len(room.object_ids)
    assert rows.records == [record] and rows.objects == [] and rows.rooms == [] and rows.architecture == []


def test_an_object_near_two_opposite_walls_is_an_invalid_plan_unless_training_graphs_show_it():
    from pipeline.graphs import checks
    from pipeline.graphs.data import EDGE_CLASSES, OBJECT_EDGES
    opp, near, far = EDGE_CLASSES.index("wall_opposite"), OBJECT_EDGES.index("front/proximal"), OBJECT_EDGES.index("front/distant")
    classes, role = [0, 0, 0, 0, 7], [0] * 5  # four walls (0 and 2 opposite, 1 and 3 opposite), one object
    arch = [(0, 2, opp), (1, 3, opp)]
    problems = lambda e, ok=frozenset(): checks.problems(classes, role, arch + e, 4, checks.GraphRules(
        frozenset({(0, 7, near), (0, 7, far)}), frozenset(), frozenset(ok)))  # noqa: E731
    assert "near_opposite_walls" in problems([(0, 4, near), (2, 4, near)])
    assert "near_opposite_walls" not in problems([(0, 4, near), (1, 4, near)])  # a corner
    assert "near_opposite_walls" not in problems([(0, 4, near), (2, 4, far)])  # across the room: far from one
    assert "near_opposite_walls" not in problems([(0, 4, near), (2, 4, near)], {7})  # the training rooms do it


def test_a_floor_node_with_planned_spatial_edges_takes_an_instance_that_stood_on_the_floor():
    import pandas as pd

    from pipeline.placement.retrieval import ModelPool
    row = lambda model, z, hz: {"category": "counter_top", "model_id": model, "cx": 0.0, "cy": 0.0, "cz": z, "hx": 0.5,  # noqa: E731
                                "hy": 0.3, "hz": hz, "yaw": 0.0, "px": 0.0, "py": 0.0, "pz": z - hz, "sx": 1.0,
                                "sy": 1.0, "sz": 1.0}
    pool = ModelPool(pd.DataFrame([row("slab", 0.93, 0.01), row("cabinet", 0.45, 0.45)] * 3), {}, 0.04)
    rng = np.random.default_rng(0)
    assert {pool.pick("counter_top", "none", rng, grounded=True).model_id for _ in range(20)} == {"cabinet"}
    assert {pool.pick("counter_top", "none", rng).model_id for _ in range(40)} == {"slab", "cabinet"}


def test_objects_left_out_are_summed_by_category_and_cause():
    rows = pd.Series([json.dumps([{"id": "a", "category": "counter", "cause": "no_place", "check": "violates"},
                                  {"id": "b", "category": "toaster", "cause": "support_dropped", "check": None}]),
                      json.dumps([{"id": "c", "category": "counter", "cause": "no_place", "check": "violates"},
                                  {"id": "d", "category": "counter", "cause": "no_place", "check": "collides"}]),
                      "[]", None])
    assert drops(rows) == {"counter": {"no_place:collides": 1, "no_place:violates": 2}, "toaster": {"support_dropped": 1}}


def _tv_room(k: int, tv_width: float):
    """A TV stand 0.9 m wide with a TV of ``tv_width`` on it; a nightstand with a lamp wholly on it."""
    from conftest import Room

    r = Room([(0, 0), (4, 0), (4, 3), (0, 3)], room_id=f"t{k}", room_type="living")
    r.add("stand", "tv_stand", (0.9, 0.4, 0.5), (2.0, 0.3)).add("tv", "tv", (tv_width, 0.1, 0.6), (2.0, 0.3), z=0.5)
    r.add("ns", "nightstand", (0.5, 0.4, 0.55), (0.5, 2.5)).add("lamp", "table_lamp", (0.2, 0.2, 0.4), (0.5, 2.5), z=0.55)
    return r.room_input()


def test_a_tv_wider_than_its_stand_in_every_training_room_may_overhang_it_and_nothing_else_may():
    from pipeline.placement.checks import Checker, support_share
    from pipeline.placement.support import learn_support_floor, supported_shares

    checks = {**default_config()["instantiate"]["checks"], "min_support": 0.9}
    rooms = [_tv_room(k, w) for k, w in enumerate(np.linspace(1.0, 1.2, 12))]  # shares 0.90 .. 0.75
    assert sorted(c for c, _ in supported_shares(rooms[0], 0.02, 0.04)) == ["table_lamp", "tv"]
    floor = learn_support_floor(rooms, checks, 0.04)
    assert list(floor) == ["tv"] and 0.75 <= floor["tv"] <= 0.77  # the low end of 0.75 .. 0.90; lamps stay at 0.9
    assert learn_support_floor(rooms[:9], checks, 0.04) == {}  # fewer than min_pairs (10) TVs: nothing learned
    checker = Checker({}, set(), {}, {}, object, checks, floor)
    wide = _tv_room(99, 1.18)
    share = support_share(wide.boxes[1], wide.boxes[0])
    assert 0.76 < share < 0.77 and share >= checker.min_support("tv") and checker.min_support("table_lamp") == 0.9
    assert checker.min_support("vase") == 0.9


def test_a_learned_overhang_never_goes_below_half_the_footprint():
    from pipeline.placement.support import learn_support_floor

    checks = {**default_config()["instantiate"]["checks"], "min_support": 0.9}
    rooms = [_tv_room(k, 3.0) for k in range(12)]  # a 3 m TV on a 0.9 m stand: share 0.3
    assert learn_support_floor(rooms, checks, 0.04) == {"tv": 0.5}


def test_an_object_whose_plan_puts_a_placed_object_around_it_is_turned_so_that_it_stands_there():
    # a table turned 30 degrees at the room's middle; a chair drawn 1.2 m beyond its left side, planned with the table
    # in front of it (behind it, on its left, on its right): the turn puts the table on that side of the chair; with
    # no edge from the chair to a placed object the base orienter's turn stands (facing away from the nearest wall)
    from pipeline.placement.anchors import anchors_of
    from pipeline.placement.proposers import FaceAway, FacePlanned, Grid, Request

    from test_poses import furnished, given, plan_of, setup_room

    room, walls, pool, _, _ = setup_room(furnished(0))
    placed = given(room, pool, "desk", "table", (2.2, 2.3), 30)
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    xy = np.array([2.2, 2.3]) + np.array([[c, -s], [s, c]]) @ [-1.2, 0.1]
    for direction in SIDES:
        plan = plan_of("c", "chair", [PlanEdge("c", "table", "spatial", direction, "adjacent")])
        anchors = anchors_of("c", plan, placed, walls, {}, (0.25, 0.25))
        req = Request(placed, walls, "chair", "left-right", anchors, Grid(placed.outline, 0.1), np.ones(1, bool))
        yaw = FacePlanned(FaceAway()).orientation(req, xy, np.random.default_rng(0))
        boxes = np.vstack([[*xy, 0.45, 0.25, 0.25, 0.45, yaw], placed.boxes.reshape(-1, 7)])
        assert SIDES[sides(boxes, corners=False)[0, 1]] == direction
    alone = Request(placed, walls, "chair", "left-right", [], Grid(placed.outline, 0.1), np.ones(1, bool))
    assert FacePlanned(FaceAway()).orientation(alone, xy, None) == FaceAway().orientation(alone, xy, None)
    # planned against the bottom wall with objects to come behind it (and on its left): the side toward the wall is
    # the first the plan leaves free, back, left, right, then front
    bottom = walls.ids.index(next(w for w, (a, b) in zip(walls.ids, zip(walls.a, walls.b)) if a[1] == b[1] == 0.0))
    plan = plan_of("t", "desk", [PlanEdge(walls.ids[bottom], "t", "spatial", "front", "adjacent")])
    anchors = anchors_of("t", plan, room, walls, {}, (0.6, 0.3))
    toward = {"back": -np.pi / 2, "left": np.pi, "right": 0.0, "front": np.pi / 2}  # the side's world direction: -y
    for later, side in (((), "back"), (("back",), "left"), (("back", "left"), "right"),
                        (("back", "left", "right"), "front")):
        req = Request(room, walls, "desk", "none", anchors, Grid(room.outline, 0.1), np.ones(1, bool), (), later)
        yaw = FacePlanned(FaceAway()).orientation(req, np.array([2.0, 0.5]), None)
        assert abs(turn_error(yaw + toward[side] + np.pi / 2)) < 1e-9, (later, side, np.degrees(yaw))
