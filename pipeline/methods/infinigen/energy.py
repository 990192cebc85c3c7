"""A constraint program as the annealer's problem: one :class:`~pipeline.methods.solver.moves.Spec` per rule (its
degrees of freedom from ``on`` and ``against_wall``) and the program's soft terms, built from Infinigen's operators
(``solver.operators``) over the state's realised boxes."""
from __future__ import annotations

from functools import partial

import numpy as np
import shapely

from ...geometry import boxes as gb
from ...geometry.polygon import nearest_segment
from ...placement.checks import AREA_EPS
from ...placement.retrieval import ModelPool
from ...room.walkability import Walk, walkability
from ..solver import operators as op
from ..solver.moves import Spec
from ..solver.state import State, wall_yaw
from ..solver.terms import Term, footprints, front_of, gaps
from .program import Program


def specs_of(program: Program, pool: ModelPool, symmetry: dict[str, str] | None = None) -> dict[str, Spec]:
    """The program's rules whose category has a training instance, as solver specs."""
    out = {}
    for cat, r in program.objects.items():
        if not pool.has(cat) or (r.on is not None and not pool.has(r.on)):
            continue
        dof = "on" if r.on is not None else "wall" if r.against_wall else "floor"
        out[cat] = Spec(cat, tuple(r.count), "small" if dof == "on" else r.stage, dof, r.on,
                        (symmetry or {}).get(cat, "none"), r.next_to if dof != "on" else None)
    return out


def _of(state: State, category: str) -> list[int]:
    return [k for k, it in enumerate(state.items) if it.category == category]


def related(program: Program, state: State, relation: str):
    """``(k, js)`` for each object whose rule names a category in ``relation`` (next_to, facing): its index and the
    indices of the objects of that category."""
    for k, it in enumerate(state.items):
        rule = program.objects.get(it.category)
        target = getattr(rule, relation) if rule is not None else None
        if target is not None:
            yield k, _of(state, target)


def next_to(program: Program, state: State) -> float:
    """Sum over objects with a ``next_to`` rule of their cost beside the best object of that category: the gap
    between the footprints (m, at most 2) plus the alignment of their facings (side by side, facing one way); 2.5
    when there is none."""
    total = 0.0
    for k, js in related(program, state, "next_to"):
        turn = (1 - np.cos(state.boxes[js, 6] - state.boxes[k, 6])) / 2
        total += float(np.min(np.minimum(gaps(state, k, js), 2.0) + turn)) if js else 2.5
    return total


def facing(program: Program, state: State) -> float:
    """Sum over objects with a ``facing`` rule of the alignment of their front towards the nearest object of that
    category plus half the gap to it (m, at most 2); 2 when there is none."""
    total = 0.0
    for k, js in related(program, state, "facing"):
        if not js:
            total += 2.0
            continue
        j = js[int(np.argmin(np.linalg.norm(state.boxes[js, :2] - state.boxes[k, :2], axis=1)))]
        d = state.boxes[j, :2] - state.boxes[k, :2]
        want = np.arctan2(-d[0], d[1])  # the yaw whose front points at the other object
        total += op.alignment_cost([state.boxes[k, 6]], [want]) + min(float(gaps(state, k, [j])[0]), 2.0) / 2
    return total


def front_strip(box: np.ndarray, reach: float) -> np.ndarray:
    """``(4, 2)`` corners of the floor strip ``reach`` m deep in front of a box's front face."""
    local = np.array([[-box[3], box[4]], [box[3], box[4]], [box[3], box[4] + reach], [-box[3], box[4] + reach]])
    return local @ gb.rotation(box[6]).T + box[:2]


def accessibility(reach: float, state: State) -> float:
    """Mean over floor and wall objects of Infinigen's accessibility cost of their front, over the other grounded
    objects (not their own children) whose footprint reaches into the strip ``reach`` m deep in front of it."""
    grounded = [k for k, it in enumerate(state.items) if it.parent < 0]
    if len(grounded) < 2:
        return 0.0
    b = state.boxes
    diag = 2 * np.hypot(b[:, 3], b[:, 4])
    polys = shapely.polygons(footprints(b))
    cost = 0.0
    for k in grounded:
        strip = shapely.Polygon(front_strip(b[k], reach))
        others = [j for j in grounded if j != k and shapely.area(shapely.intersection(polys[j], strip)) > AREA_EPS]
        front, normal = front_of(b[k])
        cost += op.accessibility_cost(front, normal, b[others, :2], diag[others], reach + float(diag.max()))
    return cost / len(grounded)


def alignment(state: State) -> float:
    """Infinigen's angle alignment of each free floor object with the nearest wall's axes (period 90 degrees)."""
    free = [k for k, it in enumerate(state.items) if it.dof == "floor"]
    if not free:
        return 0.0
    _, w = nearest_segment(state.boxes[free, :2], state.walls.segments)
    ref = [wall_yaw(state.walls, int(j)) for j in w]
    return op.alignment_cost(state.boxes[free, 6], ref, period=np.pi / 2)


def symmetry(program: Program, state: State) -> float:
    """Reflection asymmetry of each group of objects beside one anchor (their ``next_to`` category's nearest
    object), about the anchor's centre line."""
    groups: dict[int, list[int]] = {}
    for k, js in related(program, state, "next_to"):
        if js:
            j = js[int(np.argmin(np.linalg.norm(state.boxes[js, :2] - state.boxes[k, :2], axis=1)))]
            groups.setdefault(j, []).append(k)
    total = 0.0
    for j, ks in groups.items():
        if len(ks) >= 2:
            axis = front_of(state.boxes[j])[1]
            total += op.reflection_asymmetry(state.boxes[ks, :2], state.boxes[ks, 6], state.boxes[j, :2], axis)
    return total


def free_floor(walk: Walk, state: State) -> float:
    """1 - the walkable share of the evaluation's walkability measure (``walk``: its settings, a coarser cell)."""
    return 1.0 - walkability(state.as_room(), walk)["walkable_share"] if state.items else 0.0


def terms_of(program: Program, reach: float, walk: Walk) -> list[Term]:
    """The program's weighted soft terms."""
    fns = {"next_to": partial(next_to, program), "facing": partial(facing, program),
           "accessibility": partial(accessibility, reach), "alignment": alignment,
           "symmetry": partial(symmetry, program), "free_floor": partial(free_floor, walk)}
    return [Term(name, float(program.weights.get(name, 0.0)), fn) for name, fn in fns.items()]
