"""Each filter rule on hand-built rooms, and the filters on the real procedural corpus."""
import numpy as np
import pandas as pd
import pytest

from pipeline import config
from pipeline.corpus import procedural
from pipeline.filtering import category_room_counts, filter_rooms
from pipeline.shards import shard_of

from conftest import Room

_C = config.validate({"filter": {"min_category_rooms": 1}})
CFG = {**_C["filter"], "floor_contact": _C["floor_contact"]}  # what the filter stage passes


def tables_of(*rooms):
    room_rows = pd.DataFrame([dict(vars(r.row()), shard=k % 3) for k, r in enumerate(rooms)])
    arch = pd.concat([r.walls() for r in rooms], ignore_index=True)
    objs = pd.concat([r.objects_df() for r in rooms], ignore_index=True)
    return room_rows, arch, objs


def bedroom(room_id="b", height=2.7, size=(4.0, 4.0)):
    w, d = size
    r = Room([[0, 0], [w, 0], [w, d], [0, d]], height=height, room_id=room_id)
    r.add("o1", "bed", (1.6, 2.0, 1.0), (2.0, 1.01))
    for k, x in enumerate([0.4, 1.2, 2.8, 3.6]):
        r.add(f"c{k}", "chair", (0.45, 0.45, 0.9), (x, 3.3))
    return r


def verdict(*rooms, cfg=CFG):
    rep = run_filter(*tables_of(*rooms), cfg)
    return {row.room_id: (row.status, row.rule, list(row.rules)) for row in rep.itertuples()}


def run_filter(rooms, arch, objs, cfg):
    """The filter as one shard job runs it: category counts from every room, then the shard's rooms."""
    return filter_rooms(rooms, arch, objs, cfg, category_room_counts(rooms, objs))


def test_clean_room_is_kept_in_its_shard():
    rep = run_filter(*tables_of(bedroom(), bedroom("c")), CFG)
    assert (rep["status"] == "kept").all() and rep["shard"].tolist() == [0, 1]


def test_each_rule_rejects_with_its_name():
    tall = bedroom("tall", height=4.5)
    big = bedroom("big", size=(7.0, 4.0))
    few = bedroom("few")
    few.objects = few.objects[:3]
    many = bedroom("many")
    for k in range(20):
        many.add(f"x{k}", "vase", (0.1, 0.1, 0.3), (0.2 + 0.15 * k, 2.5))
    nobed = bedroom("nobed")
    nobed.objects[0]["category"] = "sofa"
    crash = bedroom("crash")
    crash.add("o9", "armchair", (0.8, 0.8, 0.8), (2.0, 1.2))
    out = bedroom("out")
    out.add("o9", "plant", (0.4, 0.4, 1.0), (3.9, 2.0))
    v = verdict(tall, big, few, many, nobed, crash, out)
    assert v["tall"][:2] == ("rejected", "room_height")
    assert v["big"][:2] == ("rejected", "room_size")
    assert v["few"][:2] == ("rejected", "too_few_objects")
    assert v["many"][:2] == ("rejected", "too_many_objects")
    assert v["nobed"][:2] == ("rejected", "mislabeled")
    assert v["crash"][:2] == ("rejected", "interpenetration")
    assert v["out"][:2] == ("rejected", "outside_room")


def test_open_wall_loop_and_rare_category():
    a, b = bedroom("a"), bedroom("b")
    b.objects[1]["category"] = "harp"
    rooms, arch, objs = tables_of(a, b)
    arch.loc[(arch.room_id == "a") & (arch.element_id == "wall_2"), "x1"] -= 0.4
    rep = run_filter(rooms, arch, objs, {**CFG, "min_category_rooms": 2}).set_index("room_id")
    assert rep.loc["a", "rule"] == "wall_loop" and "meets no other wall" in rep.loc["a", "detail"]
    assert rep.loc["b", "rule"] == "rare_category" and "harp" in rep.loc["b", "detail"]


def test_supported_object_does_not_count_as_interpenetration():
    r = bedroom()
    r.add("ns", "nightstand", (0.5, 0.4, 0.55), (0.3, 0.25))
    r.add("lamp", "table_lamp", (0.25, 0.25, 0.45), (0.3, 0.25), z=0.5, parent="ns")  # sunk 5 cm into its parent
    assert verdict(r)["b"][0] == "kept"


def test_shards_are_stable_and_balanced():
    ids = [f"room_{k}" for k in range(4000)]
    shards = np.array([shard_of(i, 4) for i in ids])
    assert shard_of("room_7", 4) == shards[7]
    assert np.bincount(shards).min() > 900


@pytest.fixture(scope="module")
def corpus():
    models, _ = procedural.build_models(4, 0)
    rooms = [procedural.generate_room(i, rt, 0, models, 0.25, 0.3) for rt in procedural.ROOM_TYPES for i in range(40)]
    tabs = [procedural.room_tables(r) for r in rooms]
    return (pd.DataFrame([dict(t[0], shard=0) for t in tabs]), pd.DataFrame([a for t in tabs for a in t[1]]),
            pd.DataFrame([o for t in tabs for o in t[2]]), pd.DataFrame([g for t in tabs for g in t[3]]))


def test_filters_catch_every_planted_defect_and_keep_clean_rooms(corpus):
    rooms, arch, objs, gt = corpus
    rep = run_filter(rooms, arch, objs, {**CFG, "min_category_rooms": 2}).set_index("room_id")
    defects = gt[gt.relation == "defect"].set_index("room_id")["label"]
    assert len(defects) >= 20 and defects.nunique() == len(procedural.DEFECTS)
    for room_id, rule in defects.items():
        assert rule in rep.loc[room_id, "rules"], (room_id, rule, rep.loc[room_id, "detail"])
    clean = rep.drop(index=defects.index)
    assert (clean["status"] == "kept").mean() >= 0.97


def test_floor_objects_use_the_shared_floor_contact_tolerance():
    r = bedroom()  # a bed and four chairs: five floor objects, the minimum for a bedroom
    r.objects[1]["cz"] += 0.03  # 3 cm up: still on the floor (real meshes float 1-35 mm)
    assert verdict(r)["b"][0] == "kept"
    r.objects[1]["cz"] += 0.03  # 6 cm up: no longer
    assert verdict(r)["b"][:2] == ("rejected", "too_few_objects")
