"""The built-in procedural corpus: rooms with functional arrangements and the relations they were built with.

Every room is generated from ``(seed, room index)`` alone, so a corpus is deterministic per seed and any
room can be rebuilt by itself. Arrangements follow what PlanIT's extraction must rediscover: beds against
walls between nightstands with lamps on them, rows of wardrobes and kitchen units, dining tables with chairs
around, desks with chairs and monitors, sofas facing a TV on a stand, rows of plants, plus free clutter.
A share of rooms carries one deliberate defect for the filters (recorded as a ``defect`` relation).

Placements are as hard as real rooms when ``placement`` shares are given: a share of contacts is exactly
flush, a share slightly interpenetrating (objects into each other or into the wall, up to ``max_overlap``),
and a share of chairs and armchairs is turned (desk chairs pulled out and angled, armchairs at 30-45 deg to a
wall) with the nearest corner at the contact. Every intended adjacency records its case in ``label``
(gap | flush | overlap | turned) so that extraction is scored per case.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely

from ..geometry import boxes
from ..geometry.polygon import inward_normals, polygon_segments, signed_area
from ..seeding import rng_for
from . import furniture
from .rows import model_row, opening_row, room_row, wall_rows

ROOM_TYPES = ("bedroom", "living", "office", "bathroom", "kitchen")
ROOM_SIZE = {  # (min, max) extent in m along each axis
    "bedroom": (3.2, 5.4), "living": (4.0, 5.9), "office": (3.2, 5.6), "bathroom": (2.2, 3.6), "kitchen": (3.0, 5.0),
}
DEFECTS = ("wall_loop", "mislabeled", "interpenetration", "rare_category", "room_size", "room_height")
MAX_OBJECTS = 20
# closed bodies (no legs, no raised frame, not hollow): an ottoman pushed into one penetrates its mesh, not only its box
SOLID = {"wardrobe", "dresser", "bookshelf", "kitchen_cabinet", "sink_cabinet", "refrigerator", "washing_machine", "dryer",
         "vanity", "tv_stand", "sideboard", "filing_cabinet", "cabinet", "pantry", "dishwasher", "stove"}


@dataclass
class Model:
    model_id: str
    category: str
    w: float
    d: float
    h: float


@dataclass
class Obj:
    object_id: str
    category: str
    model: Model
    cx: float
    cy: float
    cz: float
    yaw: float
    parent: str | None = None

    @property
    def box(self) -> tuple:
        return (self.cx, self.cy, self.cz, self.model.w / 2, self.model.d / 2, self.model.h / 2, self.yaw)


@dataclass
class Wall:
    index: int
    a: np.ndarray
    b: np.ndarray
    normal: np.ndarray

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.b - self.a))

    @property
    def dir(self) -> np.ndarray:
        return (self.b - self.a) / self.length

    @property
    def yaw_in(self) -> float:
        """Yaw that makes an object's front face into the room."""
        return math.atan2(self.normal[1], self.normal[0]) - math.pi / 2

    @property
    def element_id(self) -> str:
        return f"wall_{self.index}"


def build_models(variants: int, seed: int) -> tuple[dict[str, list[Model]], list[dict]]:
    """Every catalogue model: per-category lists for the generator and rows of the ``models`` table."""
    by_cat: dict[str, list[Model]] = {}
    rows = []
    for name in [*furniture.CATEGORIES, *furniture.RARE]:
        n = variants if name in furniture.CATEGORIES else 1
        for k in range(n):
            v, f, (w, d, h) = furniture.build_model(name, k, seed)
            mid = furniture.model_id(name, k)
            by_cat.setdefault(name, []).append(Model(mid, name, w, d, h))
            rows.append(model_row(mid, name, "procedural", v, f))
    return by_cat, rows


def _overlap(a: shapely.Polygon, b: shapely.Polygon) -> bool:
    """Footprints overlapping by more than 1 mm^2 (bounds checked first: most pairs are far apart)."""
    ax0, ay0, ax1, ay1 = a.bounds
    bx0, by0, bx1, by1 = b.bounds
    return ax0 < bx1 and bx0 < ax1 and ay0 < by1 and by0 < ay1 and a.intersection(b).area > 1e-6


def _direction_label(anchor_category: str, local_xy: np.ndarray) -> str:
    """front/back/left/right of a point in an anchor's local frame (radial anchors: always front)."""
    cat = furniture.CATEGORIES.get(anchor_category)
    if cat is not None and cat.symmetry == "radial":
        return "front"
    x, y = local_xy
    if abs(y) >= abs(x):
        return "front" if y > 0 else "back"
    return "right" if x > 0 else "left"


def _slack(gaps: list[float]) -> float:
    """The deepest intended interpenetration among a group's contact gaps (m, >= 0)."""
    return max(0.0, -min(gaps))


def _depth_along(m: Model, turn: float) -> float:
    """Half extent of a footprint turned by ``turn`` (rad) along the direction it faced before turning."""
    return abs(m.w / 2 * math.sin(turn)) + abs(m.d / 2 * math.cos(turn))


@dataclass
class RoomBuilder:
    room_id: str
    room_type: str
    rng: np.random.Generator
    models: dict[str, list[Model]]
    outline: np.ndarray = None
    height: float = 2.7
    walls: list[Wall] = field(default_factory=list)
    arch: list[dict] = field(default_factory=list)
    objects: list[Obj] = field(default_factory=list)
    gt: list[dict] = field(default_factory=list)
    keepout: list = field(default_factory=list)
    placement: dict = field(default_factory=dict)  # shares: flush, overlap, turned; max_overlap in m
    index: int = 0
    _groups: int = 0
    _placed: list = field(default_factory=list)  # (object id, footprint) of the first-tier objects placed so far
    _room: shapely.Polygon | None = None

    # ------------------------------------------------------------------ architecture
    def make_shell(self, l_shape: bool, size_range: tuple[float, float], height: float) -> None:
        lo, hi = size_range
        w, d = self.rng.uniform(lo, hi, size=2)
        if l_shape:
            a, b = w * self.rng.uniform(0.3, 0.45), d * self.rng.uniform(0.3, 0.45)
            corner = int(self.rng.integers(4))
            pts = np.array([[0, 0], [w, 0], [w, d - b], [w - a, d - b], [w - a, d], [0, d]], dtype=float)
            if corner % 2:  # mirror in x (stays counter-clockwise after reversing)
                pts = np.column_stack([w - pts[:, 0], pts[:, 1]])[::-1]
            if corner >= 2:
                pts = np.column_stack([pts[:, 0], d - pts[:, 1]])[::-1]
            pts = np.roll(pts, -int(np.argmin(pts[:, 0] * 1e3 + pts[:, 1])), axis=0)
        else:
            pts = np.array([[0, 0], [w, 0], [w, d], [0, d]], dtype=float)
        assert signed_area(pts) > 0
        self.outline = np.round(pts, 4)
        self.height = height
        segs = polygon_segments(self.outline)
        for i, (seg, n) in enumerate(zip(segs, inward_normals(segs))):
            self.walls.append(Wall(i, seg[0].copy(), seg[1].copy(), n))
        self.arch += wall_rows(self.room_id, self.outline, height, float(self.rng.uniform(0.1, 0.2)))
        self._openings()

    def _openings(self) -> None:
        long_walls = [w for w in self.walls if w.length >= 1.4]
        door_wall = long_walls[int(self.rng.integers(len(long_walls)))]
        dw = float(self.rng.uniform(0.8, 0.95))
        s = float(self.rng.uniform(0.1, door_wall.length - dw - 0.1))
        self._opening("door", 0, door_wall, s, dw, 0.0, 2.05)
        # keep the door swing free: a square in front of the door
        p0 = door_wall.a + door_wall.dir * s
        p1 = p0 + door_wall.dir * dw
        swing = np.array([p0, p1, p1 + door_wall.normal * 0.9, p0 + door_wall.normal * 0.9])
        self.keepout.append(shapely.Polygon(swing))
        others = [w for w in long_walls if w is not door_wall]
        self.rng.shuffle(others)
        for k, wall in enumerate(others[: int(self.rng.integers(0, 3))]):
            ww = float(self.rng.uniform(0.8, min(1.4, wall.length - 0.4)))
            s = float(self.rng.uniform(0.2, wall.length - ww - 0.2))
            self._opening("window", k, wall, s, ww, 0.9, 2.1)

    def _opening(self, kind: str, k: int, wall: Wall, s: float, width: float, z0: float, z1: float) -> None:
        p0 = wall.a + wall.dir * s
        self.arch.append(opening_row(self.room_id, kind, k, (p0, p0 + wall.dir * width), (z0, z1), wall.element_id))

    # ------------------------------------------------------------------ objects
    def model(self, category: str, variant: int | None = None) -> Model:
        options = self.models[category]
        return options[int(self.rng.integers(len(options)))] if variant is None else options[variant % len(options)]

    @staticmethod
    def _footprint(m: Model, cx: float, cy: float, yaw: float) -> shapely.Polygon:
        """The footprint polygon (the arithmetic of ``boxes.footprint_corners``, for one box without NumPy)."""
        c, s = math.cos(yaw), math.sin(yaw)
        hx, hy = m.w / 2, m.d / 2
        return shapely.Polygon([(c * lx - s * ly + cx, s * lx + c * ly + cy)
                                for lx, ly in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))])

    def fits(self, placements: list[tuple[Model, float, float, float]], slack: float = 0.0,
             partners: tuple[str, ...] = ()) -> bool:
        """All footprints inside the room, outside the door swing, clear of every first-tier object. ``slack`` (m):
        the intended interpenetration among the placements, with the walls and with the placed objects named in
        ``partners``; footprints are eroded by it for those checks only (other objects are never touched)."""
        if self._room is None:
            self._room = shapely.Polygon(self.outline).buffer(1e-6)
        group = []
        for m, cx, cy, yaw in placements:
            full = self._footprint(m, cx, cy, yaw)
            fp = full.buffer(-slack - 1e-4, join_style="mitre") if slack > 0 else full
            if not self._room.covers(fp) or any(_overlap(full, k) for k in self.keepout):
                return False
            if any(_overlap(fp if oid in partners else full, p) for oid, p in self._placed):
                return False
            if any(_overlap(fp, q) for q in group):
                return False
            group.append(fp)
        return True

    def add(self, category: str, m: Model, cx: float, cy: float, yaw: float, z: float = 0.0, parent: str | None = None) -> Obj:
        o = Obj(f"obj_{len(self.objects):02d}", category, m, cx, cy, z + m.h / 2, yaw, parent)
        self.objects.append(o)
        if parent is not None:
            self.relation("support", parent, o.object_id)
        else:
            self._placed.append((o.object_id, self._footprint(m, cx, cy, yaw)))
        return o

    def relation(self, relation: str, anchor: str | None, target: str | None, direction: str | None = None,
                 group: str | None = None, label: str | None = None) -> None:
        self.gt.append({"room_id": self.room_id, "relation": relation, "anchor_id": anchor, "target_id": target,
                        "direction": direction, "group_id": group, "label": label})

    def group_id(self, kind: str) -> str:
        self._groups += 1
        return f"{kind}_{self._groups}"

    def direction(self, anchor: Obj, target: Obj) -> str:
        local = boxes.to_local(np.array([target.cx, target.cy]), anchor.cx, anchor.cy, anchor.yaw)
        return _direction_label(anchor.category, local)

    def adjacent(self, a: Obj, b: Obj, case: str, both: bool = True) -> None:
        self.relation("adjacent", a.object_id, b.object_id, self.direction(a, b), label=case)
        if both:
            self.relation("adjacent", b.object_id, a.object_id, self.direction(b, a), label=case)

    def remaining(self) -> int:
        return MAX_OBJECTS - len(self.objects)

    # ------------------------------------------------------------------ placement helpers
    def wall_group(self, pieces: list[tuple[str, Model, float, float, float]], tries: int = 30,
                   walls: list[Wall] | None = None, slack: float = 0.0) -> tuple[Wall, list[Obj]] | None:
        """Place a rigid group along a wall. ``pieces``: (category, model, gx, gy, yaw_g) in the wall frame
        (x along the wall from the chosen point, y into the room, yaw relative to facing the room); ``slack``:
        the group's intended interpenetration (m)."""
        if len(pieces) > self.remaining():
            return None
        xs = [gx + s * h for _, m, gx, _, _ in pieces for s, h in ((-1, m.w / 2), (1, m.w / 2))]
        span_lo, span_hi = min(xs), max(xs)
        candidates = walls or self.walls
        for _ in range(tries):
            wall = candidates[int(self.rng.integers(len(candidates)))]
            lo, hi = -span_lo, wall.length - span_hi
            if hi < lo:
                continue
            s = float(self.rng.uniform(lo, hi))
            placements = []
            for _cat, m, gx, gy, yg in pieces:
                p = wall.a + wall.dir * (s + gx) + wall.normal * gy
                placements.append((m, float(p[0]), float(p[1]), wall.yaw_in + yg))
            if self.fits(placements, slack):
                return wall, [self.add(cat, m, cx, cy, yaw) for (cat, *_), (m, cx, cy, yaw) in zip(pieces, placements)]
        return None

    def free_group(self, pieces: list[tuple[str, Model, float, float, float]], tries: int = 40) -> list[Obj] | None:
        """Place a rigid group anywhere inside the room at a cardinal orientation (plus a little jitter)."""
        if len(pieces) > self.remaining():
            return None
        lo, hi = self.outline.min(axis=0), self.outline.max(axis=0)
        for _ in range(tries):
            c = self.rng.uniform(lo + 0.3, hi - 0.3)
            theta = float(self.rng.integers(4)) * math.pi / 2 + float(self.rng.normal(0, 0.03))
            r = boxes.rotation(theta)
            placements = []
            for _cat, m, gx, gy, yg in pieces:
                p = c + r @ np.array([gx, gy])
                placements.append((m, float(p[0]), float(p[1]), theta + yg))
            if self.fits(placements):
                return [self.add(cat, m, cx, cy, yaw) for (cat, *_), (m, cx, cy, yaw) in zip(pieces, placements)]
        return None

    def on_top(self, parent: Obj, category: str, frac: tuple[float, float] = (0.0, 0.0)) -> Obj | None:
        """Put a small object on ``parent``'s top surface at local offset ``frac`` of its half extents."""
        if self.remaining() < 1:
            return None
        m = self.model(category)
        if m.w > parent.model.w * 0.95 or m.d > parent.model.d * 0.95:
            return None
        fx = frac[0] * (parent.model.w - m.w) / 2
        fy = frac[1] * (parent.model.d - m.d) / 2
        p = np.array([parent.cx, parent.cy]) + boxes.rotation(parent.yaw) @ np.array([fx, fy])
        top = parent.cz + parent.model.h / 2 + float(self.rng.uniform(0.0, 0.002))
        yaw = parent.yaw + float(self.rng.normal(0, 0.05))
        if not self._room.covers(self._footprint(m, float(p[0]), float(p[1]), yaw)):  # a parent pushed into a wall
            p = np.array([parent.cx, parent.cy])
        return self.add(category, m, float(p[0]), float(p[1]), yaw, z=top, parent=parent.object_id)

    def wall_adjacent(self, wall: Wall, objs: list[Obj], cases: list[str]) -> None:
        for o, case in zip(objs, cases):
            self.relation("adjacent", wall.element_id, o.object_id, "front", label=case)

    def gap(self, hi: float = 0.008) -> float:
        return float(self.rng.uniform(0.0, hi))

    def contact(self, hi: float = 0.008) -> tuple[float, str]:
        """The gap (m) of one intended contact and its case: flush (0), overlap (< 0) or gap (0 .. ``hi``)."""
        u = self.rng.random()
        flush, overlap = self.placement.get("flush", 0.0), self.placement.get("overlap", 0.0)
        if u < flush:
            return 0.0, "flush"
        if u < flush + overlap:
            return -float(self.rng.uniform(0.005, self.placement["max_overlap"])), "overlap"
        return self.gap(hi), "gap"

    def turned(self) -> bool:
        return bool(self.rng.random() < self.placement.get("turned", 0.0))

    # ------------------------------------------------------------------ functional arrangements
    def bed_with_nightstands(self) -> None:
        bed, ns = self.model("bed"), self.model("nightstand")
        (g1, c1), (g2, c2) = self.contact(), self.contact()
        backs = [self.contact(0.006) for _ in range(3)]
        pieces = [("bed", bed, 0.0, backs[0][0] + bed.d / 2, 0.0),
                  ("nightstand", ns, -(bed.w / 2 + g1 + ns.w / 2), backs[1][0] + ns.d / 2, 0.0),
                  ("nightstand", ns, bed.w / 2 + g2 + ns.w / 2, backs[2][0] + ns.d / 2, 0.0)]
        placed = self.wall_group(pieces, slack=_slack([g1, g2] + [g for g, _ in backs]))
        if placed is None:
            return
        wall, (b, n1, n2) = placed
        self.wall_adjacent(wall, [b, n1, n2], [c for _, c in backs])
        hub = self.group_id("hub")
        for n, case in ((n1, c1), (n2, c2)):
            self.adjacent(b, n, case)
            self.relation("hub", b.object_id, n.object_id, self.direction(b, n), hub)
            if self.rng.random() < 0.85:
                self.on_top(n, "table_lamp", (float(self.rng.uniform(-0.3, 0.3)), 0.0))

    def row(self, categories: list[str], same_model: bool = True, wall: Wall | None = None) -> None:
        """An adjacent chain of similar-size objects along a wall."""
        ms = [self.model(categories[0])] * len(categories) if same_model else [self.model(c) for c in categories]
        pieces, x, backs, joins = [], 0.0, [], []
        for cat, m in zip(categories, ms):
            backs.append(self.contact(0.006))
            joins.append(self.contact(0.006))
            pieces.append((cat, m, x + m.w / 2, backs[-1][0] + m.d / 2, 0.0))
            x += m.w + joins[-1][0]
        gaps = [g for g, _ in backs] + [g for g, _ in joins[:-1]]
        placed = self.wall_group(pieces, walls=[wall] if wall else None, slack=_slack(gaps))
        if placed is None:
            return None
        wall, objs = placed
        self.wall_adjacent(wall, objs, [c for _, c in backs])
        chain = self.group_id("chain")
        for k, o in enumerate(objs):
            self.relation("chain", objs[0].object_id, o.object_id, None, chain, "adjacent")
            if k:
                self.adjacent(objs[k - 1], o, joins[k - 1][1])
        return objs

    def plant_row(self, n: int = 3) -> None:
        m = self.model("plant")
        back = float(self.rng.uniform(0.05, 0.25))
        pieces, x = [], 0.0
        for _ in range(n):
            pieces.append(("plant", m, x + m.w / 2, back + m.d / 2, float(self.rng.normal(0, 0.03))))
            x += m.w + float(self.rng.uniform(0.15, 0.3))
        placed = self.wall_group(pieces)
        if placed is None:
            return
        _, objs = placed
        chain = self.group_id("chain")
        for o in objs:
            self.relation("chain", objs[0].object_id, o.object_id, None, chain, "proximal")

    def desk_setup(self, chair_cat: str = "office_chair") -> None:
        desk, chair = self.model("desk"), self.model(chair_cat)
        back, case = self.contact(0.006)
        pulled = self.turned()  # pulled out and angled: the nearest corner touches the desk's front
        turn = float(self.rng.choice([-1.0, 1.0]) * self.rng.uniform(math.radians(10), math.radians(30))) if pulled else 0.0
        cgap = self.gap(0.01) if pulled else float(self.rng.uniform(0.1, 0.3))
        pieces = [("desk", desk, 0.0, back + desk.d / 2, 0.0),
                  (chair_cat, chair, float(self.rng.uniform(-0.1, 0.1)), back + desk.d + cgap + _depth_along(chair, turn),
                   math.pi + turn)]
        placed = self.wall_group(pieces, slack=_slack([back]))
        if placed is None:
            return
        wall, (d, c) = placed
        self.wall_adjacent(wall, [d], [case])
        if pulled:
            self.adjacent(d, c, "turned", both=False)
        self.relation("faces", c.object_id, d.object_id, "front")
        self.on_top(d, "monitor", (float(self.rng.uniform(-0.4, 0.0)), -0.9))
        if self.rng.random() < 0.6:
            self.on_top(d, "keyboard", (float(self.rng.uniform(-0.4, 0.0)), 0.8))
        elif self.rng.random() < 0.5:
            self.on_top(d, "laptop", (0.7, 0.5))

    def dining(self, table_cat: str = "dining_table", chair_cat: str = "dining_chair") -> None:
        t, ch = self.model(table_cat), self.model(chair_cat)
        pieces = [(table_cat, t, 0.0, 0.0, 0.0)]
        if table_cat == "round_table":
            k = int(self.rng.integers(2, 5))
            r = t.w / 2 + ch.d / 2 + float(self.rng.uniform(0.0, 0.1))
            for i in range(k):
                a = 2 * math.pi * i / k
                pieces.append((chair_cat, ch, r * math.sin(a), r * math.cos(a), math.pi - a))
        else:
            per_side = 2 if t.w > 1.5 else 1
            for side in (1, -1):
                y = side * (t.d / 2 + ch.d / 2 + float(self.rng.uniform(0.0, 0.1)))
                for i in range(per_side):
                    x = (i - (per_side - 1) / 2) * t.w / 2
                    pieces.append((chair_cat, ch, x, y, math.pi if side > 0 else 0.0))
        objs = self.free_group(pieces)
        if objs is None:
            return
        hub = self.group_id("hub")
        for c in objs[1:]:
            self.relation("hub", objs[0].object_id, c.object_id, self.direction(objs[0], c), hub)
            self.relation("faces", c.object_id, objs[0].object_id, "front")
        if self.rng.random() < 0.5:
            self.on_top(objs[0], self.rng.choice(["fruit_bowl", "vase"]), (0.0, 0.0))

    def tv_and_sofa(self) -> None:
        stand, sofa = self.model("tv_stand"), self.model("sofa")
        back, case = self.contact(0.006)
        dist = float(self.rng.uniform(1.8, 2.6))
        pieces = [("tv_stand", stand, 0.0, back + stand.d / 2, 0.0),
                  ("sofa", sofa, 0.0, back + stand.d + dist + sofa.d / 2, math.pi)]
        with_table = self.rng.random() < 0.8
        if with_table:
            ct = self.model("coffee_table")
            pieces.append(("coffee_table", ct, 0.0, back + stand.d + dist - float(self.rng.uniform(0.3, 0.45)) - ct.d / 2, 0.0))
        placed = self.wall_group(pieces, slack=_slack([back]))
        if placed is None:
            return
        wall, objs = placed
        self.wall_adjacent(wall, [objs[0]], [case])
        self.relation("faces", objs[1].object_id, objs[0].object_id, "front")
        self.on_top(objs[0], "tv", (0.0, -0.5))
        if self.rng.random() < 0.5:
            self.side_table_beside(objs[1])

    def side_table_beside(self, anchor: Obj) -> None:
        st = self.model("side_table")
        side = float(self.rng.choice([-1.0, 1.0]))
        g, case = self.contact()
        local = np.array([side * (anchor.model.w / 2 + g + st.w / 2), -anchor.model.d / 2 + st.d / 2 + self.gap(0.05)])
        p = np.array([anchor.cx, anchor.cy]) + boxes.rotation(anchor.yaw) @ local
        if self.remaining() >= 1 and self.fits([(st, float(p[0]), float(p[1]), anchor.yaw)], _slack([g]), (anchor.object_id,)):
            o = self.add("side_table", st, float(p[0]), float(p[1]), anchor.yaw)
            self.adjacent(anchor, o, case)
            if self.rng.random() < 0.7:
                self.on_top(o, "table_lamp")

    def against_wall(self, category: str, on_top: str | None = None) -> Obj | None:
        m = self.model(category)
        back, case = self.contact(0.006)
        placed = self.wall_group([(category, m, 0.0, back + m.d / 2, 0.0)], slack=_slack([back]))
        if placed is None:
            return None
        wall, (o,) = placed
        self.wall_adjacent(wall, [o], [case])
        if on_top:
            self.on_top(o, on_top, (float(self.rng.uniform(-0.5, 0.5)), 0.0))
        return o

    def in_corner(self, category: str) -> Obj | None:
        """Long side against a wall, short side against the previous wall at a convex corner."""
        m = self.model(category)
        rotated = m.d > m.w  # put the long side along the wall
        w_along = m.d if rotated else m.w
        d_in = m.w if rotated else m.d
        order = list(range(len(self.walls)))
        self.rng.shuffle(order)
        for i in order:
            wall, prev = self.walls[i], self.walls[i - 1]
            if np.dot(prev.normal, wall.dir) < 0.99:  # not a convex right-angle corner
                continue
            (g_prev, c_prev), (g_wall, c_wall) = self.contact(0.005), self.contact(0.005)
            p = wall.a + wall.dir * (w_along / 2 + g_prev) + wall.normal * (d_in / 2 + g_wall)
            yaw = wall.yaw_in + (math.pi / 2 if rotated else 0.0)
            if self.remaining() >= 1 and self.fits([(m, float(p[0]), float(p[1]), yaw)], _slack([g_prev, g_wall])):
                o = self.add(category, m, float(p[0]), float(p[1]), yaw)
                self.wall_adjacent(wall, [o], [c_wall])
                self.wall_adjacent(prev, [o], [c_prev])
                return o
        return None

    def turned_against_wall(self, m: Model) -> None:
        """An armchair at 30-45 deg to a wall, its nearest corner 0-1 cm from it."""
        turn = float(self.rng.choice([-1.0, 1.0]) * self.rng.uniform(math.radians(30), math.radians(45)))
        placed = self.wall_group([(m.category, m, 0.0, self.gap(0.01) + _depth_along(m, turn), turn)], tries=10)
        if placed is not None:
            self.wall_adjacent(placed[0], placed[1], ["turned"])

    def clutter(self, categories: list[str], n: int) -> None:
        for _ in range(n):
            if self.remaining() < 1:
                return
            cat = str(self.rng.choice(categories))
            m = self.model(cat)
            if cat == "armchair" and self.turned():
                self.turned_against_wall(m)
            elif self.rng.random() < 0.5:
                self.wall_group([(cat, m, 0.0, float(self.rng.uniform(0.05, 0.4)) + m.d / 2,
                                  float(self.rng.normal(0, 0.15)))], tries=10)
            else:
                self.free_group([(cat, m, 0.0, 0.0, float(self.rng.uniform(-0.4, 0.4)))], tries=10)


# ---------------------------------------------------------------------------------------- room recipes
def _bedroom(r: RoomBuilder) -> None:
    r.bed_with_nightstands()
    if r.rng.random() < 0.6:
        r.row(["wardrobe"] * int(r.rng.integers(3, 5)))
    else:
        r.against_wall("wardrobe")
    if r.rng.random() < 0.5:
        r.desk_setup("chair")
    if r.rng.random() < 0.5:
        r.against_wall("dresser", on_top=str(r.rng.choice(["vase", "books", "clock"])))
    if r.rng.random() < 0.3:
        r.plant_row()
    r.clutter(["floor_lamp", "armchair", "laundry_basket", "trash_can", "plant", "toy_box", "ottoman", "bookshelf",
               "coat_rack", "stool"], int(r.rng.integers(1, 4)))


def _living(r: RoomBuilder) -> None:
    r.tv_and_sofa()
    if r.rng.random() < 0.5:
        r.dining(str(r.rng.choice(["dining_table", "round_table"])))
    if r.rng.random() < 0.45:
        r.row(["bookshelf"] * int(r.rng.integers(3, 5)))
    if r.rng.random() < 0.35:
        r.plant_row()
    if r.rng.random() < 0.4:
        r.against_wall("sideboard", on_top=str(r.rng.choice(["vase", "fruit_bowl", "table_lamp"])))
    r.clutter(["armchair", "floor_lamp", "plant", "ottoman", "speaker", "side_table", "bookshelf", "stool",
               "trash_can", "armchair", "radiator"], int(r.rng.integers(1, 4)))


def _office(r: RoomBuilder) -> None:
    r.desk_setup()
    if r.rng.random() < 0.5:
        r.desk_setup()
    if r.rng.random() < 0.5:
        r.row([str(r.rng.choice(["bookshelf", "filing_cabinet"]))] * int(r.rng.integers(3, 5)))
    if r.rng.random() < 0.35:
        r.dining("meeting_table", "chair")
    if r.rng.random() < 0.3:
        r.plant_row()
    if r.rng.random() < 0.4:
        r.against_wall("cabinet", on_top="printer")
    r.clutter(["plant", "floor_lamp", "trash_can", "water_cooler", "coat_rack", "armchair", "bookshelf",
               "filing_cabinet", "sofa", "side_table"], int(r.rng.integers(1, 4)))


def _bathroom(r: RoomBuilder) -> None:
    r.against_wall("toilet")
    if r.rng.random() < 0.6:
        r.in_corner("bathtub")
    else:
        r.in_corner("shower")
    r.against_wall("vanity", on_top=str(r.rng.choice(["soap", "cup", "small_plant", "candle"])))
    if r.rng.random() < 0.4:
        laundry = ["washing_machine", "dryer"] if r.rng.random() < 0.6 else ["washing_machine"]
        pieces, x, backs, joins = [], 0.0, [], []
        for cat in laundry:
            m = r.model(cat)
            backs.append(r.contact(0.006))
            joins.append(r.contact())
            pieces.append((cat, m, x + m.w / 2, backs[-1][0] + m.d / 2, 0.0))
            x += m.w + joins[-1][0]
        placed = r.wall_group(pieces, slack=_slack([g for g, _ in backs] + [joins[0][0]]))
        if placed is not None:
            wall, objs = placed
            r.wall_adjacent(wall, objs, [c for _, c in backs])
            if len(objs) == 2:
                r.adjacent(objs[0], objs[1], joins[0][1])
    r.clutter(["trash_can", "towel_rack", "laundry_basket", "hamper", "plant", "stool", "radiator", "shelf",
               "toilet_brush", "bath_scale", "mirror", "cabinet", "bench"], int(r.rng.integers(1, 4)))


def _kitchen(r: RoomBuilder) -> None:
    units = ["kitchen_cabinet", "sink_cabinet", "stove", "dishwasher", "kitchen_cabinet", "kitchen_cabinet"]
    n = int(r.rng.integers(3, 7))
    objs = r.row([str(c) for c in r.rng.permutation(units)[:n]], same_model=False)
    r.against_wall("refrigerator")
    for o in objs or []:
        if o.category == "kitchen_cabinet" and r.rng.random() < 0.5:
            r.on_top(o, str(r.rng.choice(["microwave", "kettle", "toaster", "coffee_maker", "fruit_bowl"])))
    if r.rng.random() < 0.5:
        r.dining(str(r.rng.choice(["dining_table", "round_table"])))
    if r.rng.random() < 0.3:
        r.against_wall("pantry")
    r.clutter(["trash_can", "stool", "plant", "shelf", "radiator", "bench"], int(r.rng.integers(1, 4)))


MIN_FLOOR_OBJECTS = 6
CLUTTER = {"bedroom": ["floor_lamp", "armchair", "laundry_basket", "trash_can", "plant", "ottoman"],
           "living": ["armchair", "floor_lamp", "plant", "ottoman", "side_table"],
           "office": ["plant", "floor_lamp", "trash_can", "coat_rack", "filing_cabinet"],
           "bathroom": ["trash_can", "towel_rack", "laundry_basket", "hamper", "stool", "toilet_brush", "bath_scale"],
           "kitchen": ["trash_can", "stool", "plant", "shelf"]}
RECIPES = {"bedroom": _bedroom, "living": _living, "office": _office, "bathroom": _bathroom, "kitchen": _kitchen}
REQUIRED = {"bedroom": {"bed"}, "living": {"sofa", "armchair"}, "office": {"desk"},
            "kitchen": {"kitchen_cabinet", "refrigerator", "stove"}, "bathroom": {"toilet", "bathtub", "shower"}}


def room_id(room_type: str, index: int) -> str:
    return f"proc_{room_type}_{index:05d}"


def generate_room(index: int, room_type: str, seed: int, models: dict[str, list[Model]],
                  defect_rate: float, l_shape_rate: float, placement: dict | None = None) -> RoomBuilder:
    """Generate room ``index`` of ``room_type``; deterministic in ``(seed, room_type, index)``. ``placement``:
    shares of flush, overlapping and turned placements (config ``procedural.placement``; none: clean gaps)."""
    rng = rng_for(seed, ROOM_TYPES.index(room_type), index, "procedural-room")
    defect = str(rng.choice(DEFECTS)) if rng.random() < defect_rate else None
    content_type = room_type
    if defect == "mislabeled":
        # bathroom content holds no bed, sofa, desk or kitchen unit; kitchen content no toilet, bath or shower
        content_type = "kitchen" if room_type == "bathroom" else "bathroom"
    size = ROOM_SIZE[content_type]
    if defect == "room_size":
        size = (6.4, 7.8)
    height = float(rng.uniform(4.3, 5.0)) if defect == "room_height" else float(rng.uniform(2.5, 3.0))
    r = RoomBuilder(room_id(room_type, index), room_type, rng, models, placement=placement or {}, index=index)
    r.make_shell(bool(rng.random() < l_shape_rate), size, height)
    RECIPES[content_type](r)
    for _ in range(8):  # top up sparse rooms with clutter so clean rooms pass the object-count bounds
        if sum(o.parent is None for o in r.objects) >= MIN_FLOOR_OBJECTS:
            break
        r.clutter(CLUTTER[content_type], 1)
    if defect == "mislabeled" and REQUIRED[room_type] & {o.category for o in r.objects}:
        defect = None  # content happens to satisfy the label after all
    if defect is not None:
        _apply_defect(r, defect)
    return r


def _apply_defect(r: RoomBuilder, defect: str) -> None:
    if defect == "wall_loop":
        wall = r.arch[int(r.rng.integers(len(r.walls)))]
        cut = float(r.rng.uniform(0.2, 0.5))
        length = math.hypot(wall["x1"] - wall["x0"], wall["y1"] - wall["y0"])
        t = (length - cut) / length
        wall["x1"] = wall["x0"] + t * (wall["x1"] - wall["x0"])
        wall["y1"] = wall["y0"] + t * (wall["y1"] - wall["y0"])
    elif defect == "interpenetration":
        big = [o for o in r.objects if o.parent is None and o.category in SOLID and min(o.model.w, o.model.d) >= 0.4
               and o.model.h >= 0.4]
        if not big:
            return
        host = big[int(r.rng.integers(len(big)))]
        m = r.model("ottoman")
        r.add("ottoman", m, host.cx + float(r.rng.uniform(-0.05, 0.05)), host.cy, host.yaw)
    elif defect == "rare_category":
        cat = furniture.RARE[r.index % len(furniture.RARE)]  # spread over the list so each stays rare
        m = r.model(cat)
        if r.free_group([(cat, m, 0.0, 0.0, 0.0)]) is None:
            c = r.outline.mean(axis=0)
            r.add(cat, m, float(c[0]), float(c[1]), 0.0)
    r.relation("defect", None, None, label={"room_size": "room_size", "room_height": "room_height"}.get(defect, defect))


def room_tables(r: RoomBuilder) -> tuple[dict, list[dict], list[dict], list[dict]]:
    """Rows of the canonical tables for one generated room."""
    room = room_row(r.room_id, "procedural", (r.room_type, r.room_type), r.outline, r.height, len(r.objects))
    objs = []
    for o in r.objects:
        objs.append({"room_id": r.room_id, "object_id": o.object_id, "category": o.category, "model_id": o.model.model_id,
                     "cx": o.cx, "cy": o.cy, "cz": o.cz, "hx": o.model.w / 2, "hy": o.model.d / 2, "hz": o.model.h / 2,
                     "yaw": o.yaw, "px": o.cx, "py": o.cy, "pz": o.cz - o.model.h / 2, "sx": 1.0, "sy": 1.0, "sz": 1.0,
                     "source_parent_id": o.parent})
    return room, r.arch, objs, r.gt
