"""GRAINS's room hierarchies (Li et al. 2019, section 3.1): a room as a tree of objects grouped by wall, support,
surround and co-occurrence, each internal node holding its children's relative positions (:mod:`.relpos`).

The root holds the floor (``half = (w/2, d/2, height/2)``) and four wall nodes, anticlockwise from the wall on the
bottom edge (``y = min``) of the outline's bounding rectangle: bottom, right, top, left. A wall node's box
(:func:`rectangle_walls`) lies behind the wall's inner face, its front (+y) facing into the room, so each wall's
local x runs anticlockwise along the room. GRAINS's rooms are four-walled; any other room (an L shape) uses its
bounding rectangle's walls, a documented departure.

How :func:`build_tree` groups a room's objects:

- every floor object (no support parent) goes to the rectangle wall nearest its footprint (the smallest distance
  from a footprint corner to the wall's inner line, 0 when it reaches it; ties to the lower wall index); a
  supported object follows its parent (a parent that names no object of the room counts as the floor; a loop of
  parents is cut at its largest footprint, which stands on the floor);
- inside a wall group, (1) *support*: a parent merges with each of its children in turn, children ordered by id:
  ``support(support(p, c1), c2)``, bottom-up so a child's own children come with it; (2) *surround*: a centre node
  with two nodes whose anchors share a category, on opposite sides of the centre's anchor in its local x (left:
  local x < 0, right: > 0), each within ``3 * wall_gap`` m of the centre's footprint in x and with
  ``|local y| <= centre half depth + 0.5`` m, both with a smaller footprint than the centre; the nearest in x on
  each side is taken, the category with the smallest total gap wins; centres are tried hubs first (when ``roles``
  names them), then by footprint area, largest first, until no surround forms; (3) *co-occurrence*: while more than
  one node remains, the two whose anchors' centres are nearest merge as ``cooc(larger, smaller)``; the wall node
  holds the single remaining subtree.

Each internal node's codes place its later children's anchors relative to its first child's anchor (support,
surround, cooc) or the wall box (wall). :func:`layout` reads them top down onto any rectangle: siblings stand on
their reference's base (the floor at the top level), a support child on its parent's top. Numpy only.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...geometry.boxes import footprint_corners, to_local
from ...geometry.polygon import polygon_segments
from ...geometry.relations import parent_cycles
from ...room import RoomInput
from . import relpos

KINDS = ("leaf", "support", "surround", "cooc", "wall", "root")
DEFAULT_THICKNESS = 0.1  # m, when a room names no wall thickness
DEFAULT_HEIGHT = 2.6  # m, when a decoded tree names no height
DEPTH_SLACK = 0.5  # m, how far beyond the centre's half depth a surround's side may stand


@dataclass
class Node:
    """One node of a room's hierarchy; see the module docstring for the children and codes of each kind."""
    kind: str                       # one of KINDS
    children: list[Node] = field(default_factory=list)
    codes: list[np.ndarray] = field(default_factory=list)  # (28,) relative-position codes, see below
    # leaf: (3,) half extents (m); wall: (3,) the wall's box half extents; root: (3,) the floor's (w/2, d/2, height/2)
    half: np.ndarray | None = None
    label: str | None = None        # leaf: category
    object_id: str | None = None    # leaf: the object's id (None when decoded)
    box: np.ndarray | None = None   # (7,) world box of a leaf or wall when built from a room (None when decoded)


def anchor(node: Node) -> Node:
    """The node whose box stands for ``node``: a leaf itself, a wall itself, else its first child's anchor."""
    if node.kind in ("leaf", "wall"):
        return node
    return anchor(node.children[0])


def leaves(node: Node) -> list[Node]:
    """The leaves under ``node``, depth first in children order."""
    if node.kind == "leaf":
        return [node]
    return [leaf for c in node.children for leaf in leaves(c)]


def rect_wall(rect: tuple[float, float, float, float], k: int, thickness: float, height: float) -> np.ndarray:
    """``(7,)`` box of wall ``k`` (0 bottom, 1 right, 2 top, 3 left) of ``rect = (xmin, ymin, xmax, ymax)`` (m):
    behind the inner face, its front (+y) facing into the room, its local x running anticlockwise."""
    x0, y0, x1, y1 = (float(v) for v in rect)
    cx, cy, t = (x0 + x1) / 2, (y0 + y1) / 2, thickness / 2
    centre, length, yaw = [((cx, y0 - t), x1 - x0, 0.0), ((x1 + t, cy), y1 - y0, np.pi / 2),
                           ((cx, y1 + t), x1 - x0, np.pi), ((x0 - t, cy), y1 - y0, -np.pi / 2)][k]
    return np.array([centre[0], centre[1], height / 2, length / 2, t, height / 2, yaw])


def room_rect(room: RoomInput) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` (m) of the room's outline (its wall segments when it has none)."""
    pts = np.asarray(room.outline, float).reshape(-1, 2)
    if len(pts) == 0:
        pts = np.asarray(room.wall_segments, float).reshape(-1, 2)
    lo, hi = pts.min(0), pts.max(0)
    return float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1])


def wall_thickness(room: RoomInput) -> float:
    """The median finite, positive wall thickness of the room (m), :data:`DEFAULT_THICKNESS` without one."""
    t = np.asarray(room.wall_thickness, float).ravel()
    t = t[np.isfinite(t) & (t > 0)]
    return float(np.median(t)) if len(t) else DEFAULT_THICKNESS


def rectangle_walls(room: RoomInput) -> tuple[np.ndarray, np.ndarray]:
    """(4,7) wall boxes of the outline's bounding rectangle, anticlockwise from the bottom edge, fronts facing in,
    and the rectangle (xmin, ymin, xmax, ymax). GRAINS's rooms are four-walled; an L-shaped room uses its bounding
    rectangle's walls (a documented departure). Thickness: the room's median; height: the room's (m)."""
    rect = room_rect(room)
    t = wall_thickness(room)
    return np.stack([rect_wall(rect, k, t, float(room.height)) for k in range(4)]), np.array(rect)


def support_forest(ids: list[str], parents: dict[str, str | None],
                   size: dict[str, float] | None = None) -> dict[str, str | None]:
    """Object id -> support parent id among ``ids`` (None: the floor). A parent outside ``ids`` or the object itself
    counts as floor; a loop of parents is cut at its largest member by ``size`` (footprint area, m^2; then the
    smallest id), which goes to the floor."""
    known, size = set(ids), size or {}
    par = {i: (p if p in known and p != i else None) for i, p in ((i, parents.get(i)) for i in ids)}
    for loop in parent_cycles({i: par[i] for i in sorted(ids)}):
        par[min(loop, key=lambda j: (-size.get(j, 0.0), j))] = None
    return par


def nearest_wall(box: np.ndarray, walls: np.ndarray) -> int:
    """Index of the wall box ``(4, 7)`` whose inner face line is nearest the footprint of ``box`` (7,)."""
    corners = footprint_corners(box[0], box[1], box[3], box[4], box[6])[0]  # (4, 2)
    dist = []
    for w in walls:
        local = to_local(corners, w[0], w[1], w[6])  # the inner face is local y = hy, the room at y > hy
        dist.append(max(float((local[:, 1] - w[4]).min()), 0.0))
    return int(np.argmin(dist))


def area(node: Node) -> float:
    """Footprint area (m^2) of the node's anchor."""
    h = anchor(node).half
    return float(4 * h[0] * h[1])


def code_of(ref: Node, other: Node) -> np.ndarray:
    """``(28,)`` code of ``other``'s anchor box relative to ``ref``'s anchor box."""
    return relpos.encode(anchor(ref).box, anchor(other).box)


def support_subtree(i: str, kids: dict[str, list[str]], leaf: dict[str, Node]) -> Node:
    """Object ``i`` with everything it supports: ``support(support(leaf_i, c1), c2)``, children by id."""
    node = leaf[i]
    for c in sorted(kids.get(i, [])):
        child = support_subtree(c, kids, leaf)
        node = Node("support", [node, child], [code_of(node, child)])
    return node


def side_of(centre: Node, other: Node, wall_gap: float) -> tuple[int, float] | None:
    """``(-1 left | +1 right, gap in x (m))`` of ``other`` beside ``centre`` in the centre's frame, or None when it
    is not a surround side (too far in x or y, straight in front or behind, or not smaller)."""
    c, o = anchor(centre).box, anchor(other).box
    if area(other) >= area(centre):
        return None
    lx, ly = to_local(o[:2], c[0], c[1], c[6])
    ext = relpos.extents(o[6] - c[6], o[3:6])
    gap = abs(lx) - ext[0] - c[3]
    if lx == 0 or gap > 3 * wall_gap or abs(ly) > c[4] + DEPTH_SLACK:
        return None
    return (-1 if lx < 0 else 1), float(gap)


def surround_sides(centre: Node, nodes: list[Node], wall_gap: float) -> tuple[Node, Node] | None:
    """The (left, right) pair of one category that best flanks ``centre`` among ``nodes``, or None."""
    best: dict[tuple[str, int], tuple[float, int]] = {}
    for k, n in enumerate(nodes):
        s = None if n is centre else side_of(centre, n, wall_gap)
        key = (anchor(n).label, s[0]) if s else None
        if s and (key not in best or s[1] < best[key][0]):
            best[key] = (s[1], k)
    pairs = [(best[(cat, -1)][0] + best[(cat, 1)][0], cat) for cat, side in best if side == -1 and (cat, 1) in best]
    if not pairs:
        return None
    cat = min(pairs)[1]
    return nodes[best[(cat, -1)][1]], nodes[best[(cat, 1)][1]]


def centre_order(nodes: list[Node], roles: dict[str, tuple[str, str | None]] | None) -> list[Node]:
    """Surround centre candidates: hubs first (when ``roles`` names them), then the largest footprint, then id."""
    def key(n: Node) -> tuple:
        role = (roles or {}).get(anchor(n).object_id, ("none", None))[0] or "none"
        return ("hub" not in role, -area(n), anchor(n).object_id or "")
    return sorted(nodes, key=key)


def merge_surrounds(nodes: list[Node], roles: dict | None, wall_gap: float) -> list[Node]:
    """Replace every centre and its two flanking like-category nodes by ``surround(centre, left, right)``."""
    nodes = list(nodes)
    formed = True
    while formed:
        formed = False
        for centre in centre_order(nodes, roles):
            sides = surround_sides(centre, nodes, wall_gap)
            if sides:
                left, right = sides
                node = Node("surround", [centre, left, right], [code_of(centre, left), code_of(centre, right)])
                nodes = [node if n is centre else n for n in nodes if n is not left and n is not right]
                formed = True
                break
    return nodes


def merge_cooc(nodes: list[Node]) -> Node | None:
    """Merge nodes pairwise, nearest anchor centres first, into one ``cooc`` tree (None for no nodes)."""
    nodes = list(nodes)
    while len(nodes) > 1:
        xy = np.array([anchor(n).box[:2] for n in nodes])
        d = np.linalg.norm(xy[:, None] - xy[None], axis=-1) + np.diag(np.full(len(nodes), np.inf))
        i, j = np.unravel_index(int(np.argmin(d)), d.shape)
        i, j = min(i, j), max(i, j)
        big, small = (nodes[i], nodes[j]) if area(nodes[i]) >= area(nodes[j]) else (nodes[j], nodes[i])
        nodes[i] = Node("cooc", [big, small], [code_of(big, small)])
        del nodes[j]
    return nodes[0] if nodes else None


def leaf_of(room: RoomInput, k: int) -> Node:
    """Object ``k`` of the room as a leaf."""
    box = np.asarray(room.boxes[k], float).copy()
    return Node("leaf", half=box[3:6].copy(), label=room.categories[k], object_id=room.object_ids[k], box=box)


def wall_node(box: np.ndarray, groups: list[Node], roles: dict | None, wall_gap: float) -> Node:
    """A wall node over the subtrees ``groups`` standing against it (support already merged)."""
    sub = merge_cooc(merge_surrounds(groups, roles, wall_gap))
    node = Node("wall", half=box[3:6].copy(), box=box.copy())
    if sub is not None:
        node.children, node.codes = [sub], [relpos.encode(box, anchor(sub).box)]
    return node


def build_tree(room: RoomInput, parents: dict[str, str | None],
               roles: dict[str, tuple[str, str | None]] | None = None, wall_gap: float = 0.3) -> Node:
    """The room's hierarchy. parents: object id -> support parent id (None: floor). roles: object id -> (role,
    group_id) from the final graph (optional; hub/spoke roles may seed surrounds: hubs are tried first as centres).

    ``wall_gap`` (m): a third of how far a surround's side may stand from its centre. Rules: module docstring.
    """
    walls, rect = rectangle_walls(room)
    ids = list(room.object_ids)
    leaf = {i: leaf_of(room, k) for k, i in enumerate(ids)}
    par = support_forest(ids, parents, {i: area(n) for i, n in leaf.items()})
    kids: dict[str, list[str]] = {}
    for i, p in par.items():
        if p is not None:
            kids.setdefault(p, []).append(i)
    groups: list[list[Node]] = [[] for _ in range(4)]
    for i in sorted(i for i in ids if par[i] is None):
        groups[nearest_wall(leaf[i].box, walls)].append(support_subtree(i, kids, leaf))
    half = np.array([(rect[2] - rect[0]) / 2, (rect[3] - rect[1]) / 2, float(room.height) / 2])
    return Node("root", [wall_node(walls[k], groups[k], roles, wall_gap) for k in range(4)], half=half)


def placed(ref: np.ndarray, half: np.ndarray, code: np.ndarray, base: float, snap: bool = False) -> np.ndarray:
    """``(7,)`` box of half extents ``half`` placed by ``code`` relative to ``ref`` (7,), its bottom at ``base`` (m);
    ``snap``: the code's bits win over its reals (:func:`.relpos.decode`)."""
    x, y, yaw = relpos.decode(ref, half, code, snap)
    return np.array([x, y, base + half[2], half[0], half[1], half[2], yaw])


def place(node: Node, box: np.ndarray, out: list[tuple[str, str | None, np.ndarray]], snap: bool = False) -> None:
    """Append ``(label, object_id, box)`` of every leaf under ``node``, its anchor at ``box`` (7,), depth first."""
    if node.kind == "leaf":
        out.append((node.label, node.object_id, box))
        return
    boxes = [box]
    for k, child in enumerate(node.children[1:]):
        base = box[2] + box[5] if node.kind == "support" else box[2] - box[5]
        boxes.append(placed(box, anchor(child).half, node.codes[k], base, snap))
    for child, b in zip(node.children, boxes):
        place(child, b, out, snap)


def layout(tree: Node, rect: tuple[float, float, float, float],
           snap: bool = False) -> list[tuple[str, str | None, np.ndarray]]:
    """(label, object_id, box (7,)) per leaf, depth first, placed top down from the codes onto ``rect``.

    ``rect = (xmin, ymin, xmax, ymax)`` (m): wall ``k`` of the tree goes onto wall ``k`` of ``rect`` (its box as
    :func:`rectangle_walls` would give, with the tree's wall thickness and height), which is how a decoded tree
    is re-anchored onto a held-out room. Floor objects get ``cz = hz``, supported ones their parent's top + hz.
    ``snap``: every code's bits win over its reals (decoded trees, :func:`.relpos.decode`).
    """
    height = 2 * float(tree.half[2]) if tree.half is not None else DEFAULT_HEIGHT
    out: list[tuple[str, str | None, np.ndarray]] = []
    for k, wall in enumerate(tree.children[:4]):
        thick = 2 * float(wall.half[1]) if wall.half is not None else DEFAULT_THICKNESS
        box = rect_wall(rect, k, thick, height)
        if wall.children:
            place(wall.children[0], placed(box, anchor(wall.children[0]).half, wall.codes[0], 0.0, snap), out, snap)
    return out


def decoded_room(tree: Node, room_id: str, room_type: str) -> RoomInput:
    """The room a decoded tree names itself (GRAINS's own walls, the faithful mode): the rectangle of the root's
    floor half extents centred on the origin, four walls anticlockwise from the bottom one (``wall_<k>`` is the
    tree's wall ``k``) with the decoded walls' median thickness, the root's height, no doors or windows, no objects."""
    half = np.asarray(tree.half if tree.half is not None else [1.0, 1.0, DEFAULT_HEIGHT / 2], float)
    (hx, hy, hz) = half
    outline = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    thick = [2 * float(w.half[1]) for w in tree.children[:4] if w.half is not None]
    return RoomInput(room_id=room_id, room_type=room_type, height=2 * float(hz), outline=outline,
                     wall_ids=[f"wall_{k}" for k in range(4)],
                     wall_segments=polygon_segments(outline),
                     wall_thickness=np.full(4, float(np.median(thick)) if thick else DEFAULT_THICKNESS),
                     openings=[], object_ids=[], categories=[], model_ids=[], boxes=np.zeros((0, 7)),
                     poses=np.zeros((0, 7)))


def tree_depth(node: Node) -> int:
    """Levels from ``node`` down to its deepest leaf (a leaf or a childless node: 1)."""
    return 1 + max((tree_depth(c) for c in node.children), default=0)


def _array(v) -> np.ndarray | None:
    return None if v is None else np.asarray(v, float)


def to_dict(node: Node) -> dict:
    """A JSON-safe dict of the tree (lists of floats for arrays)."""
    return {"kind": node.kind, "children": [to_dict(c) for c in node.children],
            "codes": [np.asarray(c, float).tolist() for c in node.codes],
            "half": None if node.half is None else np.asarray(node.half, float).tolist(),
            "label": node.label, "object_id": node.object_id,
            "box": None if node.box is None else np.asarray(node.box, float).tolist()}


def from_dict(d: dict) -> Node:
    """The tree :func:`to_dict` wrote."""
    if d["kind"] not in KINDS:
        raise ValueError(f"unknown GRAINS node kind {d['kind']!r}")
    return Node(d["kind"], [from_dict(c) for c in d.get("children", [])],
                [np.asarray(c, float) for c in d.get("codes", [])], _array(d.get("half")), d.get("label"),
                d.get("object_id"), _array(d.get("box")))


def describe(node: Node) -> str:
    """A compact string of the tree: leaves by category, internal nodes as ``kind(child,child)``."""
    if node.kind == "leaf":
        return str(node.label)
    return f"{node.kind}({','.join(describe(c) for c in node.children)})"
