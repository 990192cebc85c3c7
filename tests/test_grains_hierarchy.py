"""GRAINS's hierarchies (pipeline/methods/grains): the 28-D relative-position code inverts exactly for any yaw and
names contacts and alignments on hand cases; a 4 x 3 m bedroom builds the tree the paper's rules give; the tree's
codes lay the room back out exactly, and onto a larger rectangle with each wall group on its wall; an L-shaped
room gets its bounding rectangle's four walls; trees survive a JSON round trip."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from pipeline.geometry.frames import wrap
from pipeline.methods.grains import relpos
from pipeline.methods.grains.hierarchy import (
    Node,
    anchor,
    build_tree,
    describe,
    from_dict,
    layout,
    leaves,
    rectangle_walls,
    to_dict,
    tree_depth,
)
from pipeline.room import RoomInput

BEDROOM = ("root(wall(surround(bed,support(nightstand,table_lamp),support(nightstand,table_lamp))),"
           "wall(),wall(cooc(desk,chair)),wall())")


def box(cx: float, cy: float, hx: float, hy: float, hz: float, yaw: float = 0.0, base: float = 0.0) -> np.ndarray:
    return np.array([cx, cy, base + hz, hx, hy, hz, yaw])


def make_room(outline: np.ndarray, objects: list[tuple[str, str, np.ndarray]]) -> RoomInput:
    """A room with walls along ``outline`` and objects ``(id, category, box)``."""
    segs = np.stack([outline, np.roll(outline, -1, 0)], 1)
    n = len(objects)
    return RoomInput("r", "bedroom", 2.6, outline, [f"wall_{k}" for k in range(len(outline))], segs,
                     np.full(len(outline), 0.1), [], [o[0] for o in objects], [o[1] for o in objects],
                     [f"m_{o[1]}" for o in objects], np.array([o[2] for o in objects]).reshape(n, 7),
                     np.zeros((n, 7)))


def bedroom(turn: float = 0.0) -> tuple[RoomInput, dict[str, str | None]]:
    """4 x 3 m: bed centred on the bottom wall, nightstands flush either side with a lamp each, a desk against the
    top wall facing down and a chair touching its front. ``turn`` (rad) turns the lamps and the chair in place."""
    outline = np.array([[0, 0], [4, 0], [4, 3], [0, 3]], float)
    ns_top = 0.55
    objects = [("bed", "bed", box(2.0, 1.0, 0.8, 1.0, 0.3)),
               ("ns_l", "nightstand", box(0.95, 0.25, 0.25, 0.25, ns_top / 2)),
               ("ns_r", "nightstand", box(3.05, 0.25, 0.25, 0.25, ns_top / 2)),
               ("lamp_l", "table_lamp", box(0.95, 0.25, 0.12, 0.12, 0.2, turn, ns_top)),
               ("lamp_r", "table_lamp", box(3.05, 0.2, 0.12, 0.12, 0.2, -turn, ns_top)),
               ("desk", "desk", box(1.0, 2.65, 0.6, 0.35, 0.38, math.pi)),
               ("chair", "chair", box(1.0, 2.05, 0.25, 0.25, 0.45, turn))]
    parents = {"bed": None, "ns_l": None, "ns_r": None, "lamp_l": "ns_l", "lamp_r": "ns_r", "desk": None,
               "chair": None}
    return make_room(outline, objects), parents


def random_box(rng: np.random.Generator, aligned: bool) -> np.ndarray:
    yaw = rng.integers(-4, 4) * math.pi / 2 if aligned else rng.uniform(-2 * math.pi, 2 * math.pi)
    return np.r_[rng.uniform(-5, 5, 2), rng.uniform(0, 1), rng.uniform(0.1, 1.5, 3), yaw]


def yaw_error(a: float, b: float) -> float:
    return abs(float(wrap(a - b)))


def test_code_round_trips_for_any_yaw():
    rng = np.random.default_rng(7)
    for k in range(500):
        a, b = random_box(rng, k % 2 == 0), random_box(rng, k % 4 < 2)
        code = relpos.encode(a, b)
        assert code.shape == (relpos.CODE,) == (28,)
        assert code[relpos.PAIRS].sum() == 2 and set(np.unique(code[relpos.PAIRS])) == {0.0, 1.0}
        assert -1 <= code[0] < 1
        x, y, yaw = relpos.decode(a, b[3:6], code)
        assert abs(x - b[0]) < 1e-6 and abs(y - b[1]) < 1e-6 and yaw_error(yaw, b[6]) < 1e-6


def test_code_names_contacts_and_alignments():
    a = box(0.0, 0.0, 0.5, 0.4, 0.3, yaw=0.7)
    right = a.copy()
    right[:2] = a[:2] + relpos.rotation(0.7) @ [0.5 + 0.2, 0.1]
    right[3:5] = [0.2, 0.2]
    code = relpos.encode(a, right)
    assert list(code[relpos.ATTACH]) == [0, 0, 0, 1]  # flush against a's right side only
    assert code[relpos.ALIGN][2] == 1 and code[relpos.ALIGN][:2].tolist() == [0, 0]
    # beside a, same yaw, front edges on one line (b is shallower so its back is not)
    beside = right.copy()
    beside[:2] = a[:2] + relpos.rotation(0.7) @ [1.0, 0.4 - 0.2]
    code = relpos.encode(a, beside)
    assert code[relpos.ALIGN].tolist() == [0, 0, 1, 1, 0]
    assert code[relpos.ATTACH].sum() == 0
    # the x pair is a's right edge to b's left edge, 0.3 m apart
    ax, bx = relpos.edge_pair(code, relpos.X_EDGES)
    assert (relpos.SIDES[ax], relpos.SIDES[bx]) == ("right", "left") and code[1] == pytest.approx(0.3)
    # turned half a turn in front of a, b's front meets a's front: a contact, not a 'front' alignment
    facing = beside.copy()
    facing[6] += math.pi
    facing[:2] = a[:2] + relpos.rotation(0.7) @ [0.0, 0.4 + 0.2]
    code = relpos.encode(a, facing)
    assert code[relpos.ALIGN].tolist() == [1, 0, 0, 0, 0] and code[relpos.ATTACH].tolist() == [1, 0, 0, 0]


def test_soft_codes_decode_by_argmax():
    rng = np.random.default_rng(3)
    a, b = random_box(rng, False), random_box(rng, False)
    code = relpos.encode(a, b)
    soft = code.copy()
    soft[relpos.PAIRS] = 0.7 * soft[relpos.PAIRS] + 0.05
    x, y, yaw = relpos.decode(a, b[3:6], soft)
    assert (x, y) == pytest.approx((b[0], b[1]), abs=1e-9) and yaw_error(yaw, b[6]) < 1e-9


def test_bedroom_tree():
    room, parents = bedroom()
    tree = build_tree(room, parents)
    # wall 0 is the bottom edge (y = 0, the bed's), then anticlockwise: right, top (y = 3, the desk's), left
    assert describe(tree) == BEDROOM
    assert [w.kind for w in tree.children] == ["wall"] * 4
    assert tree.half == pytest.approx([2.0, 1.5, 1.3])
    surround = tree.children[0].children[0]
    left, right = surround.children[1:]
    assert (anchor(left).object_id, anchor(right).object_id) == ("ns_l", "ns_r")
    assert surround.codes[0][relpos.ATTACH][2] == 1 and surround.codes[1][relpos.ATTACH][3] == 1  # flush
    assert tree.children[0].codes[0][relpos.ATTACH][0] == 1  # the bed stands against its wall's front
    assert anchor(tree.children[2].children[0]).object_id == "desk"
    assert [n.object_id for n in leaves(tree)] == ["bed", "ns_l", "lamp_l", "ns_r", "lamp_r", "desk", "chair"]
    assert tree_depth(tree) == 5  # root > wall > surround > support > leaf


def test_bedroom_without_the_pair_falls_back_to_cooc():
    room, parents = bedroom()
    keep = [0, 1, 3, 5, 6]  # one nightstand: no surround
    room = RoomInput(**{**vars(room), "object_ids": [room.object_ids[k] for k in keep],
                        "categories": [room.categories[k] for k in keep], "boxes": room.boxes[keep]})
    tree = build_tree(room, parents)
    assert describe(tree) == "root(wall(cooc(bed,support(nightstand,table_lamp))),wall(),wall(cooc(desk,chair)),wall())"


@pytest.mark.parametrize("turn", [0.0, 0.6])
def test_layout_reproduces_the_room(turn: float):
    room, parents = bedroom(turn)
    tree = build_tree(room, parents)
    _, rect = rectangle_walls(room)
    out = {oid: b for _, oid, b in layout(tree, tuple(rect))}
    assert set(out) == set(room.object_ids)
    for k, oid in enumerate(room.object_ids):
        want = room.boxes[k]
        assert out[oid][:2] == pytest.approx(want[:2], abs=1e-6)
        assert yaw_error(out[oid][6], want[6]) < 1e-6
        assert out[oid][3:6] == pytest.approx(want[3:6])
    for child, parent in (("lamp_l", "ns_l"), ("lamp_r", "ns_r")):
        assert out[child][2] - out[child][5] == pytest.approx(out[parent][2] + out[parent][5])
    assert out["bed"][2] == pytest.approx(out["bed"][5])


def test_layout_moves_wall_groups_with_their_walls():
    room, parents = bedroom(0.6)
    tree = build_tree(room, parents)
    out = {oid: b for _, oid, b in layout(tree, (0.0, 0.0, 5.0, 4.0))}
    desk = out["desk"]
    assert desk[1] + desk[4] == pytest.approx(4.0)  # its back still against the (moved) top wall
    assert yaw_error(desk[6], math.pi) < 1e-9
    assert out["chair"][1] + 0.25 == pytest.approx(desk[1] - desk[4])  # still touching the desk's front
    assert out["bed"][1] - out["bed"][4] == pytest.approx(0.0)  # the bed stays on the bottom wall
    assert out["ns_l"][0] + out["ns_l"][3] == pytest.approx(out["bed"][0] - out["bed"][3])  # still flush
    for b in out.values():
        assert 0 <= b[0] <= 5 and 0 <= b[1] <= 4


def test_l_shaped_room_uses_its_bounding_rectangle():
    outline = np.array([[0, 0], [5, 0], [5, 2], [2, 2], [2, 4], [0, 4]], float)
    objects = [("sofa", "sofa", box(2.5, 0.45, 1.0, 0.45, 0.4)),
               ("shelf", "bookshelf", box(4.8, 1.0, 0.4, 0.2, 1.0, math.pi / 2)),
               ("tv", "tv_stand", box(1.0, 3.8, 0.6, 0.2, 0.3, math.pi))]
    room = make_room(outline, objects)
    walls, rect = rectangle_walls(room)
    assert rect.tolist() == [0, 0, 5, 4] and walls.shape == (4, 7)
    assert walls[1, :2].tolist() == pytest.approx([5.05, 2.0]) and walls[1, 6] == pytest.approx(math.pi / 2)
    tree = build_tree(room, {o[0]: None for o in objects})
    assert describe(tree) == "root(wall(sofa),wall(bookshelf),wall(tv_stand),wall())"
    out = {oid: b for _, oid, b in layout(tree, tuple(rect))}
    assert out["shelf"][:2] == pytest.approx([4.8, 1.0])


def test_parent_loops_and_unknown_parents_stand_on_the_floor():
    room, parents = bedroom()
    tree = build_tree(room, {**parents, "ns_l": "lamp_l", "desk": "nowhere"})
    assert len(leaves(tree)) == len(room.object_ids)
    assert describe(tree) == BEDROOM  # the loop is cut at its larger footprint, ns_l


def test_dict_round_trip():
    room, parents = bedroom(0.3)
    tree = build_tree(room, parents)
    back = from_dict(json.loads(json.dumps(to_dict(tree))))
    assert describe(back) == describe(tree) and tree_depth(back) == tree_depth(tree) == 5
    for x, y in zip(leaves(back), leaves(tree)):
        assert (x.label, x.object_id) == (y.label, y.object_id) and np.array_equal(x.box, y.box)
    ours, theirs = layout(tree, (0, 0, 4, 3)), layout(back, (0, 0, 4, 3))
    assert all(np.array_equal(a[2], b[2]) for a, b in zip(ours, theirs))
    decoded = from_dict({**to_dict(Node("leaf", half=np.ones(3), label="bed")), "box": None})
    assert decoded.box is None and decoded.object_id is None
    with pytest.raises(ValueError):
        from_dict({"kind": "tree"})


def test_snapping_a_true_code_moves_a_box_by_at_most_the_contact_tolerance():
    """On an exact code the bits agree with the reals up to ``eps``: snapping moves the centre by <= eps (m) per
    axis, plus how much squaring a box turned under 1 degree (the same-yaw bit's tolerance) changes its bound, and
    the yaw by <= 1 degree."""
    rng = np.random.default_rng(11)
    for k in range(300):
        a = random_box(rng, aligned=True)
        b = random_box(rng, aligned=k % 2 == 0)
        if k % 3 == 0:  # touch a's right side, same yaw, backs collinear
            b = np.array([a[0], a[1], 0, *b[3:6], a[6]])
            d = np.array([a[3] + b[3], b[4] - a[4]])
            b[:2] = a[:2] + relpos.rotation(a[6]) @ d
        code = relpos.encode(a, b)
        x, y, yaw = relpos.decode(a, b[3:6], code, snap=True)
        squared = relpos.extents(code[relpos.ROT] * math.pi, b[3:6]) - b[3:5] if code[relpos.ALIGN][2] else 0.0
        assert math.hypot(x - b[0], y - b[1]) <= 0.01 * math.sqrt(2) + np.linalg.norm(squared) + 1e-9
        assert yaw_error(yaw, b[6]) <= math.radians(1.0) + 1e-9


def test_snapping_a_noisy_decoded_code_restores_what_its_bits_state():
    """A nightstand flush against the bed's right side, backs collinear: with its reals off (turned 9 degrees,
    offsets 7 cm out), the reals alone leave a gap and a turn; snapped, it touches, is square and lines up."""
    bed = box(2.0, 1.0, 0.8, 1.0, 0.3)
    stand = box(3.05, 0.25, 0.25, 0.25, 0.275)
    code = relpos.encode(bed, stand)
    assert code[relpos.ATTACH][3] == 1 and code[relpos.ALIGN][[2, 4]].tolist() == [1, 1]
    noisy = code.copy()
    noisy[relpos.ROT] += 0.05
    noisy[relpos.OFF_X] += 0.07
    noisy[relpos.OFF_Y] += 0.07
    x, y, yaw = relpos.decode(bed, stand[3:6], noisy)
    assert abs(x - 3.05) > 0.05 and abs(yaw) > math.radians(8)
    x, y, yaw = relpos.decode(bed, stand[3:6], noisy, snap=True)
    assert (x, y, yaw) == pytest.approx((3.05, 0.25, 0.0), abs=1e-9)
