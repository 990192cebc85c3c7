"""The string method's own instantiation (issue 31, item 4b): relative poses and their mean-shift clusters, the edge
tagger, and breadth-first assembly with repair, on hand-built bedrooms whose clusters are known (nightstands on
either side of a bed centred on a wall), with the real placement checks (Embree extraction) judging the result."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, strategies as st

from pipeline.geometry.frames import Frame
from pipeline.geometry.raycast import intersector_class
from pipeline.graphs.data import EDGE_CLASSES, Graph, Vocab
from pipeline.learning.epochs import Session
from pipeline.methods.strings import assemble, poses, tagger
from pipeline.methods.strings.serialize import tokens
from pipeline.methods.strings.tagfit import tagger_room, token_vocab
from pipeline.placement.checks import Checker
from pipeline.placement.layout import walls_of, with_objects
from pipeline.placement.plan import PlanEdge, ScenePlan
from pipeline.placement.retrieval import ModelPool
from pipeline.placement.search import Kit

from conftest import Room, default_config

E = EDGE_CLASSES.index
VOCAB = Vocab(("bed", "nightstand", "table_lamp"))
BED, NS, LAMP = (2.0, 1.6, 0.5), (0.5, 0.4, 0.55), (0.2, 0.2, 0.4)  # full sizes (w, d, h); the bed's front is +y
OUTLINE = ((0, 0), (4, 0), (4, 3.5), (0, 3.5))


def bedroom(room_id: str, bed_x: float, lamps: bool = True) -> tuple[Room, Graph]:
    """A 4 x 3.5 m bedroom: the bed's head against the bottom wall (wall_0) at ``bed_x``, a nightstand flush on each
    side against the same wall, a lamp on each nightstand; and its final graph built by hand."""
    r = Room(list(OUTLINE), room_id=room_id)
    r.add("bed", "bed", BED, (bed_x, 0.8))
    side = BED[0] / 2 + NS[0] / 2
    r.add("ns_l", "nightstand", NS, (bed_x - side, 0.2)).add("ns_r", "nightstand", NS, (bed_x + side, 0.2))
    nodes = ["wall_0", "wall_1", "wall_2", "wall_3", "bed", "ns_l", "ns_r"]
    edges = [(0, 4, E("front/adjacent")), (0, 5, E("front/adjacent")), (0, 6, E("front/adjacent")),
             (4, 5, E("left/adjacent")), (4, 6, E("right/adjacent")),
             *((k, (k + 1) % 4, E("wall_adjacent/left")) for k in range(4))]
    if lamps:
        r.add("lamp_l", "table_lamp", LAMP, (bed_x - side, 0.2), z=NS[2], parent="ns_l")
        r.add("lamp_r", "table_lamp", LAMP, (bed_x + side, 0.2), z=NS[2], parent="ns_r")
        nodes += ["lamp_l", "lamp_r"]
        edges += [(5, 7, E("support")), (6, 8, E("support"))]
    cls = [0, 0, 0, 0, *(VOCAB.node_classes.index(n.split("_")[0].replace("ns", "nightstand").replace("lamp", "table_lamp"))
                         for n in nodes[4:])]
    n = len(nodes)
    g = Graph(room_id, nodes, np.array(cls), np.zeros(n, int), np.zeros(n, int), np.zeros(n), 4,
              np.array(edges, np.int64), np.zeros(len(edges)))
    return r, g


def posed(r: Room, g: Graph) -> list[poses.EdgePose]:
    room = r.room_input()
    return poses.edge_poses(g, VOCAB, room, walls_of(room))


def training_set(n: int = 8):
    return [bedroom(f"r{k}", 1.5 + 0.15 * k) for k in range(n)]


def test_an_edges_relative_pose_is_its_target_in_the_anchors_frame():
    r, g = bedroom("r0", 2.0)
    got = {(g.node_ids[p.source], g.node_ids[p.target]): p for p in posed(r, g)}
    side = BED[0] / 2 + NS[0] / 2
    # the bed faces +y: its left side is -x in its frame, where ns_l stands
    np.testing.assert_allclose(got[("bed", "ns_l")].pose, [-side, -0.6, 0.0], atol=1e-9)
    np.testing.assert_allclose(got[("bed", "ns_r")].pose, [side, -0.6, 0.0], atol=1e-9)
    # against wall_0 (4 m long): the along coordinate is a share of the half length, the depth is metres
    wall = got[("wall_0", "ns_r")].pose
    assert wall[1] == pytest.approx(0.2) and abs(wall[0]) == pytest.approx(side / 2.0)
    assert got[("ns_l", "lamp_l")].pose == pytest.approx([0, 0, 0])
    assert {p.triple for p in got.values()} >= {("wall", "nightstand", E("front/adjacent")), ("nightstand", "table_lamp", E("support"))}


@given(st.floats(-5, 5), st.floats(-5, 5), st.floats(-np.pi, np.pi), st.floats(0.5, 3), st.floats(-3, 3),
       st.floats(-3, 3), st.floats(-np.pi, np.pi))
def test_from_relative_inverts_relative_pose(ox, oy, yaw, scale, x, y, turn):
    frame = Frame((ox, oy), yaw)
    xy, world_yaw = poses.from_relative(frame, scale, np.array([x, y, turn]))
    back = poses.relative_pose(frame, scale, np.array([*xy[0], 0.5, 0.3, 0.2, 0.1, world_yaw[0]]))
    np.testing.assert_allclose(back[:2], [x, y], atol=1e-9)
    assert np.cos(back[2] - turn) == pytest.approx(1.0)


def test_mean_shift_finds_the_two_nightstand_places_along_a_wall_and_one_beside_the_bed():
    """The wall -> nightstand poses of eight rooms (the bed moved along the wall) fall in two clusters, left and
    right of centre; the bed -> nightstand ones in one per side (one edge class each); centres are the hand values."""
    found = poses.fit_clusters([p for r, g in training_set() for p in posed(r, g)], default_config()["strings"]["tagger"]["bandwidth"])
    side = BED[0] / 2 + NS[0] / 2
    wall = found.centres[("wall", "nightstand", E("front/adjacent"))]
    assert len(wall) == 2 and found.counts[("wall", "nightstand", E("front/adjacent"))].tolist() == [8, 8]
    xs = np.array([1.5 + 0.15 * k for k in range(8)])
    expected = sorted([((xs - side) - 2).mean() / 2, ((xs + side) - 2).mean() / 2])
    np.testing.assert_allclose(sorted(wall[:, 0]), expected, atol=0.05 / 2)
    np.testing.assert_allclose(wall[:, 1], [0.2, 0.2], atol=1e-9)
    right = found.centres[("bed", "nightstand", E("right/adjacent"))]
    assert len(right) == 1 and right[0] == pytest.approx([side, -0.6, 0.0])
    back = poses.Clusters.from_record(found.to_record())
    assert back.size == found.size and back.offset == found.offset
    p = posed(*bedroom("x", 2.6))[1]
    assert back.label(p.triple, p.pose) == found.label(p.triple, p.pose)


def test_each_tagged_edge_points_at_the_bond_token_that_wrote_it():
    r, g = bedroom("r0", 2.0)
    clusters = poses.fit_clusters(posed(r, g), default_config()["strings"]["tagger"]["bandwidth"])
    room = tagger_room(g, VOCAB, posed(r, g), clusters)
    rng = np.random.default_rng(0)
    for _ in range(20):
        ex = tagger.example(room, clusters, rng)
        toks = tokens(ex.text)
        assert sorted(ex.edges) == sorted(room.labels)  # every posed edge once
        for (_s, _t, c), b, code in zip(ex.edges, ex.bond, ex.code):
            assert toks[b].startswith("{") and EDGE_CLASSES[c] in toks[b] and code // 2 == c


def test_the_tagger_learns_which_side_of_the_wall_a_nightstand_takes(tmp_path):
    """The wall -> nightstand edges have two clusters; which one is told only by the bed -> nightstand edge of the
    same nightstand (left or right), elsewhere in the string. A trained tagger tags unseen rooms' edges right, voting
    over strings in random orders; the majority cluster alone would get half of them."""
    cfg = default_config()["strings"]["tagger"]
    train = training_set(10)
    clusters = poses.fit_clusters([p for r, g in train for p in posed(r, g)], cfg["bandwidth"])
    rooms = [tagger_room(g, VOCAB, posed(r, g), clusters) for r, g in train]
    held = [tagger_room(g, VOCAB, posed(r, g), clusters) for r, g in (bedroom(f"h{k}", 1.6 + 0.2 * k) for k in range(4))]
    tokens_ = token_vocab(rooms, rooms + held, 0, 4)
    preset = {**cfg["presets"]["tiny"], "max_epochs": 40, "patience": 40, "strings_per_room": 4, "lr": 0.02}
    model, history, _ = tagger.train(rooms, rooms[:2], clusters, tokens_, preset, Session(0, tmp_path / "progress.pt", "h"))
    got = tagger.accuracy(model, held, clusters, tokens_, 3, 0)
    assert got["edges_with_choice"] == 8 and got["majority_with_choice"] == 0.5
    assert got["accuracy_with_choice"] == 1.0 and got["accuracy"] == 1.0


def _checker_pool():
    r = Room(list(OUTLINE))
    for k, (c, size) in enumerate((("bed", BED), ("nightstand", NS))):
        r.add(f"{c}_{k}", c, size, (1.0 + k, 1.5))
    r.add("lamp", "table_lamp", LAMP, (3.0, 1.5), z=NS[2], parent="x")
    cfg = default_config()
    ext = {"floor_contact": cfg["floor_contact"], **cfg["extract"]}
    checker = Checker(r.models, set(r.models), {}, ext, intersector_class("embree"), cfg["instantiate"]["checks"])
    return ModelPool(r.objects_df(), {}), checker, cfg


def plan_of(g: Graph) -> ScenePlan:
    ids, names = g.node_ids, VOCAB.node_classes
    objs = list(range(g.n_arch, len(ids)))
    parent = {t: ids[s] for s, t, c in g.edges.tolist() if c == E("support")}
    edges = []
    for s, t, c in g.edges.tolist():
        name = EDGE_CLASSES[c]
        if c == E("support"):
            edges.append(PlanEdge(ids[s], ids[t], "support", None, None))
        elif "/" in name and not name.startswith("wall_"):
            edges.append(PlanEdge(ids[s], ids[t], "spatial", *name.split("/")))
    return ScenePlan("s0", g.room_id, "bedroom", [ids[k] for k in objs], [names[g.node_class[k]] for k in objs],
                     ["none"] * len(objs), [2 if k in parent else 1 for k in objs], [parent.get(k) for k in objs],
                     ["none"] * len(objs), edges)


@pytest.mark.parametrize("seed", range(5))
def test_assembly_puts_each_object_at_its_tagged_cluster_and_keeps_the_planned_graph(seed):
    """A new bedroom's graph assembled from the clusters of the training rooms (tags ranked by truth): the bed at
    the wall's centre cluster, the nightstands flush on either side and against the wall, the lamps on top; the
    project's extraction finds every planned edge, and nothing collides."""
    cfg = default_config()
    train = training_set()
    clusters = poses.fit_clusters([p for r, g in train for p in posed(r, g)], cfg["strings"]["tagger"]["bandwidth"])
    r, g = bedroom("new", 2.0)
    truth = {(g.node_ids[p.source], g.node_ids[p.target], p.edge_class): clusters.label(p.triple, p.pose) for p in posed(r, g)}
    tags = {}
    for k, y in truth.items():
        tr = next(t for t in clusters.offset if clusters.offset[t] <= y < clusters.offset[t] + len(clusters.centres[t]))
        order = [y - clusters.offset[tr]] + [j for j in range(len(clusters.centres[tr])) if j != y - clusters.offset[tr]]
        tags[k] = [(clusters.centres[tr][j], clusters.spread[tr][j]) for j in order]
    pool, checker, cfg = _checker_pool()
    plan = plan_of(g)
    start = with_objects(r.room_input(), [])
    outcome, walls, unanchored = assemble.assemble(plan, start, tags, Kit(pool, checker), cfg["strings"]["tagger"]["placement"],
                                                   cfg["instantiate"], seed)
    room = outcome.room
    assert outcome.dropped == [] and unanchored == 0 and sorted(room.object_ids) == sorted(plan.ids)
    at = {o: room.boxes[k] for k, o in enumerate(room.object_ids)}
    bed_x = at["bed"][0]
    side = BED[0] / 2 + NS[0] / 2
    assert at["ns_l"][0] == pytest.approx(bed_x - side, abs=0.05) and at["ns_r"][0] == pytest.approx(bed_x + side, abs=0.05)
    assert at["ns_l"][1] == pytest.approx(0.2, abs=0.05) and at["lamp_r"][:2] == pytest.approx(at["ns_r"][:2], abs=0.05)
    assert all(c == 0.0 for c in outcome.accepted.values())  # every planned edge held when placed


def test_breadth_first_order_starts_at_the_walls_and_puts_supports_first():
    _, g = bedroom("r0", 2.0)
    plan = plan_of(g)
    order = [plan.ids[k] for k in assemble.bfs_order(plan, {"wall_0", "wall_1", "wall_2", "wall_3"})]
    assert order[:3] == ["bed", "ns_l", "ns_r"] and order.index("lamp_l") > order.index("ns_l")
    # an object no edge reaches is still placed (after the reachable ones)
    lonely = ScenePlan("s", "r", "bedroom", [*plan.ids, "x"], [*plan.categories, "bed"], [*plan.symmetry, "none"],
                       [*plan.tier, 1], [*plan.parent, None], [*plan.role, "none"], plan.edges)
    assert [lonely.ids[k] for k in assemble.bfs_order(lonely, {"wall_0"})][-1] == "x"
    # support parents in a cycle, or naming no object (a generated graph can hold both), still end the order
    odd = ScenePlan("s", "r", "bedroom", ["a", "b", "c"], ["bed"] * 3, ["none"] * 3, [1, 1, 1], ["b", "a", "ghost"],
                    ["none"] * 3, [])
    assert sorted(assemble.bfs_order(odd, {"wall_0"})) == [0, 1, 2]


def test_an_object_no_try_can_place_is_left_out_with_what_it_supports():
    """A nightstand whose only cluster puts it inside the bed: every try collides or breaks its relations, so it is
    dropped, its lamp with it (support_dropped), and the scene is partial with both named."""
    cfg = default_config()
    r, g = bedroom("new", 2.0)
    inside_bed = (np.array([0.0, 0.0, 0.0]), np.array([0.0, 0.0]))
    tags = {("wall_0", "bed", E("front/adjacent")): [(np.array([0.0, 0.8, 0.0]), np.zeros(2))],
            ("bed", "ns_l", E("left/adjacent")): [inside_bed], ("wall_0", "ns_l", E("front/adjacent")): [inside_bed]}
    pool, checker, cfg = _checker_pool()
    plan = plan_of(g)
    pc = {**cfg["strings"]["tagger"]["placement"], "tries": 3, "min_jitter": 0.0}
    outcome, _, _ = assemble.assemble(plan, with_objects(r.room_input(), []), tags, Kit(pool, checker), pc, cfg["instantiate"], 0)
    causes = {d["id"]: d["cause"] for d in outcome.drops}
    assert causes["ns_l"] == "no_place" and causes["lamp_l"] == "support_dropped"
    assert "bed" in outcome.room.object_ids and "dropped" in outcome.reason and outcome.status == "partial"

