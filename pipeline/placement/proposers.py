"""Proposers without networks, and what every proposer answers: a pose (centre and yaw) for the object being placed
(:class:`Request`). A :class:`DensityProposer` draws it PlanIT's way, location first from a density over the
candidate centres, then the orientation at that location; the relative-pose prior (``placement/prior.py``) draws
whole poses. Here: uniform locations (the "random location" ablation of PlanIT's Table 3), the relation bands
(:class:`RelationPrior`: where extraction would find each planned edge) and the orientation rule "face away from the
nearest wall". The network proposer is :class:`pipeline.methods.planit.nets.proposer.NetProposer`."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry import raster
from ..geometry.boxes import SIDES, diagonal_2d, point_box
from ..geometry.frames import front_of, to_local, to_world, turn_error, wrap
from ..geometry.function import faces_wall, facing_angles, facing_each_other, facing_turn, in_front
from ..geometry.polygon import nearest_segment
from ..geometry.relations import DistanceBands, distance_thresholds
from ..room import RoomInput, Walls
from .anchors import SUPPORT, Anchor
from .facing import AnchorFacing
from .layout import box_frame, wall_frame
from .support import EDGES, OFF_EDGE, CentreLine, EdgeRule, half_depth_on
from .turns import QUARTER, SupportTurn

WALL_DEPTH = 1e-3  # m, half depth of a wall's segment standing in as a box (FacingPartner)
HELD_COS = np.cos(np.pi / 4)  # no tuning: the bisector of a frame's two axes, so a held axis holds the nearer of them
HOLDING = ("adjacent", "proximal")  # the distances of the edges that hold an object along their axis


@dataclass
class Request:
    """The object being placed: its category and symmetry, its anchors (:class:`~pipeline.placement.anchors.Anchor`)
    in the room as it stands, the candidate centres (:class:`Grid`) and which of them are allowed ``mask (cells,)``
    (on the floor or its support's top, off what stands there, outside rejected squares); ``ahead``: the plan's objects
    not placed yet that are not its anchors, as (category, index of the wall it is planned adjacent to);
    ``later_sides``: the directions of its planned spatial edges to objects not placed yet (the sides the plan fills
    later)."""
    room: RoomInput
    walls: Walls
    category: str
    symmetry: str
    anchors: list[Anchor]
    grid: "Grid"
    mask: np.ndarray
    ahead: tuple[tuple[str, int], ...] = ()
    later_sides: tuple[str, ...] = ()

    @property
    def points(self) -> np.ndarray:
        return self.grid.points


class Grid:
    """Candidate centres: cell centres over the room's bounding square at ``mpp``, and those on the floor."""

    def __init__(self, outline: np.ndarray, mpp: float):
        lo, hi = outline.min(0), outline.max(0)
        self.mpp = mpp
        self.size = int(np.ceil((hi - lo).max() / mpp)) + 2
        self.centre = (lo + hi) / 2
        xs, ys = raster.pixel_centres(self.size, mpp, self.centre)
        self.points = np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)
        self.floor = raster.fill_polygon(outline, self.size, mpp, self.centre).reshape(-1)

    def cells(self, xy: np.ndarray) -> np.ndarray:
        """``(m,)`` index of the cell holding each point ``xy (m, 2)`` (-1 outside the grid)."""
        k = np.asarray(xy, float) - self.centre
        col = np.floor(k[:, 0] / self.mpp + self.size / 2).astype(int)
        row = np.floor(self.size / 2 - k[:, 1] / self.mpp).astype(int)
        ok = (row >= 0) & (row < self.size) & (col >= 0) & (col < self.size)
        return np.where(ok, row * self.size + col, -1)


def nearest_wall(walls: Walls, xy: np.ndarray) -> int:
    """Index of the wall nearest to plan point ``xy (2,)``."""
    return int(nearest_segment(np.asarray(xy, float), walls.segments)[1])


class DensityProposer:
    """PlanIT's order: a centre drawn from ``density`` over the allowed candidates (uniformly within its cell), then
    a yaw from ``orientation`` at that centre."""

    def density(self, room: RoomInput, walls: Walls, category: str, anchors: list[Anchor], points: np.ndarray) -> np.ndarray:
        """``(m,)`` unnormalised density of the object's centre at ``points (m, 2)``."""
        raise NotImplementedError

    def orientation(self, req: Request, xy: np.ndarray, rng: np.random.Generator) -> float:
        """A yaw (rad) for the requested object centred at ``xy (2,)``."""
        raise NotImplementedError

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        """A centre ``(2,)`` and yaw, or None when no allowed candidate has mass."""
        if not req.mask.any():
            return None
        p = self.density(req.room, req.walls, req.category, req.anchors, req.points) * req.mask
        if not np.isfinite(p).all() or p.sum() <= 0:
            p = req.mask.astype(float)
        cell = rng.choice(len(p), p=p / p.sum())
        xy = req.points[cell] + rng.uniform(-0.5, 0.5, 2) * req.grid.mpp
        return xy, self.orientation(req, xy, rng)


class UniformLocation(DensityProposer):
    """Every candidate centre equally likely (before the floor / support mask)."""

    def density(self, room, walls, category, anchors, points) -> np.ndarray:
        return np.ones(len(points))


def gap_thresholds(a: Anchor, room: RoomInput, walls: Walls, extract: dict) -> tuple[float, float]:
    """The largest gaps (m) at which extraction labels the anchor's edge to the placed object (half extents
    ``a.target_half``) adjacent and proximal: ``extract.distance``'s thresholds for the larger footprint diagonal of
    the two (a wall's is the object's)."""
    anchor_diag = 0.0 if a.wall is not None else float(diagonal_2d(*room.boxes[a.obj, 3:5]))
    diag = max(anchor_diag, float(diagonal_2d(*a.target_half)))
    adj, prox = distance_thresholds(diag, DistanceBands.of(extract["distance"]))
    return float(adj), float(prox)


def band_limits(a: Anchor, room: RoomInput, walls: Walls, extract: dict, slack: float):
    """Where a target's centre may lie beyond the anchor side its spatial edge names for extraction to find that edge:
    ``(side half length, depth range (lo, hi) m beyond the side, largest |along| m)``. Depth follows the distance
    label's gap thresholds (:func:`gap_thresholds`) for any turn of the target (its half extents: smaller ``s``, larger
    ``l``), widened by ``slack`` m; along keeps the share of the target or of the side that must be visible
    (``extract.spatial.min_visibility``) for the target's smallest extent along the side."""
    s, l = min(a.target_half), max(a.target_half)
    if a.wall is not None:
        half_len = walls.length[a.wall] / 2
    else:
        hx, hy = room.boxes[a.obj, 3:5]
        half_len = hx if SIDES.index(a.direction) < 2 else hy
    adj, prox = gap_thresholds(a, room, walls, extract)
    depth = {"adjacent": (s - slack, l + adj + slack), "proximal": (s + adj - slack, l + prox + slack),
             "distant": (s + prox - slack, np.inf)}[a.distance]
    return half_len, depth, half_len + s - 2 * extract["spatial"]["min_visibility"] * min(half_len, s)


def side_coordinates(a: Anchor, room: RoomInput, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(m,)`` depth of ``points`` beyond the anchor's side its edge names (m, from the side's line) and their
    coordinate along it (from its middle)."""
    local = to_local(a.frame, points)
    if a.wall is not None:
        return local[:, 1], local[:, 0]
    hx, hy = room.boxes[a.obj, 3:5]
    s = SIDES.index(a.direction)
    axis, sign = (1, 1.0 if s == 0 else -1.0) if s < 2 else (0, -1.0 if s == 2 else 1.0)
    return sign * local[:, axis] - (hy if axis == 1 else hx), local[:, 1 - axis]


class RelationPrior(DensityProposer):
    """No network: each spatial edge from a placed anchor allows the band beyond the anchor's side where extraction
    would find it (:func:`band_limits`); anchors multiply, support and reverse edges leave every point. A baseline,
    the relation mask over the networks' densities, and the proposer of the tests that must not depend on training.
    ``extract``: the extraction config (``distance`` and ``spatial`` thresholds)."""

    def __init__(self, extract: dict, soft: float = 0.0, slack: float = 0.05):
        self.extract, self.soft, self.slack = extract, soft, slack  # soft: the density outside a band (0: none)

    def density(self, room, walls, category, anchors, points) -> np.ndarray:
        out = np.ones(len(points))
        for a in anchors:
            if a.kind == "spatial" and not a.reverse:
                out *= np.where(self.band(a, room, walls, points), 1.0, self.soft)
        return out

    def band(self, a: Anchor, room: RoomInput, walls: Walls, points: np.ndarray) -> np.ndarray:
        """``(m,)`` bool: the points in anchor ``a``'s band; a radially symmetric anchor's edges are all labelled
        front by extraction, so its band is the union of its four sides'."""
        sides = SIDES if a.obj is not None and a.symmetry == "radial" else (a.direction,)
        inside = np.zeros(len(points), bool)
        for side in sides:
            s = replace(a, direction=side)
            _, (lo, hi), reach = band_limits(s, room, walls, self.extract, self.slack)
            depth, along = side_coordinates(s, room, points)
            inside |= (depth >= lo) & (depth <= hi) & (np.abs(along) <= reach)
        return inside


class FaceAway:
    """Front turned away from the nearest wall (into the room)."""

    def orientation(self, req: Request, xy: np.ndarray, rng: np.random.Generator) -> float:
        return wall_frame(req.walls, nearest_wall(req.walls, xy)).yaw


class FacePlanned:
    """Turned so that what the plan puts around the object can stand there. With an edge from the object to a placed
    one (a reverse anchor), the turn that squarely faces the side of that object its place lies beyond
    (:func:`~pipeline.geometry.function.facing_turn`), then turned so that it lies in the edge's direction (front: as
    is; back: half a turn; left, right: a quarter turn): a dining chair whose plan puts the table in front of it faces
    the table. Else, planned adjacent to walls, square to the nearest of them with a side the plan leaves free
    toward it (:attr:`Request.later_sides`; back first, then left, right, front): a dining table against a wall with
    chairs planned behind and before it stands end-on. Else the ``base`` orienter's turn. The plan's own relations, nothing
    learned: for proposers with no orientation model (the relation bands)."""

    TURN = {"front": 0.0, "back": np.pi, "left": -np.pi / 2, "right": np.pi / 2}  # from facing it, side toward it

    def __init__(self, base):
        self.base = base

    def orientation(self, req: Request, xy: np.ndarray, rng: np.random.Generator) -> float:
        ahead = [a for a in req.anchors if a.reverse and a.obj is not None and a.direction in self.TURN]
        walls = [a.wall for a in req.anchors if a.wall is not None and a.distance == "adjacent" and not a.reverse]
        if ahead:
            a = ahead[0]
            return float(wrap(facing_turn(req.room.boxes.reshape(-1, 7)[a.obj], xy) + self.TURN[a.direction]))
        if walls:
            free = next((side for side in ("back", "left", "right") if side not in req.later_sides), "front")
            w = walls[int(nearest_segment(np.asarray(xy, float), req.walls.segments[walls])[1])]
            return float(wrap(wall_frame(req.walls, w).yaw + np.pi + self.TURN[free]))  # + pi: facing the wall
        return self.base.orientation(req, xy, rng)


class BackToWall:
    """A proposer whose objects planned adjacent to a wall stand with their back to one of those walls as often as the
    training rooms' objects of their category do against a wall (``shares``:
    :func:`~pipeline.placement.walls.learn_wall_backs`): with that share the drawn turn becomes the nearest of the
    planned walls' "facing into the room" turns; the place stays drawn (the search's snap then slides the object
    flush against the wall)."""

    def __init__(self, base, shares: dict[str, float]):
        self.base, self.shares = base, shares

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        drawn = self.base.pose(req, rng)
        share = self.shares.get(req.category, 0.0)
        walls = [a.wall for a in req.anchors if a.wall is not None and a.distance == "adjacent" and not a.reverse]
        if drawn is None or not walls or not share or rng.random() >= share:
            return drawn
        xy, yaw = drawn
        away = np.array([wall_frame(req.walls, w).yaw for w in walls])
        return xy, float(away[np.argmin(turn_error(away - yaw))])


class FaceAnchor:
    """A proposer whose floor objects planned beside a placed floor anchor face it as often as the training rooms'
    objects of their category face one of the anchor's category standing near it (``rules``: (anchor category,
    object category) -> :class:`~pipeline.placement.facing.AnchorFacing`): with the largest share among the planned
    anchors, the drawn turn becomes the one that squarely faces the side of that anchor the drawn place lies beyond
    (:func:`~pipeline.geometry.function.facing_turn`: an office chair in front of its desk turns to the desk), turned
    by one of the training pairs' turns off square, drawn uniformly; the place stays drawn."""

    def __init__(self, base, rules: dict[tuple[str, str], AnchorFacing]):
        self.base, self.rules = base, rules

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        drawn = self.base.pose(req, rng)
        none = AnchorFacing(0.0)
        ruled = [(self.rules.get((req.room.categories[a.obj], req.category), none), a.obj) for a in req.anchors
                 if a.obj is not None and a.kind == "spatial" and not a.reverse]
        if drawn is None or not ruled or any(a.kind == SUPPORT for a in req.anchors):
            return drawn
        rule, obj = max(ruled, key=lambda r: (r[0].share, r[1]))
        if rng.random() >= rule.share:
            return drawn
        xy, _ = drawn
        off = rule.residuals[rng.integers(len(rule.residuals))]
        return xy, float(wrap(facing_turn(req.room.boxes.reshape(-1, 7)[obj], xy) + off))


class FacingPartner:
    """A proposer whose floor objects face a placed object their plan says nothing of as often as the training rooms'
    objects of their category face one of that category (``shares``: (partner category, object category) -> share,
    :func:`~pipeline.placement.facing.learn_facing_partners`): with the largest such share among the placed
    partners, the pose is drawn from the base proposer conditioned on facing one of them within ``facing`` rad
    (:func:`~pipeline.geometry.function.facing_each_other`): up to ``tries`` poses are drawn and the first that faces
    one is kept; where none does, the first that does once turned to squarely face the side of the nearest partner its
    place lies beyond (:func:`~pipeline.geometry.function.facing_turn`; a turn drawn, as a wall back, goes first; never
    turned away from a planned anchor it faced as drawn), else one drawn among the cells in a partner's view no nearer
    than the training pairs stand (``near``: (partner, object) category -> m), else the first drawn. With no partner placed yet, a
    partner the plan puts against a wall later (:attr:`Request.ahead`: a sofa placed before the television stand the
    plan puts in front of it, or says nothing of) stands in as that wall: the object is drawn squarely facing the
    wall's segment (:func:`~pipeline.geometry.function.faces_wall`), so that the partner, back to the wall, faces it
    back. A placed partner the object has a planned edge to is the plan's; an object on a support has none."""

    def __init__(self, base, shares: dict[tuple[str, str], float], facing: float, tries: int,
                 near: dict[tuple[str, str], float] | None = None):
        self.base, self.shares, self.facing, self.tries, self.near = base, shares, facing, tries, near or {}

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        first = self.base.pose(req, rng)
        if first is None or any(a.kind == SUPPORT for a in req.anchors):
            return first
        partners, share, boxes, wall = self._partners(req), 0.0, req.room.boxes.reshape(-1, 7), None
        near = np.array([self.near.get((req.room.categories[o], req.category), 0.0) for o in partners])
        if len(partners):
            share = max(self.shares[(req.room.categories[o], req.category)] for o in partners)
            boxes = boxes[partners]
        else:
            later = [(self.shares[(c, req.category)], w) for c, w in req.ahead if (c, req.category) in self.shares]
            if later:
                share, wall = max(later)
                boxes = self._wall_box(req, wall)
        if not share or rng.random() >= share:
            return first
        turned: tuple[np.ndarray, float] | None = None
        for k in range(self.tries):
            drawn = first if k == 0 else self.base.pose(req, rng)
            if drawn is None:
                break
            xy, yaw = drawn
            if self._faces(req, boxes, xy, yaw, wall, near):
                return drawn
            turn = facing_turn(boxes[np.argmin(np.linalg.norm(boxes[:, :2] - xy, axis=1))], xy)
            if turned is None and self._faces(req, boxes, xy, turn, wall, near) and self._keeps(req, xy, yaw, turn):
                turned = (xy, turn)
        return turned or (self._in_view(req, boxes, near, rng) if wall is None else None) or first

    def _in_view(self, req: Request, partners: np.ndarray, near: np.ndarray,
                 rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        """A pose drawn from the base proposer among the cells within a placed partner's facing cone and no nearer
        to any partner than the training pairs stand (``near (m,)`` m), turned to face the nearest partner's side
        (None where no such cell has mass or the turned pose faces none): a sofa whose draws all stood beside the
        television's view, along its own wall."""
        apart = np.linalg.norm(req.grid.points[:, None] - partners[None, :, :2], axis=-1)  # (cells, partners)
        seen = req.mask & in_front(partners, req.grid.points, self.facing) & (apart >= near).all(axis=1)
        drawn = self.base.pose(replace(req, mask=seen), rng) if seen.any() else None
        if drawn is None:
            return None
        xy, yaw = drawn
        turn = facing_turn(partners[np.argmin(np.linalg.norm(partners[:, :2] - xy, axis=1))], xy)
        faces = self._faces(req, partners, xy, turn, None, near) and self._keeps(req, xy, yaw, turn)
        return (xy, turn) if faces else None

    def _partners(self, req: Request) -> np.ndarray:
        """Indices of the placed objects of a partner category the plan gives the object no edge to."""
        planned = {req.room.categories[a.obj] for a in req.anchors if a.obj is not None}
        cats = req.room.categories
        return np.array([k for k, c in enumerate(cats) if (c, req.category) in self.shares and c not in planned], int)

    def _keeps(self, req: Request, xy: np.ndarray, yaw: float, turn: float) -> bool:
        """Turned from ``yaw`` to ``turn`` at ``xy``, the object still faces (within ``facing``) every planned object
        anchor it faced as drawn: an office chair turned to its desk by its plan is never turned to another desk."""
        planned = [a.obj for a in req.anchors if a.obj is not None and not a.reverse]
        if not planned:
            return True
        boxes = np.vstack([req.room.boxes.reshape(-1, 7)[planned], point_box(xy, yaw), point_box(xy, turn)])
        angles = facing_angles(boxes)[:-2, -2:]  # (planned, drawn | turned)
        return bool(np.all((angles[:, 0] > self.facing) | (angles[:, 1] <= self.facing)))

    def _faces(self, req: Request, partners: np.ndarray, xy: np.ndarray, yaw: float, wall: int | None,
               near: np.ndarray) -> bool:
        """A pose at ``xy`` turned ``yaw`` faces one of ``partners (m, 7)``: each within ``facing`` of the other, no
        nearer than ``near (m,)`` m (how near the training pairs stand); or,
        standing in for a partner placed later against ``wall``, faces that wall squarely and meets it
        (:func:`~pipeline.geometry.function.faces_wall`: what stands there with its back to it faces the pose)."""
        if wall is not None:
            walls = req.walls
            return bool(faces_wall(xy, yaw, walls.a[wall], walls.b[wall], walls.normal[wall], self.facing)[0])
        boxes = np.vstack([partners, point_box(xy, yaw)])
        far = np.linalg.norm(partners[:, :2] - xy, axis=1) >= near
        return bool((facing_each_other(boxes, self.facing)[:-1, -1] & far).any())

    @staticmethod
    def _wall_box(req: Request, w: int) -> np.ndarray:
        """``(1, 7)``: wall ``w``'s segment as a box of depth :data:`WALL_DEPTH` whose front faces into the room."""
        mid, half = (req.walls.a[w] + req.walls.b[w]) / 2, req.walls.length[w] / 2
        return np.array([[mid[0], mid[1], 0.0, half, WALL_DEPTH, 0.0, wall_frame(req.walls, w).yaw]])


class TurnedOnSupport:
    """A proposer whose objects on a support turn to it as the training rooms' objects of their category turn to a
    support of its category (``rules``: (support category, object category) -> :class:`~pipeline.placement.turns.
    SupportTurn`): the drawn turn's nearest quarter turn of the support among those the training pairs stand at
    (counting the object's equivalent fronts), plus one of that quarter's training residuals drawn uniformly. A monitor
    stands square to its desk within the few degrees training monitors do, never sideways; the place stays drawn."""

    def __init__(self, base, rules: dict[tuple[str, str], SupportTurn]):
        self.base, self.rules = base, rules

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        drawn = self.base.pose(req, rng)
        support = next((a.obj for a in req.anchors if a.kind == SUPPORT and a.obj is not None), None)
        rule = None if support is None else self.rules.get((req.room.categories[support], req.category))
        if drawn is None or rule is None:
            return drawn
        xy, yaw = drawn
        turns = req.room.boxes.reshape(-1, 7)[support, 6] + np.array(rule.quarters) * QUARTER
        k = int(np.argmin(turn_error(turns - yaw, req.symmetry)))
        residuals = rule.residuals[k]
        return xy, float(wrap(turns[k] + residuals[rng.integers(len(residuals))]))


class Combined(DensityProposer):
    """Locations from one proposer, orientations from another."""

    def __init__(self, location, orienter):
        self.location, self.orienter = location, orienter

    def density(self, *args) -> np.ndarray:
        return self.location.density(*args)

    def orientation(self, *args) -> float:
        return self.orienter.orientation(*args)


class Masked(DensityProposer):
    """A proposer whose densities are weighted by ``mask``'s (e.g. the network's by the relation bands: with soft
    bands, where fewer relations can hold is unlikely, not impossible)."""

    def __init__(self, base, mask):
        self.base, self.mask = base, mask

    def density(self, *args) -> np.ndarray:
        return self.base.density(*args) * self.mask.density(*args)

    def orientation(self, *args) -> float:
        return self.base.orientation(*args)


def axis_of(yaw: float, direction: str) -> np.ndarray:
    """The world unit axis ``(2,)`` along which a frame turned ``yaw`` (rad) measures ``direction``: its local y for
    ``front``/``back``, its local x for ``left``/``right``."""
    return front_of(yaw) if direction in ("front", "back") else front_of(yaw - np.pi / 2)


def held_axes(anchors: list[Anchor], yaw: float, symmetry: str = "none") -> np.ndarray:
    """``(n, 2)`` world axes along which the object's planned adjacent and proximal edges hold it: the axis of each
    edge's direction in its frame (the anchor's; the drawn turn ``yaw`` for a reverse edge, whose direction is in the
    object's own frame). A wall's edge holds the object at its distance from the wall. A distant edge holds nothing:
    it allows any distance beyond the proximal gap (every side wall is distant from a sofa; centring a coffee table
    on the sofa's line runs along that wall's normal). A radially symmetric frame (``symmetry``: the object's own, for
    reverse edges) holds nothing either: extraction labels all its edges front, so its front axis is arbitrary."""
    axes = [axis_of(yaw if a.reverse else a.frame.yaw, a.direction) for a in anchors
            if a.kind != SUPPORT and a.direction is not None and a.distance in HOLDING
            and (symmetry if a.reverse else a.symmetry) != "radial"]
    return np.array(axes).reshape(-1, 2)


def unheld(share: np.ndarray, yaw: float, held: np.ndarray) -> np.ndarray:
    """``share (2,)`` (of moving a place across and along a frame turned ``yaw``) with each component zeroed whose axis
    lies within 45 degrees of one of the ``held (n, 2)`` axes (:func:`held_axes`)."""
    axes = np.array([axis_of(yaw, "left"), axis_of(yaw, "front")])
    return share * ~(np.abs(axes @ held.T) > HELD_COS).any(1)


class Centred:
    """A proposer whose objects stand near their anchors' centre lines as often and as far off them as the training
    rooms' do: ``rules`` maps (anchor category, object category, ``support`` | ``spatial`` | ``facing``) to the
    :class:`~pipeline.placement.support.CentreLine` of :func:`~pipeline.placement.support.learn_centring` (a plain
    ``(across, along)`` pair of shares: offsets 0). On a support, with the ``back`` or ``front`` rule's share the
    drawn place moves along the support to stand the rule's gap from that edge (a monitor at the back of its desk, a
    keyboard at its front) unless that puts its centre farther off the support's centre line than any training
    pair's (a thin television at the back of a deep stand, the stand's middle no longer under it), else with each
    share's probability the drawn place's offset across (along) the support is replaced by one of the training
    pairs' offsets near the line, drawn uniformly, and with an edge rule the offset along its depth is kept within
    the training pairs' (no television in front of its stand's middle); beside a placed floor anchor planned in
    front of or behind it, the offset across it (by the pair's ``facing`` line where planned in front of it and
    turned to face it back: an office chair facing its desk stands closer to the desk's line than chairs in front of
    desks at large), and planned left or right of it, the offset along it; a floor object facing a placed object
    with no planned edge to it, the two facing each other within ``facing`` rad at the drawn pose
    (:func:`~pipeline.geometry.function.facing_each_other`), the offset across it, unless that offset runs along an
    axis a planned edge holds it on (:func:`held_axes`: a chair planned in front of its table, facing a chair seated
    at the table's end, stays in front of the table); the same holds for the moves onto a planned anchor's lines (a
    chair planned in front of a table and beside a chair across it is not moved to that chair's depth). A drawn place
    is only as fine as the proposer's grid or network (0.15 m per pixel for PlanIT's at the default preset); the turn
    is the base proposer's.
    """

    def __init__(self, base, rules: dict[tuple[str, str, str], tuple], facing: float = np.pi / 4):
        self.base, self.rules, self.facing = base, rules, facing

    def pose(self, req: Request, rng: np.random.Generator) -> tuple[np.ndarray, float] | None:
        drawn = self.base.pose(req, rng)
        if drawn is None:
            return None
        xy, yaw = drawn
        for a in req.anchors:
            if a.obj is None or a.reverse:
                continue
            pair = (req.room.categories[a.obj], req.category)
            rule, edge = self.rules.get((*pair, a.kind)), self._edge(pair) if a.kind == SUPPORT else None
            if a.kind != SUPPORT and a.direction == "front" and self._turned_to(req, a.obj, yaw):
                rule = self.rules.get((*pair, "facing"), rule)
            if rule is None and edge is None:
                continue
            line = CentreLine(*(rule or (0.0, 0.0)))
            share = np.asarray(line[:2]) * (
                [1, 1] if a.kind == SUPPORT else [1, 0] if a.direction in ("front", "back") else [0, 1])
            if edge is not None:
                moved = self._at_edge(req.room.boxes[a.obj], a.target_half, yaw, edge, xy, rng)
                if moved is not None:
                    xy, share = moved, share * [1, 0]
                elif (*pair, OFF_EDGE) in self.rules:  # the centre lines of the training pairs off that edge
                    line = CentreLine(*self.rules[(*pair, OFF_EDGE)])
                    share = np.asarray(line[:2], float)
            if a.kind != SUPPORT:  # never off another planned edge's place
                share = unheld(share, a.frame.yaw, held_axes([b for b in req.anchors if b is not a], yaw, req.symmetry))
            xy = self._onto_line(a.frame, xy, share, line, rng)
            if edge is not None:
                xy = self._within(req.room.boxes[a.obj], xy, edge[1])
        planned, held = {a.obj for a in req.anchors}, held_axes(req.anchors, yaw, req.symmetry)
        for o in ([] if any(a.kind == SUPPORT for a in req.anchors) else self._facing(req, xy, yaw)):
            if o not in planned:
                line = CentreLine(*self.rules[(req.room.categories[o], req.category, "facing")])
                frame = box_frame(req.room.boxes[o])
                xy = self._onto_line(frame, xy, unheld(np.array([line.across, 0.0]), frame.yaw, held), line, rng)
        return xy, yaw

    def _turned_to(self, req: Request, obj: int, yaw: float) -> bool:
        """Whether a drawn turn ``yaw`` (rad) faces the placed object ``obj`` back within ``facing``: planned in front
        of it, the two then face each other on its line."""
        return bool(abs(turn_error(yaw - req.room.boxes.reshape(-1, 7)[obj, 6] - np.pi)) <= self.facing)

    def _facing(self, req: Request, xy: np.ndarray, yaw: float) -> np.ndarray:
        """Indices of the placed objects with a ``facing`` rule for the requested category that face each other with
        the drawn pose."""
        ruled = np.array([(c, req.category, "facing") in self.rules for c in req.room.categories], bool)
        if not ruled.any():
            return np.zeros(0, int)
        boxes = np.vstack([req.room.boxes.reshape(-1, 7), point_box(xy, yaw)])
        return np.flatnonzero(ruled & facing_each_other(boxes, self.facing)[:-1, -1])

    def _at_edge(self, support: np.ndarray, half, yaw: float, edge: tuple[str, EdgeRule], xy: np.ndarray,
                 rng: np.random.Generator) -> np.ndarray | None:
        """With the ``edge`` rule's share, ``xy`` moved to its gap from that edge of ``support (7,)``
        (:meth:`_onto_edge`); None where not drawn, or where the move lies beyond the rule's low and high offsets from
        the support's middle."""
        if rng.random() >= edge[1].share:
            return None
        moved = self._onto_edge(support, half, yaw, edge, xy)
        return moved if edge[1].low <= to_local(box_frame(support), moved)[1] <= edge[1].high else None

    @staticmethod
    def _within(support: np.ndarray, xy: np.ndarray, rule: EdgeRule) -> np.ndarray:
        """``xy`` with its offsets from ``support (7,)``'s centre lines clipped to the ``rule``'s (m): never farther
        behind, in front of or beside the middle than any training pair stood."""
        frame = box_frame(support)
        local = to_local(frame, xy)
        local[1] = np.clip(local[1], rule.low, rule.high)
        local[0] = np.clip(local[0], rule.across_low, rule.across_high)
        return to_world(frame, local)

    def _edge(self, pair: tuple[str, str]) -> tuple[str, EdgeRule] | None:
        """The (support, object) ``pair``'s edge rule, ``(edge, rule)`` (None: none learned)."""
        return next(((e, EdgeRule(*self.rules[(*pair, e)])) for e in EDGES if (*pair, e) in self.rules), None)

    @staticmethod
    def _onto_edge(support: np.ndarray, half, yaw: float, edge: tuple[str, EdgeRule], xy: np.ndarray) -> np.ndarray:
        """``xy`` moved along ``support (7,)`` so that a footprint of half extents ``half (2,)`` turned ``yaw`` stands
        the ``edge`` rule's gap from that edge (:func:`~pipeline.placement.support.edge_gap`)."""
        frame = box_frame(support)
        local = to_local(frame, xy)
        local[1] = EDGES[edge[0]] * (support[4] - half_depth_on(support, half, yaw) - edge[1].gap)
        return to_world(frame, local)

    @staticmethod
    def _onto_line(frame, xy: np.ndarray, share: np.ndarray, line: CentreLine, rng: np.random.Generator) -> np.ndarray:
        """``xy`` with its offset across (along) ``frame``'s centre line replaced, with probability ``share (2,)``, by
        one of ``line``'s training offsets across (along) it."""
        local = to_local(frame, xy)
        hit = rng.random(2) < share
        for axis, offs in enumerate((line.across_offsets, line.along_offsets)):
            if hit[axis]:
                local[axis] = offs[rng.integers(len(offs))]
        return to_world(frame, local)
