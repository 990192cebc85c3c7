"""GRAINS's rooms in the project's tables: a hierarchy laid onto a room with models retrieved by size gives back the
room it was built from (categories, boxes, support parents), and laid onto a larger room keeps each wall group on its
wall."""
from __future__ import annotations

import numpy as np
import pandas as pd

from pipeline.methods.grains.hierarchy import build_tree, decoded_room
from pipeline.methods.grains.layout import furnish, supports
from pipeline.placement.retrieval import ModelPool
from pipeline.room import BOX_COLUMNS

from test_grains_hierarchy import bedroom, make_room


def pool_of(room) -> ModelPool:
    rows = [{"category": c, "model_id": m, **dict(zip(BOX_COLUMNS, b)), "px": b[0], "py": b[1], "pz": b[2] - b[5],
             "sx": 1.0, "sy": 1.0, "sz": 1.0} for c, m, b in zip(room.categories, room.model_ids, room.boxes)]
    return ModelPool(pd.DataFrame(rows), {})


def test_a_tree_furnished_into_its_own_room_gives_the_room_back():
    room, parents = bedroom()
    tree = build_tree(room, parents)
    got, got_parents = furnish(tree, room, pool_of(room), "s")
    assert sorted(got.categories) == sorted(room.categories)
    for cat in set(room.categories):
        mine = sorted(map(tuple, np.round(room.boxes[[c == cat for c in room.categories]][:, :3], 6)))
        theirs = sorted(map(tuple, np.round(got.boxes[[c == cat for c in got.categories]][:, :3], 6)))
        assert np.allclose(mine, theirs, atol=1e-5), cat
    on = {got.categories[got.object_ids.index(c)]: got.categories[got.object_ids.index(p)]
          for c, p in got_parents.items() if p is not None}
    assert on == {"table_lamp": "nightstand"} and sum(p is not None for p in got_parents.values()) == 2
    assert len(supports(tree)) == 2


def test_a_larger_room_keeps_each_wall_group_on_its_wall():
    room, parents = bedroom()
    big = make_room(np.array([[0, 0], [6, 0], [6, 5], [0, 5]], float), [])
    got, _ = furnish(build_tree(room, parents), big, pool_of(room), "s")
    desk = got.boxes[got.categories.index("desk")]
    bed = got.boxes[got.categories.index("bed")]
    assert abs(desk[1] + desk[4] - 5.0) < 1e-6 and abs(bed[1] - bed[4]) < 1e-6  # backs on the top and bottom walls


def test_a_tree_furnishes_the_room_it_decodes_the_source_room_moved_to_the_origin():
    """The faithful mode: the 4 x 3 m bedroom's tree names its own room (centred on the origin, four walls of the
    source's thickness, its height, no openings); furnishing it gives the source room shifted by (-2, -1.5) m."""
    room, parents = bedroom()
    tree = build_tree(room, parents)
    own = decoded_room(tree, "gen_0", "bedroom")
    assert np.allclose(own.outline, [[-2, -1.5], [2, -1.5], [2, 1.5], [-2, 1.5]]) and own.height == 2.6
    assert own.wall_ids == [f"wall_{k}" for k in range(4)] and np.allclose(own.wall_thickness, 0.1)
    assert own.openings == [] and own.object_ids == []
    assert np.allclose(own.wall_segments[:, 1], np.roll(own.outline, -1, 0))
    got, _ = furnish(tree, own, pool_of(room), "s")
    for cat in set(room.categories):
        mine = sorted(map(tuple, np.round(room.boxes[[c == cat for c in room.categories]][:, :3] - [2, 1.5, 0], 6)))
        theirs = sorted(map(tuple, np.round(got.boxes[[c == cat for c in got.categories]][:, :3], 6)))
        assert np.allclose(mine, theirs, atol=1e-5), cat


def test_within_retrieval_never_takes_a_model_wider_than_the_decoded_box():
    """Three beds (half widths 0.7, 0.8, 1.0 m): for a decoded box of half extents (0.82, 1.0) GRAINS's nearest
    retrieval takes the 0.8 one; for (0.95, 1.0) the 1.0 one (reaching past the box), ``within`` the 0.8 one; for a
    box narrower than every bed, ``within`` takes the smallest."""
    from pipeline.placement.retrieval import nearest, nearest_within

    rows = [{"category": "bed", "model_id": f"b{w}", "cx": 0.0, "cy": 0.0, "cz": 0.3, "hx": w, "hy": 1.0, "hz": 0.3,
             "yaw": 0.0, "px": 0.0, "py": 0.0, "pz": 0.0, "sx": 1.0, "sy": 1.0, "sz": 1.0} for w in (0.7, 0.8, 1.0)]
    pool = ModelPool(pd.DataFrame(rows), {})
    assert nearest(pool, "bed", np.array([0.82, 1.0, 0.3])).model_id == "b0.8"
    assert nearest(pool, "bed", np.array([0.95, 1.0, 0.3])).model_id == "b1.0"
    assert nearest_within(pool, "bed", np.array([0.95, 1.0, 0.3])).model_id == "b0.8"
    assert nearest_within(pool, "bed", np.array([0.5, 0.9, 0.3])).model_id == "b0.7"
    assert nearest_within(pool, "sofa", np.array([0.5, 0.9, 0.3])) is None


def test_within_retrieval_furnishes_the_source_room_back():
    room, parents = bedroom()
    got, _ = furnish(build_tree(room, parents), room, pool_of(room), "s", retrieval="within")
    assert sorted(got.model_ids) == sorted(room.model_ids)
