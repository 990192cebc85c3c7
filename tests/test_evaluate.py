"""Evaluation metrics on hand-built cases with known answers, on real 3D-FRONT rooms, and the real-vs-synthetic
classifier on trivially separable and on identical inputs. Real Embree, real meshes, no mocks."""
from __future__ import annotations

import os

import numpy as np
import pytest

from pipeline.evaluation import distributions, physical, render
from pipeline.geometry.collision import CollisionTest
from pipeline.geometry.raycast import intersector_class
from pipeline.room import walkability
from pipeline.stage import Files

from conftest import Room, default_config, l_sofa_mesh

SQUARE = [(0, 0), (4, 0), (4, 4), (0, 4)]


def _collision_cfg(measure="mesh"):
    ev = default_config()["evaluate"]["collision"]
    return CollisionTest.of({**ev["penetration"], "measure": measure}, ev["max_penetration"], intersector_class("embree"))


def _colliding(room: Room, measure="mesh"):
    r = room.room_input()
    meshes = [room.models[m] for m in r.model_ids]
    return physical.colliding(r, [o["source_parent_id"] for o in room.objects], meshes, _collision_cfg(measure))


@pytest.mark.parametrize("measure", ["mesh", "box"])
def test_two_overlapping_boxes_collide_and_flush_ones_do_not(measure):
    room = (Room(SQUARE).add("a", "dresser", (1.0, 0.5, 0.8), (1.0, 1.0)).add("b", "dresser", (1.0, 0.5, 0.8), (1.5, 1.2))
            .add("c", "dresser", (1.0, 0.5, 0.8), (3.0, 3.0)).add("d", "dresser", (1.0, 0.5, 0.8), (3.0, 3.5)))
    assert _colliding(room, measure).tolist() == [True, True, False, False]  # c and d touch along a face


def test_an_object_on_its_support_does_not_collide_but_one_sunk_into_another_does():
    room = (Room(SQUARE).add("stand", "nightstand", (0.5, 0.5, 0.6), (1, 1))
            .add("lamp", "lamp", (0.2, 0.2, 0.4), (1, 1), z=0.55, parent="stand")  # sunk 5 cm into its support
            .add("box", "box", (0.2, 0.2, 0.4), (1.2, 1.2), z=0.5))  # sunk 10 cm, not supported by it
    assert _colliding(room).tolist() == [True, False, True]


def test_meshes_not_boxes_decide_collisions():
    """A table under an L-sofa's box but clear of its mesh (the 3D-FRONT case) does not collide on meshes."""
    room = Room(SQUARE).add("sofa", "sofa", (2.4, 2.4, 0.8), (2.0, 2.0), mesh=l_sofa_mesh())
    room.add("table", "coffee_table", (0.6, 0.6, 0.4), (1.4, 2.6))
    assert _colliding(room, "box").tolist() == [True, True]
    assert _colliding(room, "mesh").tolist() == [False, False]


def test_a_box_half_outside_the_floor_is_out_of_bounds_and_a_flush_or_turned_one_is_not():
    l_room = np.array([(0, 0), (4, 0), (4, 2), (2, 2), (2, 4), (0, 4)], float)
    box = np.array([[4.0, 1.0, 0.4, 0.5, 0.3, 0.4, 0.0],  # half outside the right wall
                    [3.5, 1.0, 0.4, 0.5, 0.3, 0.4, 0.0],  # flush against it
                    [1.0, 3.0, 0.4, 0.5, 0.3, 0.4, 0.7],  # turned, inside
                    [3.0, 3.0, 0.4, 0.5, 0.3, 0.4, 0.0],  # in the L's missing corner
                    [1.75, 1.75, 0.4, 0.3, 0.3, 0.4, 0.0]])  # poking 5 cm past the inner corner: within the erosion
    assert physical.out_of_bounds(l_room, box, 0.1, 1e-5).tolist() == [True, False, False, True, False]


def test_identical_category_sets_give_zero_kl_and_disjoint_ones_do_not():
    real = ["bed", "nightstand", "nightstand", "lamp"]
    assert distributions.category_kl(real, list(reversed(real))) == 0.0
    assert distributions.category_kl(real, ["bed", "bed", "bed", "lamp"]) > 0.5
    assert distributions.category_kl(real, ["sofa"]) > 10
    assert distributions.count_distance([3, 4, 4], [4, 3, 4]) == 0.0
    assert distributions.count_distance([3, 3], [5, 5]) == 1.0


def test_a_sampling_floor_of_identical_rooms_is_zero_and_of_mixed_rooms_positive():
    kl = lambda a, b: distributions.category_kl(distributions.flatten(a), distributions.flatten(b))
    same = [["bed", "lamp"]] * 20
    assert distributions.sampling_floor(same, (5, 10), kl, 5, 0)["mean"] == 0.0
    mixed = [["bed", "lamp"]] * 10 + [["bed", "desk", "chair"]] * 10
    floor = distributions.sampling_floor(mixed, (8, 8), kl, 20, 0)
    assert floor["mean"] > 0 and floor["sizes"] == [8, 8]
    assert distributions.sampling_floor(mixed, (30, 30), kl, 3, 0)["sizes"] == [10, 10]  # shrunk to the pool


def _walk(room: Room):
    return walkability.walkability(room.room_input(), walkability.Walk.of(default_config()["evaluate"]["walk"]))


def test_a_wardrobe_in_front_of_the_door_makes_the_room_unwalkable():
    room = Room(SQUARE).door("door_0", (1.5, 0.0), (2.4, 0.0), "wall_0").add("bed", "bed", (1.6, 2.0, 0.5), (2.0, 3.0), 180)
    free = _walk(room)
    assert free["walkable_share"] > 0.99 and free["reachable"] == 1.0
    room.add("wardrobe", "wardrobe", (1.6, 0.6, 2.0), (2.0, 0.3))
    blocked = _walk(room)
    assert blocked["walkable_share"] < 0.05 and not blocked["all_reachable"]


def test_a_wall_of_furniture_splits_an_l_shaped_room_and_hanging_lamps_do_not_block():
    l_room = [(0, 0), (4, 0), (4, 2), (2, 2), (2, 4), (0, 4)]
    room = Room(l_room).door("door_0", (0.5, 0.0), (1.4, 0.0), "wall_0")
    room.add("pendant", "lamp", (0.6, 0.6, 0.4), (1.0, 1.0), z=2.0)
    assert _walk(room)["walkable_share"] > 0.99
    room.add("shelf", "bookshelf", (2.0, 0.4, 1.8), (1.0, 2.3))  # closes the L's upper arm off
    share = _walk(room)["walkable_share"]
    assert 0.55 < share < 0.8  # the lower arm (about 2/3 of the free floor) stays connected


def test_a_chair_facing_the_wall_has_an_unreachable_front():
    room = Room(SQUARE).door("door_0", (1.5, 0.0), (2.4, 0.0), "wall_0")
    room.add("chair", "chair", (0.5, 0.5, 0.9), (2.0, 3.74))  # front (+y) flush against the far wall
    assert _walk(room)["reachable"] == 0.0
    room.objects[0]["yaw"] = np.pi
    assert _walk(room)["reachable"] == 1.0


def test_similarity_is_one_for_a_turned_copy_and_zero_for_disjoint_layouts():
    room = Room(SQUARE).add("bed", "bed", (1.6, 2.0, 0.5), (2.0, 2.9)).add("desk", "desk", (1.2, 0.6, 0.8), (0.8, 0.4))
    index = {"bed": 0, "desk": 1}
    a = render.label_map(room.room_input(), index, 48, 0.1)
    assert (a == 0).sum() == 16 * 20 and (a == 1).sum() == 12 * 6  # exact pixels of both boxes
    assert render.similarity(a, np.stack([a, np.rot90(a), a[::-1]])).tolist() == [1.0, 1.0, 1.0]
    empty = np.full_like(a, render.EMPTY)
    other = np.where(a == render.EMPTY, 2, render.EMPTY).astype(np.int16)  # a third category elsewhere
    assert render.similarity(a, np.stack([empty, other])).tolist() == [0.0, 0.0]


def test_renders_use_one_pinned_palette_and_white_background():
    colors = render.palette(["bed", "desk", "lamp"])
    assert colors.shape == (3, 3) and len({tuple(c) for c in colors}) == 3
    rgb = render.classifier_rgb(np.array([[-1, 0], [-2, 5]], np.int16), colors)
    assert rgb[0, 0].tolist() == [1.0, 1.0, 1.0] and np.allclose(rgb[0, 1], colors[0])
    assert np.allclose(rgb[1, 0], 0.85) and np.allclose(rgb[1, 1], colors[2] * 0.5)  # floor; the lamp's front


def test_the_classifier_render_shows_the_floor_and_which_way_an_object_faces():
    """A desk facing +y in a 4 m room: the floor is drawn, the desk's front quarter is its darker label, on the
    +y side (up in the image); turned half round, the dark strip moves to the other side."""
    def render_of(yaw):
        room = Room(SQUARE).add("desk", "desk", (1.2, 0.8, 0.75), (2.0, 2.0), yaw).room_input()
        return render.classifier_map(room, {"desk": 0}, 64, render.fitted_mpp(room, 64, 0.05), 0.25)

    up, down = render_of(0.0), render_of(180.0)
    assert (up == render.FLOOR).sum() > 0.8 * 60 * 60 and (up == render.EMPTY).sum() > 0  # fitted, a margin around
    rows = np.nonzero(up == 1)[0]  # the front strip's label is the category's plus the category count
    assert len(rows) and rows.max() < np.nonzero(up == 0)[0].min() + 1  # above the body: image rows run to -y
    assert np.nonzero(down == 1)[0].min() > np.nonzero(down == 0)[0].max() - 1


def test_metrics_on_real_3d_front_rooms_are_finite_and_agree_with_the_filter(tmp_path):
    """Real 3D-FUTURE meshes: every metric runs on the mesh sample's rooms. Collisions on meshes are never more
    than on boxes (an L-sofa's box covers its coffee table); every share is in [0, 1]."""
    from pipeline import tables
    from pipeline.room import room_inputs

    from conftest import shared_data
    from test_sources import ingest_outputs, run_ingest

    sample = shared_data("3d-front-meshes")
    t = run_ingest("front3d", {"houses": str(sample / "houses"), "future": str(sample / "3d-future"),
                               "cache_dir": str(tmp_path / "cache")}, tmp_path)
    outs = ingest_outputs(tmp_path / "ingest")
    meshes, box_models = tables.read_meshes(outs["models"], t["objects"].model_id.dropna())
    cfg = default_config()["evaluate"]
    rooms = list(room_inputs(t["rooms"], t["architecture"], t["objects"]))
    assert len(rooms) >= 8
    parents = t["objects"].set_index("object_id")["source_parent_id"]
    on_mesh = on_box = 0
    for r in rooms:
        mesh = [None if m in box_models else meshes.get(m) for m in r.model_ids]
        par = [parents.get(o) for o in r.object_ids]
        on_mesh += physical.colliding(r, par, mesh, _collision_cfg("mesh")).sum()
        on_box += physical.colliding(r, par, mesh, _collision_cfg("box")).sum()
        oob = physical.out_of_bounds(r.outline, r.boxes, cfg["out_of_bounds"]["erode"], cfg["out_of_bounds"]["tolerance"])
        walk = walkability.walkability(r, walkability.Walk.of(cfg["walk"]))
        assert oob.dtype == bool and len(oob) == len(r.object_ids)
        assert 0.0 <= walk["walkable_share"] <= 1.0 and 0.0 <= walk["reachable"] <= 1.0
    assert on_mesh < on_box


def _squares(n: int, colour: int, rng: np.random.Generator) -> np.ndarray:
    """``(n, 16, 16, 3)`` white images with one 5 px square of a primary colour at a random place."""
    out = np.ones((n, 16, 16, 3), np.float32)
    for img, (r, c) in zip(out, rng.integers(0, 11, (n, 2))):
        img[r:r + 5, c:c + 5] = 0.0
        img[r:r + 5, c:c + 5, colour] = 1.0
    return out


@pytest.mark.parametrize("separable", [True, False])
def test_the_classifier_separates_separable_renders_and_not_identical_ones(separable):
    from pipeline.evaluation.sca import sca

    rng = np.random.default_rng(0)
    cfg = {**default_config()["evaluate"]["sca"], "steps": 150, "width": 8, "device": "cpu"}
    real_train, real_test = _squares(60, 0, rng), _squares(60, 0, rng)
    generated = _squares(120, 2 if separable else 0, rng)
    out = sca(real_train, real_test, generated, np.arange(120) // 2, cfg, seed=0)  # pairs share a fold
    assert out["train"] == 120 and out["test"] == 240  # two folds: 60 real and 60 generated test renders each
    assert out["low"] <= out["accuracy"] <= out["high"]
    if separable:
        assert out["accuracy"] >= 95.0
    else:
        assert 50.0 <= out["accuracy"] <= 62.0 and out["low"] <= 55.0  # folded: 50 is chance

def test_a_patient_classifier_stops_where_held_out_renders_stop_telling_and_trains_on_where_they_do():
    """Early stopping (``patience``): on renders like the real ones the held-out loss stops falling and training ends
    long before its steps, still at chance; on separable ones it trains on and still detects them; without patience
    every step is taken."""
    import torch

    from pipeline.evaluation.sca import _fit, classifier, sca

    rng = np.random.default_rng(0)
    cfg = {**default_config()["evaluate"]["sca"], "steps": 400, "width": 8, "device": "cpu", "patience": 2,
           "check_every": 25}
    t = lambda a: torch.as_tensor(np.ascontiguousarray(a.transpose(0, 3, 1, 2)))
    real, like, red = t(_squares(60, 0, rng)), t(_squares(60, 0, rng)), t(_squares(60, 2, rng))
    steps = {}
    for name, other in (("like", like), ("red", red)):
        torch.manual_seed(0)
        steps[name] = _fit(classifier(8, 2), real[12:], other[12:], cfg, torch.Generator().manual_seed(0),
                           (real[:12], other[:12]))
    assert steps["like"] <= 200 and steps["red"] > 2 * steps["like"]
    assert _fit(classifier(8, 2), real, like, {**cfg, "steps": 40}, torch.Generator().manual_seed(0), None) == 40
    real_train, real_test = _squares(60, 0, rng), _squares(60, 0, rng)
    separable = sca(real_train, real_test, _squares(120, 2, rng), np.arange(120) // 2, cfg, seed=0)
    alike = sca(real_train, real_test, _squares(120, 0, rng), np.arange(120) // 2, cfg, seed=0)
    assert separable["accuracy"] >= 95.0 and 50.0 <= alike["accuracy"] <= 62.0


def test_one_shared_classifier_scores_each_set_on_its_own_head():
    """The shared mode (one classifier per fold, a head per set): a separable set, a set like the real renders and a
    set made from the held-out renders themselves, trained together; each keeps its own score, halves and test
    renders, the separable one detected, the other two at chance."""
    from pipeline.evaluation.sca import sca_shared

    rng = np.random.default_rng(0)
    cfg = {**default_config()["evaluate"]["sca"], "steps": 200, "width": 8, "device": "cpu", "shared_batch_size": 48}
    real_train, real_test = _squares(60, 0, rng), _squares(40, 0, rng)
    copies = np.repeat(real_test, 2, axis=0)  # two copies of each held-out render, grouped by it
    sets = {"red": (_squares(60, 2, rng), np.arange(60), None), "like": (_squares(60, 0, rng), np.arange(60), None),
            "copies": (copies, np.repeat(np.arange(40), 2), np.arange(40)), "one_room": (real_test[:1], np.zeros(1), None)}
    out = sca_shared(real_train, real_test, sets, cfg, seed=0)
    assert out["red"]["accuracy"] >= 95.0 and out["red"]["test"] == 40 * 2 + 60
    assert 50.0 <= out["like"]["accuracy"] <= 62.0 and out["like"]["low"] <= 55.0
    assert out["copies"]["test"] == 40 + 80  # each fold tests only the real renders of its own test half
    assert 50.0 <= out["copies"]["accuracy"] <= 65.0
    assert np.isnan(out["one_room"]["accuracy"])  # one group: no two halves


def test_generator_rules_read_an_extracted_room():
    """A bed against a wall between two nightstands, a lamp on one: the procedural rules hold on its extracted graph;
    the bed pulled off the wall breaks 'against_wall'."""
    from pipeline.corpus.procedural_rules import satisfaction
    from pipeline.evaluation.scores import rule_view

    def bedroom(bed_y):
        room = Room(SQUARE).add("bed", "bed", (1.6, 2.0, 0.5), (2.0, bed_y), 180)
        room.add("ns1", "nightstand", (0.45, 0.4, 0.55), (0.975, 3.8), 180)
        room.add("ns2", "nightstand", (0.45, 0.4, 0.55), (3.025, 3.8), 180)
        room.add("lamp", "table_lamp", (0.2, 0.2, 0.4), (0.975, 3.8), z=0.55, parent="ns1")
        return satisfaction([rule_view(room.extract())])

    near, far = bedroom(3.0), bedroom(2.2)
    assert near["against_wall"]["share"] == 1.0 and near["small_things_on_surfaces"]["share"] == 1.0
    assert far["against_wall"]["share"] == 0.0


def test_run_time_gathers_benchmarks_per_rule_and_the_wall_clock_span(tmp_path):
    from pipeline.stages import runtime

    header = "s\th:m:s\tmax_rss\tmax_vms\n"
    for rule, job, seconds, rss, end in [("train", "bedroom", 10.0, "300.5", 1000), ("ingest", "0", 5.0, "120", 1020),
                                         ("ingest", "1", 3.0, "NA", 1003), ("generate", "bedroom-planit", 0.5, "9", 1004),
                                         ("generate", "office-planit", 0.5, "9", 1005)]:
        (tmp_path / rule).mkdir(exist_ok=True)
        tsv = tmp_path / rule / f"{job}.tsv"
        tsv.write_text(header + f"{seconds}\t0:00:00\t{rss}\t1\n")
        os.utime(tsv, (end, end))
    budget = {"wall_seconds": 20, "job_seconds": 100, "rules": {"ingest": 10, "generate": 1}, "per_method": {"generate": 0.3}}
    table = runtime.run({"runtime": budget}, Files(corpus=[], learned=[]),
                        Files(table=tmp_path / "out" / "runtime.csv", table_html=tmp_path / "out" / "runtime.html"),
                        benchmarks=str(tmp_path))
    rows = table.set_index("rule")
    assert rows.loc[runtime.WALL, "job_seconds"] == 30.0  # first start 990 (train), last end 1020
    assert rows.loc[runtime.TOTAL, "job_seconds"] == 19.0 and rows.loc[runtime.TOTAL, "jobs"] == 5
    assert rows.loc["ingest"].tolist()[:3] == [2, 8.0, 120.0]
    assert table.rule.tolist()[2:] == ["train", "ingest", "generate", "generate/planit"]
    assert rows.loc["train", "share"] == pytest.approx(10 / 19, abs=1e-3)
    # each row beside its budget: the wall clock passed its 20 s, ingest kept its 10 s, train has none
    assert rows.loc[runtime.WALL, "over_budget"] and not rows.loc["ingest", "over_budget"]
    assert np.isnan(rows.loc["train", "budget_seconds"]) and not rows.loc["train", "over_budget"]
    # per method: both room types' jobs, the slowest (0.5 s) held against 0.3 s per method and room type
    assert rows.loc["generate/planit", "jobs"] == 2 and rows.loc["generate/planit", "job_seconds"] == 1.0
    assert rows.loc["generate/planit", "budget_seconds"] == 0.3 and rows.loc["generate/planit", "over_budget"]
    assert ((tmp_path / "out" / "runtime.csv").read_text().splitlines()[0]
            == "rule,jobs,job_seconds,peak_rss_mb,share,budget_seconds,over_budget")
    assert 'data-value="30.0"' in (tmp_path / "out" / "runtime.html").read_text()  # the wall-clock span, in the page


def test_cooccurrence_similarity_is_grains_conditional_measure():
    """P(c1 | c2) = N(c1, c2) / N(c2); similarity = 1 - mean |P_train - P_set| over frequent distinct pairs."""
    from pipeline.evaluation.distributions import cooccurrence, cooccurrence_similarity

    train = [["bed", "nightstand"], ["bed"], ["bed", "nightstand", "desk"], ["bed", "desk"]]
    p = cooccurrence(train, ["bed", "desk", "nightstand"])
    assert p[0, 2] == 1.0 and p[2, 0] == 0.5 and p[1, 2] == 0.5  # P(bed|nightstand), P(nightstand|bed), P(desk|ns)
    assert cooccurrence_similarity(train, train, 0.1) == 1.0
    only_beds = [["bed"]] * 4  # P(desk|bed) 0.5 -> 0, P(ns|bed) 0.5 -> 0, the rest 0 where N(c2) = 0
    expected = 1 - np.mean(np.abs(p - cooccurrence(only_beds, ["bed", "desk", "nightstand"]))[~np.eye(3, dtype=bool)])
    assert cooccurrence_similarity(train, only_beds, 0.1) == pytest.approx(expected) and expected < 0.7
    assert np.isnan(cooccurrence_similarity(train, [], 0.1))


def test_each_method_gets_one_sentence_from_its_figures():
    """A method near the real rooms in category mix and collisions but failing the functional checks, and one
    colliding everywhere: the sentences name each figure on its side, the classifier only with the power check."""
    from pipeline.evaluation.pages import method_sentences

    real = {"category_kl": 0.0, "object_collision_rate": 0.04, "out_of_bounds_rate": 0.0, "functional_all": 0.95}
    sets = {"good": {"category_kl": 0.05, "object_collision_rate": 0.0, "out_of_bounds_rate": 0.0,
                     "functional_all": 0.5, "sca": {"accuracy": 52.0}},
            "bad": {"category_kl": 0.5, "object_collision_rate": 0.35, "out_of_bounds_rate": 0.02,
                    "functional_all": 0.9, "sca": {"accuracy": 80.0}},
            "real_heldout": real}
    metrics = {"sets": sets, "floors": {"category_kl": {"mean": 0.05}}, "power": {"passed": True}}
    got = method_sentences(metrics)["in one sentence"]
    assert list(got.index) == ["good", "bad"]
    assert got["good"].startswith("good at: category mix 1.0x the sampling floor; 0% of objects colliding (real 4%)")
    assert "real-vs-synthetic classifier at 52%" in got["good"].split("Fails")[0]
    assert got["good"].endswith("Fails at: 0.50 of rooms passing every functional check (real 0.95).")
    assert "Fails at: category mix 10.0x the sampling floor; 35% of objects colliding (real 4%)" in got["bad"]
    assert "0.90 of rooms passing every functional check" in got["bad"].split("Fails")[0]
    assert "classifier at 80%" in got["bad"]
    quiet = method_sentences({**metrics, "power": {"passed": False}})["in one sentence"]
    assert "classifier" not in quiet["good"] + quiet["bad"]
