"""Whole poses (issue 40) on hand-built rooms with known answers: the pose networks at a small preset trained on
hand-built rooms, and the relative-pose prior learned from the same rooms, each place a bed with its back to the
wall it is planned against, a nightstand planned beside a bed at the bed's head, a television planned on a stand
facing the way the stand faces, and a chair planned in front of a desk facing it. Symmetric objects' equivalent turns
count as one (one function for the evaluation and the search); the relation bands are where extraction finds the
planned edge; the search's tolerance is per object and an unsatisfiable plan ends with its cause, not a relaxed
room."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from pipeline.geometry.frames import to_local, to_world, turn_error, wrap
from pipeline.geometry.function import REGIONS, back_to_wall, facing_angles, facing_each_other, regions
from pipeline.geometry.raycast import intersector_class
from pipeline.placement import order
from pipeline.placement.checks import Checker
from pipeline.placement.facing import AnchorFacing, learn_anchor_facing, learn_facing_partners, learn_partner_distances
from pipeline.placement.layout import add_object, box_frame, wall_frame, walls_of, with_objects
from pipeline.placement.plan import PlanEdge, ScenePlan
from pipeline.placement.proposers import (
    BackToWall,
    Centred,
    Combined,
    FaceAnchor,
    FaceAway,
    FacingPartner,
    RelationPrior,
    TurnedOnSupport,
    UniformLocation,
)
from pipeline.placement.retrieval import ModelPool, place
from pipeline.placement.search import Kit, instantiate
from pipeline.placement.support import EDGES, OFF_EDGE, CentreLine, EdgeRule, Window, edge_gap, learn_centring
from pipeline.placement.turns import learn_support_turns
from pipeline.placement.walls import learn_wall_backs, learn_wall_bound

from conftest import Room, default_config

SIZES = {"bed": (1.6, 2.0, 0.5), "nightstand": (0.45, 0.4, 0.55), "desk": (1.2, 0.6, 0.75), "chair": (0.5, 0.5, 0.9),
         "tv_stand": (1.2, 0.4, 0.5), "tv": (1.0, 0.1, 0.6)}
SYMMETRY = {"bed": "left-right", "nightstand": "left-right", "desk": "none", "chair": "left-right",
            "tv_stand": "left-right", "tv": "left-right"}


def _turn(xy, k, centre):
    c, s = math.cos(k * math.pi / 2), math.sin(k * math.pi / 2)
    d = np.asarray(xy, float) - centre
    return centre + np.array([c * d[0] - s * d[1], s * d[0] + c * d[1]])


def furnished(seed: int) -> Room:
    """A W x D room (turned by a random quarter turn): a bed with its head against the top wall between two flush
    nightstands, a desk against the bottom wall with its chair in front facing it, a TV stand against the left wall
    with a TV on it facing the same way."""
    rng = np.random.default_rng(seed)
    w, d = rng.uniform(3.8, 5.0), rng.uniform(4.0, 5.0)
    k = int(rng.integers(4))
    centre = np.array([w / 2, d / 2])
    corners = [_turn(p, k, centre) for p in ((0, 0), (w, 0), (w, d), (0, d))]
    room = Room([tuple(p) for p in corners], room_id=f"t{seed}")
    put = lambda oid, cat, xy, yaw, z=0.0, parent=None: room.add(oid, cat, SIZES[cat], tuple(_turn(xy, k, centre)),
                                                                 yaw + 90 * k, z=z, parent=parent)
    bx = rng.uniform(1.4, w - 1.4)
    put("bed", "bed", (bx, d - 1.0), 180)
    for side, oid in ((-1, "ns_a"), (1, "ns_b")):
        put(oid, "nightstand", (bx + side * (0.8 + 0.225 + 0.005), d - 0.2), 180)
    dx = rng.uniform(0.9, w - 0.9)
    put("desk", "desk", (dx, 0.3), 0)
    put("chair", "chair", (dx, 0.6 + rng.uniform(0.15, 0.3) + 0.25), 180)
    ty = rng.uniform(1.4, d - 1.4)
    put("stand", "tv_stand", (0.2, ty), 270)
    put("tv", "tv", (0.2, ty), 270, z=0.5, parent="stand")
    return room


def checker_of(room: Room) -> Checker:
    cfg = default_config()
    ext = {"floor_contact": cfg["floor_contact"], **cfg["extract"]}
    return Checker(room.models, set(room.models), {}, ext, intersector_class("embree"), cfg["instantiate"]["checks"])


def kept_edges(graph) -> list[tuple[str, str, str]]:
    """A raw graph's support edges and its adjacent and proximal spatial edges (walls: adjacent only), as a final
    graph keeps them (source, target, edge kind)."""
    out = []
    for e in graph.edges:
        if e["edge_type"] == "support":
            out.append((e["source"], e["target"], "support"))
        elif e["edge_type"] == "spatial" and e["distance"] in ("adjacent", "proximal"):
            if not e["source"].startswith("wall") or e["distance"] == "adjacent":
                out.append((e["source"], e["target"], f"{e['direction']}/{e['distance']}"))
    return out


def corpus(count: int = 40):
    """Hand-built training rooms with their kept edges, and one room holding every model (the model pool)."""
    from pipeline.methods.planit.nets.data import TrainingRoom

    rooms = [furnished(s) for s in range(count)]
    out = []
    for r in rooms:
        room = r.room_input()
        edges = kept_edges(r.extract(symmetry=SYMMETRY))
        parent = {t: s for s, t, k in edges if k == "support"}
        sym = {o: SYMMETRY[c] for o, c in zip(room.object_ids, room.categories)}
        out.append(TrainingRoom(room, walls_of(room), edges, parent, sym))
    return out, rooms[0]


@pytest.fixture(scope="module")
def learned(tmp_path_factory):
    """The pose networks at a small preset and the prior, both learned from the hand-built rooms."""
    import torch

    from pipeline.learning.checkpoint import Checkpoint
    from pipeline.learning.epochs import Session
    from pipeline.methods.planit.nets import train as nets_train
    from pipeline.placement.prior import learn_prior

    rooms, pool_room = corpus()
    cfg = default_config()
    preset = {**cfg["placement"]["presets"]["tiny"], "steps": 400, "batch_size": 16, "lr": 0.004, "log_every": 100,
              "checkpoint_every": 1000}
    cats = tuple(sorted(SIZES))
    torch.set_num_threads(1)
    progress = tmp_path_factory.mktemp("nets") / "progress.pt"
    nets, _ = nets_train.train(rooms[:34], rooms[34:], cats, preset, True, Session(0, progress, "test"),
                               {"snap_angle": 5.0, "none_share": 0.1})
    saved = Checkpoint("placement_nets", "test", {"nets": [n.state_dict() for n in nets]},
                       {"categories": list(cats), "preset": preset, "snap_angle": 5.0})
    prior = Checkpoint("pose_prior", "test", {}, learn_prior([(t.room, t.edges) for t in rooms], cfg["placement"]["prior"]))
    return {"cfcn": saved, "prior": prior}, pool_room


def test_placement_training_resumed_after_an_interrupt_ends_with_the_weights_of_an_uninterrupted_run(tmp_path):
    import torch

    from pipeline.learning.epochs import Session
    from pipeline.methods.planit.nets import train as nets_train

    rooms, _ = corpus(6)
    preset = {**default_config()["placement"]["presets"]["tiny"], "steps": 4, "batch_size": 4, "log_every": 2,
              "checkpoint_every": 2, "heldout_examples": 4}
    run = lambda steps, name, chash="h", ticks=None: nets_train.train(
        rooms[:5], rooms[5:], tuple(sorted(SIZES)), {**preset, "steps": steps}, True,
        Session(0, tmp_path / name, chash, tick=None if ticks is None else lambda step, row: ticks.append(step)))
    torch.set_num_threads(1)
    whole, history = run(4, "a.pt")
    ticks: list[int] = []
    run(2, "b.pt", ticks=ticks)  # interrupted after its checkpoint at step 2
    resumed, resumed_history = run(4, "b.pt")
    assert ticks == [2] and [r["step"] for r in resumed_history] == [r["step"] for r in history] == [2, 4]
    for a, b in zip(whole, resumed):
        for k, v in a.state_dict().items():
            assert torch.equal(v, b.state_dict()[k]), k
    other, fresh = run(2, "b.pt", "other")[0], run(2, "c.pt")[0]  # a progress file of other settings is not resumed
    assert all(torch.equal(v, fresh[0].state_dict()[k]) for k, v in other[0].state_dict().items())
    assert not all(torch.equal(v, whole[0].state_dict()[k]) for k, v in other[0].state_dict().items())


def setup_room(pool_room: Room, width=4.4, depth=4.6):
    cfg = default_config()
    empty = with_objects(Room([(0, 0), (width, 0), (width, depth), (0, depth)]).room_input(), [])
    return empty, walls_of(empty), ModelPool(pool_room.objects_df(), {}), checker_of(pool_room), cfg


def proposer_of(kind: str, saved, cfg):
    from pipeline.methods.planit.layout import make_proposer

    return make_proposer(kind, saved[kind], cfg["instantiate"], cfg["extract"])


def given(room, pool, cat: str, oid: str, xy, yaw_deg: float, support=None):
    """``room`` with an object of ``cat`` fixed at ``xy``, turned ``yaw_deg``."""
    inst = pool.pick(cat, "none", np.random.default_rng(0))
    box, pose = place(inst, xy[0], xy[1], support, math.radians(yaw_deg))
    return add_object(room, oid, cat, inst.model_id, box, pose)


def plan_of(oid: str, cat: str, edges: list[PlanEdge], parent=None) -> ScenePlan:
    return ScenePlan("s", "r0", "bedroom", [oid], [cat], [SYMMETRY[cat]], [2 if parent else 1], [parent], ["none"], edges)


def placed(out, oid):
    assert out.ok, out.reason
    return out.room.boxes[out.room.object_ids.index(oid)]


SEEDS = range(8)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["cfcn", "prior"])
def test_a_bed_planned_against_a_wall_gets_its_back_to_that_wall(learned, kind):
    saved, pool_room = learned
    room, walls, pool, checker, cfg = setup_room(pool_room)
    proposer = proposer_of(kind, saved, cfg)
    for w in (1, 2):  # the right wall, the top wall
        plan = plan_of("b", "bed", [PlanEdge(walls.ids[w], "b", "spatial", "front", "adjacent")])
        for seed in SEEDS:
            bed = placed(instantiate(plan, room, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed), "b")
            assert turn_error(bed[6] - wall_frame(walls, w).yaw) <= math.radians(5), (kind, w, seed, bed)
            assert back_to_wall(bed[None], room.outline, 0.1, math.radians(15))[0]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["cfcn", "prior"])
def test_a_nightstand_planned_beside_a_bed_stands_at_its_head(learned, kind):
    saved, pool_room = learned
    room, walls, pool, checker, cfg = setup_room(pool_room)
    room = given(room, pool, "bed", "bed", (2.2, 3.6), 180)  # head against the top wall
    proposer = proposer_of(kind, saved, cfg)
    heads = 0
    for side in ("left", "right"):
        plan = plan_of("n", "nightstand", [PlanEdge("bed", "n", "spatial", side, "adjacent")])
        for seed in SEEDS:
            out = instantiate(plan, room, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed)
            b = out.room.boxes
            heads += REGIONS[regions(b)[0, 1]] == "side_back"
            assert turn_error(placed(out, "n")[6] - b[0, 6], "left-right") <= math.radians(5)  # turned with the bed
    assert heads >= 2 * len(SEEDS) - 1, (kind, heads)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["cfcn", "prior"])
def test_a_tv_planned_on_a_stand_faces_the_way_the_stand_faces(learned, kind):
    saved, pool_room = learned
    room, walls, pool, checker, cfg = setup_room(pool_room)
    for yaw, xy in ((270, (0.2, 2.0)), (90, (4.2, 2.5))):  # against the left wall, then the right wall
        base = given(room, pool, "tv_stand", "stand", xy, yaw)
        plan = plan_of("t", "tv", [PlanEdge("stand", "t", "support", None, None)], parent="stand")
        for seed in SEEDS:
            tv = placed(instantiate(plan, base, [0], proposer_of(kind, saved, cfg), Kit(pool, checker),
                                    cfg["instantiate"], seed), "t")
            assert turn_error(tv[6] - math.radians(yaw)) <= math.radians(5), (kind, yaw, seed, tv)


def _tv_turned(room: Room, degrees: float) -> Room:
    """``room`` with its television turned ``degrees`` on its stand."""
    for o in room.objects:
        if o["category"] == "tv":
            o["yaw"] = o["yaw"] + math.radians(degrees)
    return room


def test_objects_on_a_support_turn_to_it_as_the_training_rooms_objects_do():
    # learned: televisions turned a few degrees off their stands (within 6); with a quarter of them turned half a
    # turn, both quarters, unless the least share asks for more; too few pairs: no rule
    cfg = default_config()
    jitter = np.round(np.random.default_rng(1).uniform(-6, 6, 12), 2)
    rooms = [_tv_turned(furnished(s), j) for s, j in enumerate(jitter)]
    learn = lambda rs, share=0.05: learn_support_turns([r.room_input() for r in rs], 0.02, cfg["floor_contact"], 10,
                                                       share)
    rule = learn(rooms)[("tv_stand", "tv")]
    assert rule.quarters == (0,) and sorted(np.degrees(rule.residuals[0])) == pytest.approx(sorted(jitter), abs=0.01)
    half = [_tv_turned(furnished(s), 180 if s % 4 == 0 else 0) for s in range(12)]
    assert learn(half)[("tv_stand", "tv")].quarters == (0, 2) and learn(half, 0.3)[("tv_stand", "tv")].quarters == (0,)
    assert learn(rooms[:9]) == {}
    # applied: a television drawn at any turn on its stand ends at the stand's turn plus one of the training residuals
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    base = given(room, pool, "tv_stand", "stand", (0.2, 2.0), 270)
    plan = plan_of("t", "tv", [PlanEdge("stand", "t", "support", None, None)], parent="stand")
    drawn = Combined(UniformLocation(), AnyTurn())
    turn = lambda proposer, seed: math.degrees(wrap(placed(instantiate(plan, base, [0], proposer, Kit(pool, checker),
                                                                       cfg["instantiate"], seed), "t")[6]
                                                    - math.radians(270)))
    assert sum(min(abs(turn(drawn, s) - jitter)) < 0.01 for s in SEEDS) == 0
    turned = TurnedOnSupport(drawn, learn(rooms))
    assert all(min(abs(turn(turned, s) - jitter)) < 0.01 for s in SEEDS)


def test_objects_stand_on_their_anchors_centre_lines_as_often_as_in_the_training_rooms():
    # learned: the hand-built rooms' televisions stand on their stands' middles and chairs on their desks' centre
    # lines, nightstands beside the bed's head (off its middle); 0.1 m off in both axes, no support rule
    cfg = default_config()
    learn = lambda rooms, least=10: learn_centring(rooms, Window(0.02, least), 0.02, cfg["floor_contact"], math.pi / 4)
    rules = learn([furnished(s).room_input() for s in range(12)])
    assert rules[("tv_stand", "tv", "support")][:2] == (1.0, 1.0)
    assert rules[("desk", "chair", "spatial")][:2] == (1.0, 0.0) and ("bed", "nightstand", "spatial") not in rules
    assert not any(kind == "support" for _, _, kind in learn([furnished(s).room_input() for s in range(9)]))  # too few
    shifted = [furnished(s) for s in range(12)]
    for r in shifted:
        for o in r.objects:
            if o["category"] == "tv":
                o["cx"], o["cy"], o["px"], o["py"] = o["cx"] + 0.1, o["cy"] + 0.1, o["px"] + 0.1, o["py"] + 0.1
    assert ("tv_stand", "tv", "support") not in learn([r.room_input() for r in shifted])
    # applied: uniform places on the stand's top land anywhere on it; centred, on its middle (within float error)
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    base = given(room, pool, "tv_stand", "stand", (0.2, 2.0), 270)
    plan = plan_of("t", "tv", [PlanEdge("stand", "t", "support", None, None)], parent="stand")
    uniform = Combined(UniformLocation(), FaceAway())
    offset = lambda proposer, seed: np.abs(to_local(box_frame(base.boxes[0]), placed(
        instantiate(plan, base, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed), "t")[:2]))
    assert max(offset(uniform, seed).max() for seed in SEEDS) > 0.05
    centred = Centred(uniform, {("tv_stand", "tv", "support"): (1.0, 1.0)})
    assert max(offset(centred, seed).max() for seed in SEEDS) < 1e-9
    across = Centred(uniform, {("tv_stand", "tv", "support"): (1.0, 0.0)})  # across only: the depth stays drawn
    offs = np.array([offset(across, seed) for seed in SEEDS])
    assert offs[:, 0].max() < 1e-9 and offs[:, 1].max() > 0.01
    # a chair planned in front of a desk: on the desk's centre line across it, wherever the band put it
    desk = given(room, pool, "desk", "desk", (2.2, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge("desk", "c", "spatial", "front", "adjacent")])
    chair = Centred(Combined(RelationPrior(cfg["extract"]), FaceAway()), {("desk", "chair", "spatial"): (1.0, 0.0)})
    for seed in SEEDS:
        c = placed(instantiate(plan, desk, [0], chair, Kit(pool, checker), cfg["instantiate"], seed), "c")
        assert abs(to_local(box_frame(desk.boxes[0]), c[:2])[0]) < 1e-9, seed


def _shifted(room: Room, category: str, d) -> Room:
    """``room`` with its objects of ``category`` moved by ``d (2,)`` m."""
    for o in room.objects:
        if o["category"] == category:
            o["cx"], o["cy"], o["px"], o["py"] = o["cx"] + d[0], o["cy"] + d[1], o["px"] + d[0], o["py"] + d[1]
    return room


def _chair_across(room: Room, across: float) -> Room:
    """``room`` with its chair moved ``across`` m along its desk's local x (off the desk's centre line)."""
    inp = room.room_input()
    b = inp.boxes.reshape(-1, 7)
    desk, chair = b[inp.object_ids.index("desk")], b[inp.object_ids.index("chair")]
    return _shifted(room, "chair", to_world(box_frame(desk), to_local(box_frame(desk), chair[:2]) + [across, 0.0])
                    - chair[:2])


def test_objects_stand_as_far_off_their_anchors_centre_lines_as_in_the_training_rooms_where_that_is_concentrated():
    # learned: chairs a few cm off their desks' centre line (|offset| <= 6 cm): within 10 cm all of them, with their
    # offsets, where a 2 cm line holds a third; chairs spread evenly over the desk's width (1.2 m) stand within 10 cm
    # of its line only as often as chance (1 in 6), which concentration 3 refuses
    cfg = default_config()
    learn = lambda rooms, within, concentration: learn_centring(rooms, Window(within, 10, concentration), 0.02,
                                                                cfg["floor_contact"], math.pi / 4)
    jitter = np.round(np.random.default_rng(0).uniform(-0.06, 0.06, 12), 3)
    near = [_chair_across(furnished(s), j).room_input() for s, j in enumerate(jitter)]
    line = learn(near, 0.1, 3.0)[("desk", "chair", "spatial")]
    assert line.across == 1.0 and sorted(line.across_offsets) == pytest.approx(sorted(jitter), abs=1e-3)
    assert learn(near, 0.02, 0.0)[("desk", "chair", "spatial")].across == round(float(np.mean(abs(jitter) <= 0.02)), 3) < 0.5
    # the window is also at most a fraction of the anchor's half extent (0.05 of the desk's 0.6 m: 3 cm)
    small = learn_centring(near, Window(0.1, fraction=0.05), 0.02, cfg["floor_contact"], math.pi / 4)
    assert small[("desk", "chair", "spatial")].across == round(float(np.mean(abs(jitter) <= 0.03)), 3)
    spread = [_chair_across(furnished(s), j).room_input() for s, j in enumerate(np.linspace(-0.55, 0.55, 12))]
    assert learn(spread, 0.1, 0.0)[("desk", "chair", "spatial")].across == pytest.approx(2 / 12, abs=1e-3)
    assert ("desk", "chair", "spatial") not in learn(spread, 0.1, 3.0)
    # applied: a chair planned in front of a desk stands at one of the rule's offsets across it, each drawn
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    desk = given(room, pool, "desk", "desk", (2.2, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge("desk", "c", "spatial", "front", "adjacent")])
    chair = Centred(Combined(RelationPrior(cfg["extract"]), FaceAway()),
                    {("desk", "chair", "spatial"): CentreLine(1.0, 0.0, (-0.05, 0.04))})
    across = [round(float(to_local(box_frame(desk.boxes[0]), placed(instantiate(
        plan, desk, [0], chair, Kit(pool, checker), cfg["instantiate"], seed), "c")[:2])[0]), 6) for seed in SEEDS]
    assert set(across) == {-0.05, 0.04}, across


class Sideways:
    """Front turned a quarter turn from "away from the first anchor" (a wall): a desk with its side to that wall."""

    def orientation(self, req, xy, rng) -> float:
        return req.anchors[0].frame.yaw + math.pi / 2


class AnyTurn:
    """Any turn, drawn uniformly."""

    def orientation(self, req, xy, rng) -> float:
        return float(rng.uniform(-math.pi, math.pi))


def _desk_sideways(room: Room) -> Room:
    """``room`` with its desk turned a quarter turn, its side flush against the wall its back was against."""
    desk = room.room_input().boxes.reshape(-1, 7)[room.room_input().object_ids.index("desk")]
    for o in room.objects:
        if o["category"] == "desk":
            o["yaw"] = o["yaw"] + math.pi / 2
    return _shifted(room, "desk", (desk[3] - desk[4]) * np.array([-math.sin(desk[6]), math.cos(desk[6])]))


def test_objects_planned_against_a_wall_turn_their_back_to_it_as_often_as_in_the_training_rooms():
    # learned: the hand-built rooms' desks, beds, nightstands and TV stands all stand with their backs to the wall
    # they stand against; desks turned with their side to it give no desk rule; too few rooms give none
    cfg = default_config()
    learn = lambda rooms: learn_wall_backs(rooms, 0.1, math.radians(15), 10, cfg["floor_contact"])
    shares = learn([furnished(s).room_input() for s in range(12)])
    assert shares == {"bed": 1.0, "desk": 1.0, "nightstand": 1.0, "tv_stand": 1.0}, shares
    turned = [_desk_sideways(furnished(s)).room_input() for s in range(12)]
    desks = [(r.boxes.reshape(-1, 7)[[r.object_ids.index("desk")]], r.outline) for r in turned]
    assert all(back_to_wall(d, o, 0.1, math.radians(15), ["rotational-4"])[0] for d, o in desks)  # against a wall
    assert not any(back_to_wall(d, o, 0.1, math.radians(15))[0] for d, o in desks)  # by its side
    assert "desk" not in learn(turned) and learn(turned)["bed"] == 1.0
    assert learn([furnished(s).room_input() for s in range(4)]) == {}  # 8 nightstands, 4 of the rest
    # wall-bound: the categories standing against a wall (any side) at least the share asked; the sideways desks too
    bound = lambda rooms, share=0.95: learn_wall_bound(rooms, 0.1, math.radians(15), share, 10, cfg["floor_contact"])
    assert bound([furnished(s).room_input() for s in range(12)]) == {"bed", "desk", "nightstand", "tv_stand"}
    assert bound(turned) == {"bed", "desk", "nightstand", "tv_stand"}
    assert bound([furnished(s).room_input() for s in range(4)]) == frozenset()  # 8 nightstands, 4 of the rest
    assert bound([furnished(s).room_input() for s in range(12)], 0) == frozenset()
    # applied: a desk planned against the right wall, drawn with its side to the nearest wall, stands sideways; with
    # the rule its back is to the planned wall (the search's snap slides it flush)
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    plan = plan_of("d", "desk", [PlanEdge(walls.ids[1], "d", "spatial", "front", "adjacent")])
    drawn = Combined(RelationPrior(cfg["extract"]), Sideways())
    desk = lambda proposer, seed: placed(instantiate(plan, room, [0], proposer, Kit(pool, checker),
                                                     cfg["instantiate"], seed), "d")
    assert all(turn_error(desk(drawn, seed)[6] - wall_frame(walls, 1).yaw) > 1.5 for seed in SEEDS)
    backed = BackToWall(drawn, {"desk": 1.0})
    for seed in SEEDS:
        d = desk(backed, seed)
        assert turn_error(d[6] - wall_frame(walls, 1).yaw) <= 1e-9, (seed, d)
        assert back_to_wall(d[None], room.outline, 0.1, math.radians(15))[0], (seed, d)


def test_edge_gap_reads_flush_overhanging_and_turned_footprints_and_onto_back_inverts_it():
    desk = np.array([1.0, 2.0, 0.4, 0.6, 0.3, 0.4, 0.0])  # depth along y: back edge at y = 1.7
    box = lambda x, y, yaw, hx=0.2, hy=0.1: np.array([x, y, 0.9, hx, hy, 0.1, yaw])
    assert edge_gap(desk, box(1.3, 1.8, 0.0)) == pytest.approx(0.0)  # flush: its back face on the edge
    assert edge_gap(desk, box(0.8, 1.85, math.pi)) == pytest.approx(0.05)  # turned round: same depth
    assert edge_gap(desk, box(1.0, 1.9, math.pi / 2)) == pytest.approx(0.0)  # a quarter turn: its width is the depth
    assert edge_gap(desk, box(1.0, 1.75, 0.0)) == pytest.approx(-0.05)  # overhangs the back
    turned = desk.copy()
    turned[6] = math.pi / 2  # the back edge now at x = 1.3 (local -y points to +x)
    assert edge_gap(turned, box(1.2, 2.0, math.pi / 2)) == pytest.approx(0.0)
    assert edge_gap(turned, box(1.2, 2.0, 0.0)) == pytest.approx(-0.1)  # its 0.2 m half width overhangs by 0.1
    rng = np.random.default_rng(0)
    for support in (desk, turned):
        for _ in range(20):
            yaw, xy = rng.uniform(-math.pi, math.pi), support[:2] + rng.uniform(-0.3, 0.3, 2)
            moved = Centred._onto_edge(support, (0.2, 0.1), yaw, ("back", EdgeRule(1.0, 0.016, -1.0, 1.0)), xy)
            assert edge_gap(support, box(*moved, yaw)) == pytest.approx(0.016)
            assert to_local(box_frame(support), moved)[0] == pytest.approx(to_local(box_frame(support), xy)[0])


def _tv_at_back(room: Room, gap: float, edge: str = "back") -> Room:
    """``room`` with its TV moved along its stand to stand ``gap`` m from the stand's back (front) edge."""
    inp = room.room_input()
    b = inp.boxes.reshape(-1, 7)
    stand, tv = b[inp.object_ids.index("stand")], b[inp.object_ids.index("tv")]
    toward = EDGES[edge] * np.array([-math.sin(stand[6]), math.cos(stand[6])])  # the stand's local +y in the room
    return _shifted(room, "tv", (edge_gap(stand, tv, edge) - gap) * toward)


def test_objects_stand_at_their_supports_back_edge_as_often_as_in_the_training_rooms():
    # learned: televisions 1 cm (5 cm) from their stands' back edges give a back rule at that gap; centred ones (15 cm
    # off it: their share on the stand's middle is as high) give none; too few pairs give none
    cfg = default_config()
    flush = cfg["instantiate"]["snap"]["flush_within"]
    learn = lambda rooms, least=10: learn_centring(rooms, Window(0.02, least), 0.02, cfg["floor_contact"], math.pi / 4, flush)
    centred = [furnished(s).room_input() for s in range(12)]
    assert min(edge_gap(r.boxes.reshape(-1, 7)[r.object_ids.index("stand")],
                        r.boxes.reshape(-1, 7)[r.object_ids.index("tv")]) for r in centred) > flush
    assert ("tv_stand", "tv", "back") not in learn(centred)
    at_back = [_tv_at_back(furnished(s), 0.01).room_input() for s in range(12)]
    rules = learn(at_back)
    offsets = [to_local(box_frame(r.boxes.reshape(-1, 7)[r.object_ids.index("stand")]),
                        r.boxes.reshape(-1, 7)[r.object_ids.index("tv"), :2])[1] for r in at_back]
    assert rules[("tv_stand", "tv", "back")][:2] == (1.0, 0.01)
    low, high, across_low, across_high = rules[("tv_stand", "tv", "back")][2:]
    assert min(offsets) - 0.001 < low <= min(offsets) and max(offsets) <= high < max(offsets) + 0.001
    assert -0.001 <= across_low <= 0.0 <= across_high <= 0.001  # every training TV on the stand's middle across it
    assert learn([_tv_at_back(furnished(s), 0.05).room_input() for s in range(12)])[("tv_stand", "tv", "back")][:2] == (
        1.0, 0.05)
    assert ("tv_stand", "tv", "back") not in learn([_tv_at_back(furnished(s), 0.01).room_input() for s in range(9)])
    at_front = learn([_tv_at_back(furnished(s), 0.02, "front").room_input() for s in range(12)])
    assert at_front[("tv_stand", "tv", "front")][:2] == (1.0, 0.02) and ("tv_stand", "tv", "back") not in at_front
    # applied: uniform places on the stand's top stand anywhere along it; with the rule, at its gap from the back edge,
    # the offset across the stand still drawn
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    base = given(room, pool, "tv_stand", "stand", (0.2, 2.0), 270)
    plan = plan_of("t", "tv", [PlanEdge("stand", "t", "support", None, None)], parent="stand")
    uniform = Combined(UniformLocation(), FaceAway())
    tv = lambda proposer, seed: placed(instantiate(plan, base, [0], proposer, Kit(pool, checker), cfg["instantiate"],
                                                   seed), "t")
    assert max(abs(edge_gap(base.boxes[0], tv(uniform, seed)) - 0.01) for seed in SEEDS) > 0.02
    at_back = Centred(uniform, {("tv_stand", "tv", "back"): (1.0, 0.01, -1.0, 1.0)})
    placed_tvs = [tv(at_back, seed) for seed in SEEDS]
    assert max(abs(edge_gap(base.boxes[0], t) - 0.01) for t in placed_tvs) < 1e-9
    assert np.ptp([to_local(box_frame(base.boxes[0]), t[:2])[0] for t in placed_tvs]) > 0.01
    # refused where the back edge lies farther off the stand's centre line than any training TV stood, and the drawn
    # place kept within the training TVs' offsets along the stand's depth: none at the back, all on the middle
    beyond = Centred(uniform, {("tv_stand", "tv", "back"): (1.0, 0.01, -0.001, 0.001)})
    assert min(abs(edge_gap(base.boxes[0], tv(beyond, seed)) - 0.01) for seed in SEEDS) > 1e-3
    assert max(abs(to_local(box_frame(base.boxes[0]), tv(beyond, seed)[:2])[1]) for seed in SEEDS) <= 0.001 + 1e-9
    at_front = Centred(uniform, {("tv_stand", "tv", "front"): (1.0, 0.02, -1.0, 1.0)})
    assert max(abs(edge_gap(base.boxes[0], tv(at_front, seed), "front") - 0.02) for seed in SEEDS) < 1e-9
    # and across the stand within the training TVs' offsets (5 cm either side of the middle), wherever drawn
    across = lambda proposer: [to_local(box_frame(base.boxes[0]), tv(proposer, seed)[:2])[0] for seed in SEEDS]
    assert max(map(abs, across(at_back))) > 0.05
    narrow = Centred(uniform, {("tv_stand", "tv", "back"): (1.0, 0.01, -1.0, 1.0, -0.05, 0.05)})
    assert max(map(abs, across(narrow))) <= 0.05 + 1e-9


def test_objects_not_at_their_supports_back_edge_stand_where_the_training_rooms_others_stand():
    # learned: 18 of 30 televisions 1 cm from their stands' back edges, 12 on the stand's middle: the centre lines of
    # the 12 not at the back (all on the middle), beside those over every pair (0.4 along)
    cfg = default_config()
    flush = cfg["instantiate"]["snap"]["flush_within"]
    mixed = [_tv_at_back(furnished(s), 0.01).room_input() for s in range(18)] + [furnished(s).room_input()
                                                                                for s in range(18, 30)]
    rules = learn_centring(mixed, Window(0.02), 0.02, cfg["floor_contact"], math.pi / 4, flush)
    assert rules[("tv_stand", "tv", "back")][:2] == (0.6, 0.01)
    line, overall = rules[("tv_stand", "tv", OFF_EDGE)], rules[("tv_stand", "tv", "support")]
    assert line.along == 1.0 and len(line.along_offsets) == 12 and max(map(abs, line.along_offsets)) < 1e-9
    assert line.across == 1.0 and len(line.across_offsets) == 12 and overall.along == 0.4
    # applied: every television stands at the back edge or on the middle, both seen
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    base = given(room, pool, "tv_stand", "stand", (0.2, 2.0), 270)
    plan = plan_of("t", "tv", [PlanEdge("stand", "t", "support", None, None)], parent="stand")
    proposer = Centred(Combined(UniformLocation(), FaceAway()), rules)
    tvs = [placed(instantiate(plan, base, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed), "t")
           for seed in SEEDS]
    at_back = [abs(edge_gap(base.boxes[0], t) - 0.01) < 1e-9 for t in tvs]
    middle = [abs(to_local(box_frame(base.boxes[0]), t[:2])[1]) < 1e-9 for t in tvs]
    assert all(a or m for a, m in zip(at_back, middle)) and any(at_back) and any(middle)


def test_two_objects_facing_each_other_stand_on_one_axis_as_in_the_training_rooms_planned_edge_or_not():
    # learned: the hand-built rooms' chairs face their desks on the desk's centre line (both ways round); a chair
    # 0.1 m off it, or one turned away, gives no rule; the bed and the desk stand back to back, not facing
    cfg = default_config()
    learn = lambda rooms: learn_centring(rooms, Window(0.02), 0.02, cfg["floor_contact"], math.pi / 4)
    rules = learn([furnished(s).room_input() for s in range(12)])
    assert rules[("desk", "chair", "facing")][:2] == (1.0, 0.0) and rules[("chair", "desk", "facing")][:2] == (1.0, 0.0)
    assert not any(key[2] == "facing" and "bed" in key for key in rules)
    for dx, turn in ((0.1, 0.0), (0.0, 90.0)):
        moved = [furnished(s) for s in range(12)]
        for r in moved:
            for o in r.objects:
                if o["category"] == "chair":
                    o["cx"], o["cy"], o["px"], o["py"] = o["cx"] + dx, o["cy"] + dx, o["px"] + dx, o["py"] + dx
                    o["yaw"] = o["yaw"] + math.radians(turn)
        assert ("desk", "chair", "facing") not in learn([r.room_input() for r in moved]), (dx, turn)
    # applied: a chair planned only against the top wall (no edge to the desk at the bottom wall) faces the desk from
    # wherever the band puts it along that wall; with the rule, on the desk's centre line
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    desk = given(room, pool, "desk", "desk", (2.7, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge(walls.ids[2], "c", "spatial", "front", "adjacent")])
    drawn = Combined(RelationPrior(cfg["extract"]), FaceAway())
    across = lambda proposer, seed: to_local(box_frame(desk.boxes[0]), placed(
        instantiate(plan, desk, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed), "c")[:2])[0]
    assert max(abs(across(drawn, seed)) for seed in SEEDS) > 0.3
    centred = Centred(drawn, {("desk", "chair", "facing"): (1.0, 0.0)})
    assert max(abs(across(centred, seed)) for seed in SEEDS) < 1e-9
    # not when it would stand beside the desk rather than across from it: a chair planned against the right wall
    side = plan_of("c", "chair", [PlanEdge(walls.ids[1], "c", "spatial", "front", "adjacent")])
    beside = [to_local(box_frame(desk.boxes[0]), placed(instantiate(side, desk, [0], centred, Kit(pool, checker),
                                                                    cfg["instantiate"], seed), "c")[:2])[0]
              for seed in SEEDS]
    assert min(abs(u) for u in beside) > 1.0


def test_an_object_planned_in_front_of_an_anchor_it_faces_takes_the_facing_pairs_line():
    # the spatial rule (chairs in front of desks at large) puts half the chairs 0.3 m off the desk's line; a chair
    # that faces its desk at the drawn pose takes the facing rule (every facing pair on the line) instead
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    desk = given(room, pool, "desk", "desk", (2.7, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge("desk", "c", "spatial", "front", "adjacent")])
    drawn = FaceAnchor(Combined(RelationPrior(cfg["extract"]), FaceAway()), {("desk", "chair"): AnchorFacing(1.0)})
    spatial = {("desk", "chair", "spatial"): CentreLine(1.0, 0.0, (0.3, -0.3), (0.0,))}
    chairs = lambda rules: [placed(instantiate(plan, desk, [0], Centred(drawn, rules), Kit(pool, checker),
                                               cfg["instantiate"], seed), "c") for seed in SEEDS]
    across = lambda chair: to_local(box_frame(desk.boxes[0]), chair[:2])[0]
    faced = [facing_each_other(np.vstack([desk.boxes[0], c]), math.pi / 4)[0, 1] for c in chairs(spatial)]
    assert all(faced) and min(abs(across(c)) for c in chairs(spatial)) > 0.29
    both = {**spatial, ("desk", "chair", "facing"): CentreLine(1.0, 0.0, (0.0,), (0.0,))}
    assert max(abs(across(c)) for c in chairs(both)) < 1e-9


class _Drawn:
    """A base proposer that always draws ``pose`` (xy, yaw rad)."""

    def __init__(self, xy, yaw: float):
        self.xy, self.yaw = np.asarray(xy, float), yaw

    def pose(self, req, rng):
        return self.xy.copy(), self.yaw


def test_centring_never_moves_an_object_off_another_planned_edges_place():
    # a table (a desk here) with a chair seated behind it; a second chair planned in front of the table and right,
    # distant, of the first: the chair/chair rule (every training pair on one line, across and along) would move it
    # to the first chair's depth, behind the table; the table's edge holds it along that axis, so it stays in front.
    # The facing rule likewise leaves the depth of a chair planned in front of the table, facing a chair across it.
    # Only adjacent and proximal edges hold: a distant one allows any distance beyond the proximal gap.
    from pipeline.placement.anchors import anchors_of
    from pipeline.placement.proposers import Grid, Request

    room, walls, pool, _, _ = setup_room(furnished(0))
    table = given(given(room, pool, "desk", "table", (2.2, 2.3), 0), pool, "chair", "c1", (2.2, 1.7), 0)
    plan = plan_of("c2", "chair", [PlanEdge("table", "c2", "spatial", "front", "proximal"),
                                   PlanEdge("c1", "c2", "spatial", "right", "distant")])
    anchors = anchors_of("c2", plan, table, walls, {}, (0.25, 0.25))
    req = Request(table, walls, "chair", "left-right", anchors, Grid(table.outline, 0.1), np.ones(1, bool))
    drawn = _Drawn((3.4, 2.9), math.pi)  # in front of the table, facing it
    rules = {("chair", "chair", "spatial"): CentreLine(1.0, 1.0)}
    xy, _ = Centred(drawn, rules).pose(req, np.random.default_rng(0))
    assert np.allclose(xy, [3.4, 2.9])
    alone = Request(table, walls, "chair", "left-right", [a for a in anchors if a.node == "c1"],
                    Grid(table.outline, 0.1), np.ones(1, bool))  # without the table's edge the rule applies
    assert np.allclose(Centred(drawn, rules).pose(alone, np.random.default_rng(0))[0], [3.4, 1.7])
    loose = [replace(a, distance="distant") for a in anchors]  # a distant edge allows any distance: it holds nothing
    req = Request(table, walls, "chair", "left-right", loose, Grid(table.outline, 0.1), np.ones(1, bool))
    assert np.allclose(Centred(drawn, rules).pose(req, np.random.default_rng(0))[0], [3.4, 1.7])
    round_ = [replace(a, symmetry="radial") if a.node == "table" else a for a in anchors]  # every edge of it "front"
    req = Request(table, walls, "chair", "left-right", round_, Grid(table.outline, 0.1), np.ones(1, bool))
    assert np.allclose(Centred(drawn, rules).pose(req, np.random.default_rng(0))[0], [3.4, 1.7])
    # facing: c1 turned to face c2's drawn place; c2 planned only in front of the table
    facing = given(given(room, pool, "desk", "table", (2.2, 2.3), 0), pool, "chair", "c1", (2.6, 2.9), -math.degrees(math.pi / 2))
    front = plan_of("c2", "chair", [PlanEdge("table", "c2", "spatial", "front", "proximal")])
    req = Request(facing, walls, "chair", "left-right", anchors_of("c2", front, facing, walls, {}, (0.25, 0.25)),
                  Grid(facing.outline, 0.1), np.ones(1, bool))
    turned = _Drawn((3.4, 3.1), math.pi / 2)  # facing c1 (along -x), which faces it back
    xy, _ = Centred(turned, {("chair", "chair", "facing"): CentreLine(1.0, 0.0)}).pose(req, np.random.default_rng(0))
    assert np.allclose(xy, [3.4, 3.1])


def _chairs_turned(rooms: list[Room], every: int) -> list[Room]:
    """``rooms`` with the chair of every ``every``-th room turned a quarter turn (its side to its desk)."""
    for r in rooms[::every]:
        for o in r.objects:
            if o["category"] == "chair":
                o["yaw"] = o["yaw"] + math.pi / 2
    return rooms


def test_objects_planned_beside_an_anchor_face_it_as_often_as_in_the_training_rooms():
    # learned: the hand-built rooms' chairs stand within 0.5 m in front of their desks, facing them, and the desks
    # face the chairs; nightstands stand beside beds facing the way the bed does (no rule); chairs turned sideways
    # give none; too few pairs give none
    cfg = default_config()
    learn = lambda rooms: learn_anchor_facing([r.room_input() for r in rooms], 0.5, math.pi / 4, 10, 0.8,
                                              cfg["floor_contact"])
    shares = lambda rooms: {pair: rule.share for pair, rule in learn(rooms).items()}
    assert shares([furnished(s) for s in range(12)]) == {("chair", "desk"): 1.0, ("desk", "chair"): 1.0}
    assert shares(_chairs_turned([furnished(s) for s in range(12)], 1)) == {("chair", "desk"): 1.0}  # desks still do
    assert learn([furnished(s) for s in range(4)]) == {}
    # with the turns the training chairs stand off square to their desk (each within 8 degrees)
    skew = np.round(np.random.default_rng(2).uniform(-8, 8, 12), 2)
    skewed = [furnished(s) for s in range(12)]
    for room, d in zip(skewed, skew):
        for o in room.objects:
            if o["category"] == "chair":
                o["yaw"] = o["yaw"] + math.radians(d)
    rule = learn(skewed)[("desk", "chair")]
    assert rule.share == 1.0 and sorted(np.degrees(rule.residuals)) == pytest.approx(sorted(skew), abs=0.01)
    # applied: a chair planned in front of the desk, drawn with its front turned away from the top wall (the desk's
    # side or back), faces the desk with the rule, whatever the turn drawn
    room, walls, pool, checker, cfg = setup_room(furnished(0))
    desk = given(room, pool, "desk", "desk", (2.2, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge("desk", "c", "spatial", "front", "proximal")])
    chair = lambda proposer, seed: placed(instantiate(plan, desk, [0], proposer, Kit(pool, checker),
                                                      cfg["instantiate"], seed), "c")
    angle = lambda proposer, seed: facing_angles(np.vstack([desk.boxes.reshape(-1, 7), chair(proposer, seed)]))[0, 1]
    drawn = Combined(RelationPrior(cfg["extract"]), Sideways())
    assert all(angle(drawn, seed) > math.pi / 4 for seed in SEEDS)
    turned = FaceAnchor(drawn, {("desk", "chair"): AnchorFacing(1.0)})
    assert all(angle(turned, seed) < math.pi / 4 for seed in SEEDS)
    assert all(turn_error(chair(turned, seed)[6] - math.pi) < 1e-9 for seed in SEEDS)  # square to the desk
    assert all(np.array_equal(chair(drawn, seed), chair(FaceAnchor(drawn, {}), seed)) for seed in SEEDS)
    # turned off square by one of the training chairs' turns
    askew = FaceAnchor(drawn, {("desk", "chair"): rule})
    assert all(min(abs(np.degrees(wrap(chair(askew, seed)[6] - math.pi)) - skew)) < 0.01 for seed in SEEDS)
    # a partner rule never turns it away from the desk it faces by its plan: a nightstand up the room's left side,
    # turned to face the chair's place, is a partner the chair can be turned to face, and is not
    with_stand = given(desk, pool, "nightstand", "ns", (0.4, 2.5), -90)
    partnered = FacingPartner(turned, {("nightstand", "chair"): 1.0}, math.pi / 4, 16)
    to_desk = lambda seed: facing_angles(np.vstack([desk.boxes.reshape(-1, 7), placed(instantiate(
        plan, with_stand, [0], partnered, Kit(pool, checker), cfg["instantiate"], seed), "c")]))[0, 1]
    assert all(to_desk(seed) < math.pi / 4 for seed in SEEDS)


def test_objects_face_the_objects_and_partner_walls_the_training_rooms_objects_face_where_the_plan_cannot_say():
    # learned: the hand-built rooms' chairs and desks face each other (both ways round), and the desks face the beds
    # and nightstands across the room; with half the chairs turned sideways the chairs' share is 0.5, kept only at a
    # lower least share; all turned: 0
    cfg = default_config()
    learn = lambda rooms, least=0.8: learn_facing_partners([r.room_input() for r in rooms], math.pi / 4, 10, least,
                                                           cfg["floor_contact"])
    chairs = lambda rules: {pair: share for pair, share in rules.items() if "chair" in pair}
    across = {(a, b): 1.0 for p, q in (("bed", "desk"), ("nightstand", "desk")) for a, b in ((p, q), (q, p))}
    assert learn([furnished(s) for s in range(12)]) == {("chair", "desk"): 1.0, ("desk", "chair"): 1.0, **across}
    assert learn(_chairs_turned([furnished(s) for s in range(12)], 2)) == across
    assert chairs(learn(_chairs_turned([furnished(s) for s in range(12)], 2), 0.4)) == {("chair", "desk"): 0.5,
                                                                                       ("desk", "chair"): 0.5}
    none = learn(_chairs_turned([furnished(s) for s in range(12)], 1), 0.0)
    assert none[("chair", "desk")] == none[("desk", "chair")] == 0.0
    assert learn([furnished(s) for s in range(4)]) == {}  # 4 chairs: too few
    # applied: in a long, shallow room a chair planned only against the top wall, facing into the room, faces the desk
    # at the bottom wall's left end from under half of that wall; with the rule, always (and a planned desk edge, or
    # no desk, leaves the draw alone)
    room, walls, pool, checker, cfg = setup_room(furnished(0), width=8.0, depth=3.0)
    desk = given(room, pool, "desk", "desk", (1.0, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge(walls.ids[2], "c", "spatial", "front", "adjacent")])
    drawn = Combined(RelationPrior(cfg["extract"]), FaceAway())
    faces = lambda proposer, seed: bool(facing_each_other(np.vstack([desk.boxes.reshape(-1, 7), placed(
        instantiate(plan, desk, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed), "c")]),
        math.pi / 4)[0, 1])
    assert sum(faces(drawn, seed) for seed in SEEDS) < len(SEEDS) - 2
    partnered = FacingPartner(drawn, {("desk", "chair"): 1.0}, math.pi / 4, 16)
    assert all(faces(partnered, seed) for seed in SEEDS)
    # a proposer that only ever turns the chair sideways to its wall never faces the desk; with the rule the chair is
    # turned to squarely face the desk's side its place lies beyond, where that faces
    sideways = Combined(RelationPrior(cfg["extract"]), Sideways())
    assert not any(faces(sideways, seed) for seed in SEEDS)
    assert all(faces(FacingPartner(sideways, {("desk", "chair"): 1.0}, math.pi / 4, 16), seed) for seed in SEEDS)
    alone = lambda proposer, seed: placed(instantiate(plan, room, [0], proposer, Kit(pool, checker),
                                                      cfg["instantiate"], seed), "c")
    assert all(np.array_equal(alone(drawn, seed), alone(partnered, seed)) for seed in SEEDS)
    # a partner planned against a wall but placed later stands in as that wall: the chair placed first, turned at
    # random, faces the bottom wall its desk will stand against only with the rule
    both = ScenePlan("s", "r0", "bedroom", ["c", "d"], ["chair", "desk"], ["left-right", "none"], [1, 1], [None, None],
                     ["none", "none"], [PlanEdge(walls.ids[2], "c", "spatial", "front", "adjacent"),
                                        PlanEdge(walls.ids[0], "d", "spatial", "front", "adjacent")])
    turned = Combined(RelationPrior(cfg["extract"]), AnyTurn())
    first = lambda proposer, seed: placed(instantiate(both, room, [0, 1], proposer, Kit(pool, checker),
                                                      cfg["instantiate"], seed), "c")
    down = lambda box: -math.cos(box[6]) >= math.cos(math.pi / 4)  # its front within 45 degrees of -y
    assert sum(down(first(turned, seed)) for seed in SEEDS) < len(SEEDS) - 2
    assert all(down(first(FacingPartner(turned, {("desk", "chair"): 1.0}, math.pi / 4, 16), seed)) for seed in SEEDS)
    # and so where the plan puts that desk in front of the chair: the edge the chair anchors cannot be checked before
    # the desk stands, the wall it will stand against can (a sofa placed before the television stand it faces)
    planned = replace(both, edges=[*both.edges, PlanEdge("c", "d", "spatial", "front", "distant")])
    ahead = lambda proposer, seed: placed(instantiate(planned, room, [0, 1], proposer, Kit(pool, checker),
                                                      cfg["instantiate"], seed), "c")
    assert sum(down(ahead(turned, seed)) for seed in SEEDS) < len(SEEDS) - 2
    assert all(down(ahead(FacingPartner(turned, {("desk", "chair"): 1.0}, math.pi / 4, 16), seed)) for seed in SEEDS)


def test_an_object_goes_before_the_facing_partner_the_plan_puts_against_a_wall_and_so_stands_on_its_line():
    # the living rooms' miss, with a bed for the sofa: the plan puts the stand adjacent to the left wall and the bed
    # proximal to the top wall, no edge between them. PlanIT's order places the stand first (adjacent weighs more),
    # anywhere along its wall; the bed, held near the top wall, then faces it from off its line. Placed first, the bed
    # faces the stand's wall and the stand slides along it onto the bed's line
    room, walls, pool, checker, cfg = setup_room(furnished(0), width=5.8, depth=5.1)
    plan = ScenePlan("s", "r0", "living", ["b", "t"], ["bed", "tv_stand"], ["left-right"] * 2, [1, 1], [None, None],
                     ["none", "none"], [PlanEdge(walls.ids[2], "b", "spatial", "front", "proximal"),
                                        PlanEdge(walls.ids[3], "t", "spatial", "front", "adjacent")])
    partners = {("tv_stand", "bed"): 1.0, ("bed", "tv_stand"): 1.0}
    assert order.facing_first(plan, partners, walls) == [(0, 1)]
    assert order.placement_order(plan, {}) == [1, 0]
    assert order.placement_order(plan, {}, first=order.facing_first(plan, partners, walls)) == [0, 1]
    drawn = BackToWall(Combined(RelationPrior(cfg["extract"]), FaceAway()), {"tv_stand": 1.0})
    lines = {(a, b, "facing"): CentreLine(1.0, 0.0) for a, b in partners}
    proposer = Centred(FacingPartner(drawn, partners, math.pi / 4, 8), lines)

    def on_line(seq, seed) -> bool:
        out = instantiate(plan, room, seq, proposer, Kit(pool, checker), cfg["instantiate"], seed)
        bed, stand = placed(out, "b"), placed(out, "t")
        faced = facing_each_other(np.vstack([bed, stand]), math.pi / 4)[0, 1]
        return bool(faced and abs(to_local(box_frame(bed), stand[:2])[0]) < 0.05)

    assert sum(on_line([1, 0], seed) for seed in SEEDS) < len(SEEDS) - 2
    assert all(on_line([0, 1], seed) for seed in SEEDS)
    # not when the object is itself adjacent to a wall (either may then be the one turned), nor against a planned path
    # from the partner to it
    both = replace(plan, edges=[PlanEdge(walls.ids[2], "b", "spatial", "front", "adjacent"), plan.edges[1]])
    assert order.facing_first(both, partners, walls) == []
    led = replace(plan, edges=[*plan.edges, PlanEdge("t", "b", "spatial", "front", "distant")])
    assert order.facing_first(led, partners, walls) == []
    assert order.facing_first(plan, {}, walls) == []
    # nor when the plan puts the partner in a corner (adjacent to two walls that meet): the corner holds its place
    # along each wall, so it goes first; two walls that do not meet change nothing
    meet = next(w for w in walls.ids[:3] if abs(walls.normal[walls.ids.index(w)] @ walls.normal[3]) < 0.5)
    cornered = replace(plan, edges=[*plan.edges, PlanEdge(meet, "t", "spatial", "front", "adjacent")])
    assert order.facing_first(cornered, partners, walls) == []
    facing = next(w for w in walls.ids[:3] if walls.normal[walls.ids.index(w)] @ walls.normal[3] < -0.99)
    assert order.facing_first(replace(plan, edges=[*plan.edges, PlanEdge(facing, "t", "spatial", "front", "adjacent")]),
                              partners, walls) == [(0, 1)]


class FarEnd:
    """The relation bands, with all but a millionth of their mass beyond x = 5 m."""

    def __init__(self, extract):
        self.bands = RelationPrior(extract)

    def density(self, room, walls, category, anchors, points):
        return self.bands.density(room, walls, category, anchors, points) * np.where(points[:, 0] > 5.0, 1.0, 1e-6)


def test_an_object_whose_draws_all_miss_its_partners_view_is_drawn_again_within_it_at_the_training_distance():
    # learned: the hand-built chairs stand 0.70-0.85 m from the desk they face (centre to centre)
    cfg = default_config()
    apart = lambda q: learn_partner_distances([furnished(s).room_input() for s in range(12)], math.pi / 4, q,
                                              cfg["floor_contact"])[("desk", "chair")]
    assert 0.70 <= apart(0.0) <= apart(0.5) <= apart(1.0) <= 0.85
    # applied: in a long, shallow room a chair planned against the top wall is drawn beyond x = 5 m, where the desk at
    # the bottom wall's left end (facing up, its view reaching x = 3.4 m there) cannot see it, turned or not; the rule
    # draws it again among the cells in the desk's view no nearer than the training pairs, and turns it to the desk
    room, walls, pool, checker, cfg = setup_room(furnished(0), width=8.0, depth=3.0)
    desk = given(room, pool, "desk", "desk", (1.0, 0.3), 0)
    plan = plan_of("c", "chair", [PlanEdge(walls.ids[2], "c", "spatial", "front", "adjacent")])
    far = Combined(FarEnd(cfg["extract"]), FaceAway())
    chair = lambda proposer, seed: placed(instantiate(plan, desk, [0], proposer, Kit(pool, checker), cfg["instantiate"],
                                                      seed), "c")
    faces = lambda box: bool(facing_each_other(np.vstack([desk.boxes.reshape(-1, 7), box]), math.pi / 4)[0, 1])
    assert not any(faces(chair(far, seed)) for seed in SEEDS)
    for seed in SEEDS:
        box = chair(FacingPartner(far, {("desk", "chair"): 1.0}, math.pi / 4, 16, {("desk", "chair"): 2.45}), seed)
        assert faces(box) and box[0] < 3.4 and np.hypot(box[0] - 1.0, box[1] - 0.3) >= 2.45, (seed, box)
    # no cell of its view that far from the desk: the draw stands as it was (no turn makes the desk see it)
    alone = chair(FacingPartner(far, {("desk", "chair"): 1.0}, math.pi / 4, 16, {("desk", "chair"): 50.0}), 0)
    assert alone[0] > 5.0 and not faces(alone)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["cfcn", "prior"])
def test_a_chair_planned_in_front_of_a_desk_faces_it(learned, kind):
    saved, pool_room = learned
    room, walls, pool, checker, cfg = setup_room(pool_room)
    room = given(room, pool, "desk", "desk", (2.0, 0.3), 0)
    proposer = proposer_of(kind, saved, cfg)
    plan = plan_of("c", "chair", [PlanEdge("desk", "c", "spatial", "front", "proximal")])
    for seed in SEEDS:
        out = instantiate(plan, room, [0], proposer, Kit(pool, checker), cfg["instantiate"], seed)
        placed(out, "c")
        assert facing_angles(out.room.boxes)[0, 1] <= math.radians(45), (kind, seed, out.room.boxes[1])


def test_a_symmetric_objects_equivalent_turns_are_one_turn():
    """A rotational-2 keyboard turned half a turn still faces its chair; a chair (left-right) turned so does not;
    a rotational-4 side table turned a quarter stands square; radial objects face everything."""
    r = Room([(0, 0), (4, 0), (4, 4), (0, 4)])
    r.add("chair", "office_chair", (0.5, 0.5, 0.9), (2.0, 1.0), 0).add("kb", "keyboard", (0.45, 0.15, 0.03), (2.0, 1.6), 0)
    boxes = r.room_input().boxes
    assert math.degrees(facing_angles(boxes)[0, 1]) == pytest.approx(180.0)  # literal front: away from the chair
    assert facing_angles(boxes, ["left-right", "rotational-2"])[0, 1] == pytest.approx(0.0, abs=1e-9)
    assert math.degrees(facing_angles(boxes, ["left-right", "left-right"])[0, 1]) == pytest.approx(180.0)
    assert turn_error(math.pi / 2, "rotational-4") == pytest.approx(0.0)
    assert turn_error(math.radians(100), "rotational-4") == pytest.approx(math.radians(10))
    assert turn_error(1.234, "radial") == 0.0 and turn_error(math.pi, "front-back") == pytest.approx(0.0)
    wardrobe = np.array([[2.0, 3.7, 1.0, 0.5, 0.3, 1.0, 0.0]])  # its front against the top wall
    assert not back_to_wall(wardrobe, r.outline, 0.1, math.radians(15))[0]  # its literal back faces into the room
    assert back_to_wall(wardrobe, r.outline, 0.1, math.radians(15), ["rotational-2"])[0]  # its equivalent back does not


def test_a_symmetric_anchors_regions_count_in_every_frame_it_cannot_be_told_apart_from():
    """A sofa behind a rotational-2 coffee table's literal front stands in its front region once the table is turned
    half a turn (the same table from above), so the learned check 'sofa in front of the coffee table' passes; behind a
    left-right sofa-side table it stays behind. A rotational-4 table adds its quarter turns."""
    from pipeline.evaluation import functional
    from pipeline.geometry.function import equivalent_regions

    def living(yaw: float, kind: str):
        r = Room([(0, 0), (5, 0), (5, 5), (0, 5)], room_type="living")
        r.add("sofa", "sofa", (2.0, 0.9, 0.8), (2.5, 0.6), 0).add("ct", "coffee_table", (1.2, 0.6, 0.4), (2.5, 1.8), yaw)
        return r.room_input(), {"m_sofa": "left-right", "m_ct": kind}

    room, sym = living(0.0, "rotational-2")  # the table's literal front (+y) turned away from the sofa
    assert REGIONS[regions(room.boxes)[1, 0]] == "back"
    assert {REGIONS[k] for k in equivalent_regions(room.boxes, ["left-right", "rotational-2"])[:, 1, 0]} == {"back", "front"}
    assert {REGIONS[k] for k in equivalent_regions(room.boxes, ["left-right", "left-right"])[:, 1, 0]} == {"back"}
    assert len(equivalent_regions(room.boxes, ["left-right", "rotational-4"])) == 4
    cfg = {**default_config()["evaluate"]["functional"], "min_share": 0.85}
    train = [living(180.0, "rotational-2")[0] for _ in range(25)]  # its front towards the sofa
    checks = functional.learn_checks(train, cfg, {"m_sofa": "left-right", "m_ct": "rotational-2"})
    assert any(c.get("anchor") == "coffee_table" and c["target"] == "sofa" and c["region"] == "front"
               for c in checks["checks"])
    assert functional.score_room(room, checks, cfg, sym)["fn:sofa@coffee_table"] == 1.0
    room, sym = living(0.0, "none")  # a table with one front, turned away: the check fails
    checks = functional.learn_checks(train, cfg, {"m_sofa": "left-right", "m_ct": "none"})
    assert functional.score_room(room, checks, cfg, sym)["fn:sofa@coffee_table"] == 0.0


@pytest.mark.parametrize("side,distance", [("left", "adjacent"), ("front", "proximal"), ("right", "adjacent")])
def test_every_cell_of_a_band_is_where_extraction_finds_the_planned_edge(side, distance):
    """The relation bands are tied to extraction: a nightstand at any cell of the band of a bed's side (turned square
    either way, slid to the planned gap as the search does) is found by extraction with that exact edge; a cell past
    the band's end along the side is not."""
    from pipeline.placement.anchors import anchors_of
    from pipeline.placement.proposers import Grid, RelationPrior
    from pipeline.placement.search import snap

    cfg = default_config()
    r = Room([(0, 0), (6, 0), (6, 6), (0, 6)]).add("bed", "bed", SIZES["bed"], (3.0, 3.0), 0)
    r.add("n", "nightstand", SIZES["nightstand"], (0.5, 0.5), 0)
    pool = ModelPool(r.objects_df(), {})
    room = with_objects(r.room_input(), [0])
    walls = walls_of(room)
    plan = plan_of("n", "nightstand", [PlanEdge("bed", "n", "spatial", side, distance)])
    inst = pool.pick("nightstand", "none", np.random.default_rng(0))
    anchors = anchors_of("n", plan, room, walls, {}, inst.half[:2])
    grid = Grid(room.outline, 0.1)
    band = RelationPrior(cfg["extract"], slack=0.0).density(room, walls, "nightstand", anchors, grid.points) > 0
    checker = checker_of(r)
    rng = np.random.default_rng(1)
    cells = grid.points[band][rng.permutation(band.sum())[:25]]
    assert len(cells) >= 10
    for xy in cells:
        yaw = float(rng.integers(4)) * math.pi / 2
        box = snap(place(inst, xy[0], xy[1], None, yaw)[0], anchors, room, walls, cfg["extract"], cfg["instantiate"]["snap"])
        got = checker.extract(add_object(room, "n", "nightstand", inst.model_id, box, place(inst, box[0], box[1], None, yaw)[1]))
        found = [(e["direction"], e["distance"]) for e in got.edges if e["source"] == "bed" and e["target"] == "n"
                 and e["edge_type"] == "spatial"]
        assert found == [(side, distance)], (xy, yaw, found)


def _corner_room(pool_room):
    room, walls, pool, checker, cfg = setup_room(pool_room)
    return given(room, pool, "bed", "bed", (2.2, 3.6), 180), walls, pool, checker, cfg


def test_an_unsatisfiable_plan_ends_with_its_cause_and_no_relaxed_object():
    """A nightstand planned flush against both long sides and the foot of a bed: two of its three relations always
    break, which the per-object tolerance never allows (at most half of them); the search fails with the object and
    the check that refused it, and records no relaxed object."""
    from pipeline.placement.proposers import Combined, FaceAway, RelationPrior

    room, walls, pool, checker, cfg = _corner_room(furnished(0))
    plan = plan_of("n", "nightstand", [PlanEdge("bed", "n", "spatial", "left", "adjacent"),
                                       PlanEdge("bed", "n", "spatial", "right", "adjacent"),
                                       PlanEdge("bed", "n", "spatial", "front", "adjacent")])
    ic = {**cfg["instantiate"], "max_backtracks": 10, "backtracks_per_object": 0, "restarts": 0}
    out = instantiate(plan, room, [0], Combined(RelationPrior(cfg["extract"], soft=1e-3), FaceAway()), Kit(pool,
                      checker), ic, 0)
    assert not out.ok and "no place for n (nightstand)" in out.reason and "refused most by" in out.reason
    assert out.relaxed == []


def test_an_object_kept_with_a_broken_relation_is_recorded_with_the_edge_and_why():
    """Three planned wall relations of a nightstand in a corner, one of them to the far wall: after its own failures
    the object is kept with that one edge broken, and the record names it and what extraction found instead."""
    from pipeline.placement.proposers import Combined, FaceAway, RelationPrior

    room, walls, pool, checker, cfg = setup_room(furnished(0))
    plan = plan_of("n", "nightstand", [PlanEdge(walls.ids[k], "n", "spatial", "front", "adjacent") for k in (2, 3, 0)])
    out = instantiate(plan, room, [0], Combined(RelationPrior(cfg["extract"], soft=1e-3), FaceAway()), Kit(pool,
                      checker), {**cfg["instantiate"], "restarts": 0}, 0)
    assert out.ok, out.reason
    (rec,) = out.relaxed
    # the far wall is still seen in front, at a distance: half a violation of one of three relations
    assert rec["id"] == "n" and rec["failures"] >= cfg["instantiate"]["relax"]["start"] and rec["cost"] == pytest.approx(1 / 6, abs=1e-3)
    assert [(b["source"], b["planned"], b["found"]) for b in rec["broken"]] == [(walls.ids[0], "front/adjacent", "front/distant")]
    assert rec["cause"] == "violates"


def test_the_off_axis_share_sees_a_set_turned_off_its_walls_and_not_a_set_turned_with_them():
    """A known-bad set: the hand-built rooms with every object turned 30 degrees share 1.0 of off-axis objects per
    category and sit 1.0 from the training rooms; the same rooms (walls turned by quarter turns with their
    objects) share 0.0. A 3 degree turn stays under the 5 degree threshold."""
    from dataclasses import replace as swap

    from pipeline.evaluation.evaluate import off_axis_gap, off_axis_shares

    rooms = [furnished(s).room_input() for s in range(12)]
    turned = lambda deg: [swap(r, boxes=r.boxes + np.r_[np.zeros(6), np.radians(deg)]) for r in rooms]
    train = off_axis_shares(rooms, None, 5.0)
    assert train["all"] == 0.0 and set(train["categories"]) == set(SIZES)
    bad = off_axis_shares(turned(30), None, 5.0)
    assert bad["all"] == 1.0 and all(v == 1.0 for v in bad["categories"].values())
    assert off_axis_gap(bad, train, 10) == 1.0 and off_axis_gap(train, train, 10) == 0.0
    assert off_axis_shares(turned(3), None, 5.0)["all"] == 0.0
    assert off_axis_gap(bad, train, 25) is None  # no category holds 25 objects in both sets (nightstands: 24)


def test_the_relaxed_share_counts_the_objects_kept_with_a_broken_relation():
    import pandas as pd

    from pipeline.methods.scenes import relaxed, relaxed_share

    rec = '[{"id": "a", "category": "sofa", "cause": "violates"}, {"id": "b", "category": "tv", "cause": "collides"}]'
    scenes = pd.DataFrame({"relaxed_objects": [2, 0, None], "placed_objects": [10, 10, 0], "relaxed": [rec, "[]", None]})
    assert relaxed_share(scenes) == 0.1
    assert relaxed(scenes["relaxed"]) == {"sofa": {"violates": 1}, "tv": {"collides": 1}}
    assert relaxed_share(scenes.assign(relaxed_objects=None)) is None  # a method that records none


def _desk_and_chair(walls) -> ScenePlan:
    """A desk with no planned place of its own, then a chair planned in front of it and against the bottom wall:
    only a desk facing that wall a chair's depth from it leaves the chair a place keeping both."""
    edges = [PlanEdge("d", "c", "spatial", "front", "adjacent"), PlanEdge(walls.ids[0], "c", "spatial", "front", "adjacent")]
    return ScenePlan("s", "r0", "bedroom", ["d", "c"], ["desk", "chair"], ["none", "left-right"], [1, 1], [None, None],
                     ["none", "none"], edges)


def test_forward_checking_refuses_a_place_that_leaves_a_later_object_none():
    """Known answers of the lookahead: a desk facing the bottom wall a chair's depth from it leaves the chair cells in
    both of its bands; the same desk in the middle of the room leaves none (refused, nothing earlier to blame); at a
    grown tolerance nothing is refused (``at_zero_tolerance``, the default) unless ``always``; with ``none``, never."""
    from pipeline.placement.proposers import Combined, FaceAway, RelationPrior
    from pipeline.placement.search import Search

    room, walls, pool, checker, cfg = setup_room(furnished(0))
    plan, ic = _desk_and_chair(walls), cfg["instantiate"]
    proposer = Combined(RelationPrior(cfg["extract"], soft=1e-3), FaceAway())
    search = Search(plan, room, [0, 1], proposer, Kit(pool, checker), ic, np.random.default_rng(0))
    near = given(room, pool, "desk", "d", (2.2, 0.5 + 0.3 + 0.02), 180)
    middle = given(room, pool, "desk", "d", (2.2, 2.3), 180)
    assert search.forecloses(0, near, 0.0) is None
    assert search.forecloses(0, middle, 0.0) == set()
    assert search.forecloses(0, middle, 0.1) is None
    mode = lambda m: Search(plan, room, [0, 1], proposer, Kit(pool, checker), {**ic, "lookahead": m},
                            np.random.default_rng(0))
    assert mode("none").forecloses(0, middle, 0.0) is None
    assert mode("always").forecloses(0, middle, 0.1) == set() and mode("always").forecloses(0, near, 0.1) is None


def test_with_forward_checking_the_chair_keeps_both_relations():
    """The desk-and-chair plan searched from scratch over 20 seeds: without the lookahead the desk stands where it
    falls and 12 of them keep the chair with a broken relation; with it, at most 3 (a desk that spends its samples
    five times is let go, as its tolerance grows), and the backtracks fall."""
    from pipeline.placement.proposers import Combined, FaceAway, RelationPrior

    room, walls, pool, checker, cfg = setup_room(furnished(0))
    plan, proposer = _desk_and_chair(walls), Combined(RelationPrior(cfg["extract"], soft=1e-3), FaceAway())
    run = lambda look: [instantiate(plan, room, [0, 1], proposer, Kit(pool, checker),
                                    {**cfg["instantiate"], "lookahead": look}, seed) for seed in range(20)]
    with_look, without = run("at_zero_tolerance"), run("none")
    assert all(o.ok for o in with_look + without)
    relaxed = lambda outs: sum(bool(o.relaxed) for o in outs)
    assert relaxed(with_look) <= 3 and relaxed(without) >= 8, (relaxed(with_look), relaxed(without))
    assert sum(o.backtracks for o in with_look) < sum(o.backtracks for o in without)
    assert any("forecloses" in o.failures for o in with_look) and not any("forecloses" in o.failures for o in without)
