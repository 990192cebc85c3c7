"""S-AOG's potentials over a solver state (paper section 3, the terms its released code keeps, plus the affordance
term): distance to the nearest wall (log-normal) and orientation relative to it (von Mises mixture) per category,
the distance of a functional group's members to their hub (log-normal), and the affordance of each object where
the room's "humans" (the centres of seats and beds) stand. Each is an energy: a negative log density summed over
objects. Collisions, the floor's outline and door clearances are hard (``solver.terms``)."""
from __future__ import annotations

import numpy as np

from ...geometry.boxes import to_local
from ...geometry.polygon import nearest_segment
from ..solver.state import State, wall_yaw
from ..solver.terms import Term
from .stats import affordance_energy, lognormal_energy, von_mises_energy

POTENTIALS = ("wall_distance", "wall_angle", "group", "affordance")


def wall_features(state: State, grammar: dict) -> tuple[float, float]:
    """The wall-distance and wall-angle energies of the floor objects whose category the grammar fits."""
    cats = grammar["categories"]
    ks = [k for k, it in enumerate(state.items) if it.parent < 0 and "wall_distance" in cats.get(it.category, {})]
    if not ks:
        return 0.0, 0.0
    b = state.boxes[ks]
    dist, w = nearest_segment(b[:, :2], state.walls.segments)
    back = np.maximum(dist - b[:, 4], 0.0)
    angle = b[:, 6] - np.array([wall_yaw(state.walls, int(j)) for j in w])
    dist_e = sum(float(lognormal_energy(back[i], **cats[state.items[k].category]["wall_distance"]))
                 for i, k in enumerate(ks))
    angle_e = sum(float(von_mises_energy(np.array([angle[i]]), cats[state.items[k].category]["wall_angle"])[0])
                  for i, k in enumerate(ks))
    return dist_e, angle_e


def group_feature(state: State, grammar: dict) -> float:
    """Each group member's log-normal distance energy to the nearest object of its hub category."""
    total = 0.0
    for g in grammar["groups"]:
        hubs = [k for k, it in enumerate(state.items) if it.category == g["hub"]]
        if not hubs:
            continue
        for k, it in enumerate(state.items):
            if it.category == g["spoke"]:
                d = np.linalg.norm(state.boxes[hubs, :2] - state.boxes[k, :2], axis=1).min()
                total += float(lognormal_energy(d, g["mu"], g["sigma"], g.get("floor", 1e-3)))
    return total


def affordance_feature(state: State, grammar: dict) -> float:
    """Each object with an affordance map: the energy of the best-placed human (seat or bed centre) in its frame."""
    aff = grammar["affordance"]
    humans = [k for k, it in enumerate(state.items) if it.category in aff["humans"]]
    total = 0.0
    for k, it in enumerate(state.items):
        amap = aff["maps"].get(it.category)
        others = [j for j in humans if j != k]
        if amap is None or not others:
            continue
        local = to_local(state.boxes[others, :2], *state.boxes[k, [0, 1, 6]])
        total += affordance_energy(np.asarray(amap), local, extent=aff["extent"])
    return total


def features(state: State, grammar: dict) -> np.ndarray:
    """``(4,)`` the potentials (POTENTIALS order) of a state."""
    dist_e, angle_e = wall_features(state, grammar)
    return np.array([dist_e, angle_e, group_feature(state, grammar), affordance_feature(state, grammar)])


def terms_of(grammar: dict, weights: dict) -> list[Term]:
    """The weighted potentials as solver terms (the two wall terms share one pass over the state)."""
    last: dict = {}

    def walls(s: State) -> tuple[float, float]:
        if last.get("state") is not s:
            last.update(state=s, value=wall_features(s, grammar))
        return last["value"]

    fns = {"wall_distance": lambda s: walls(s)[0], "wall_angle": lambda s: walls(s)[1],
           "group": lambda s: group_feature(s, grammar), "affordance": lambda s: affordance_feature(s, grammar)}
    return [Term(name, float(weights[name]), fns[name]) for name in POTENTIALS]
