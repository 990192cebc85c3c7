"""Learning the S-AOG from a room type's training rooms (paper section 4): Set nodes (counts per category), sizes
(kernel density bandwidths), supported-supporter pairs (support parents), functional groups (hubs and their spokes
in the final graphs), distance and angle to the nearest wall, affordance maps, and the potentials' weights by
contrastive divergence (eq. 21) against rooms sampled under the current weights. Written as a YAML grammar."""
from __future__ import annotations

from collections import Counter

import numpy as np
import pandas as pd
import yaml

from ...geometry.polygon import nearest_segment
from ...placement.layout import walls_of
from ...placement.retrieval import Instance, ModelPool
from ...placement.support import learn_support_floor
from ...room import BOX_COLUMNS, POSE_COLUMNS, RoomInput
from ..solver.harness import limits_of
from ..solver.state import Item, State, empty_state, wall_yaw
from ..solver.terms import Hard
from .potentials import POTENTIALS, features
from .sample import sample_room
from .stats import affordance_map, contrastive_divergence, fit_lognormal, fit_size_kde, fit_von_mises_mixture, learn_set

NO_INSTANCE = Instance("", (0.1, 0.1, 0.1), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0), 0.0)


def real_state(room: RoomInput, parents: dict[str, str | None]) -> State:
    """A training room as a solver state (its boxes as they stand; parents by index)."""
    index = {o: k for k, o in enumerate(room.object_ids)}
    items = [Item(o, c, NO_INSTANCE, "floor", "all", (0.0, 0.0), parent=index.get(parents.get(o), -1))
             for o, c in zip(room.object_ids, room.categories)]
    base = empty_state(room, walls_of(room))
    return State(base.room, base.walls, items, room.boxes.reshape(-1, 7), room.poses.reshape(-1, 7))


def lognormal(x: np.ndarray, cfg: dict) -> dict:
    """A log-normal fit of distances (m) with the grammar's floors: distances below ``distance_floor`` read as it, and
    the log-scale spread is at least ``min_sigma`` (a category always flush against its wall would otherwise give an
    energy that no sampled room can approach)."""
    mu, sigma = fit_lognormal(x, floor=cfg["distance_floor"])
    return {"mu": mu, "sigma": max(sigma, cfg["min_sigma"]), "floor": cfg["distance_floor"]}


def wall_fits(states: list[State], cfg: dict) -> dict[str, dict]:
    """Per category of floor objects: log-normal of the back's distance to the nearest wall, von Mises mixture of
    the yaw relative to that wall's facing."""
    dist, angle = {}, {}
    for s in states:
        ks = [k for k, it in enumerate(s.items) if it.parent < 0]
        if not ks:
            continue
        d, w = nearest_segment(s.boxes[ks, :2], s.walls.segments)
        for i, k in enumerate(ks):
            c = s.items[k].category
            dist.setdefault(c, []).append(max(d[i] - s.boxes[k, 4], 0.0))
            angle.setdefault(c, []).append(s.boxes[k, 6] - wall_yaw(s.walls, int(w[i])))
    out = {}
    for c in dist:
        theta = np.array(angle[c])
        out[c] = {"wall_distance": lognormal(np.array(dist[c]), cfg),
                  "wall_angle": fit_von_mises_mixture(theta, k=min(cfg["vonmises_components"], len(theta)))}
    return out


def support_of(nodes: pd.DataFrame) -> dict[str, str]:
    """Category -> its support parent's category, where at least half its instances stand on one of that category."""
    cat = dict(zip(nodes["room_id"] + "/" + nodes["node_id"], nodes["category"].astype(str)))
    out = {}
    for c, g in nodes[nodes["kind"].astype(str) == "object"].groupby(nodes["category"].astype(str)):
        parents = [cat.get(f"{r}/{p}") for r, p in zip(g["room_id"], g["parent_id"]) if isinstance(p, str)]
        top = Counter(p for p in parents if p and p != c).most_common(1)
        if top and top[0][1] >= len(g) / 2:
            out[c] = top[0][0]
    return out


def groups_of(nodes: pd.DataFrame, cfg: dict) -> list[dict]:
    """Functional groups: (hub category, spoke category) pairs of the final graphs' hubs, with a log-normal of the
    spoke's centre distance to its hub."""
    role = nodes["role"].astype(str)
    hubs = nodes[role.str.contains("hub")].set_index(["room_id", "group_id"])
    dists: dict[tuple[str, str], list[float]] = {}
    for _, sp in nodes[role.str.contains("spoke")].iterrows():
        key = (sp["room_id"], sp["group_id"])
        if key not in hubs.index:
            continue
        hub = hubs.loc[key]
        hub = hub.iloc[0] if isinstance(hub, pd.DataFrame) else hub
        dists.setdefault((str(hub["category"]), str(sp["category"])), []).append(
            float(np.hypot(sp["cx"] - hub["cx"], sp["cy"] - hub["cy"])))
    return [{"hub": h, "spoke": s, **lognormal(np.array(d), cfg)} for (h, s), d in sorted(dists.items()) if len(d) >= 2]


def affordances(states: list[State], cfg: dict) -> dict:
    """Per category: where the humans (centres of ``cfg['humans']`` categories) stand in its frame (20 x 20 bins)."""
    from ...geometry.boxes import to_local
    pts: dict[str, list] = {}
    for s in states:
        humans = [k for k, it in enumerate(s.items) if it.category in cfg["humans"]]
        for k, it in enumerate(s.items):
            others = [j for j in humans if j != k]
            if others:
                pts.setdefault(it.category, []).append(to_local(s.boxes[others, :2], *s.boxes[k, [0, 1, 6]]))
    maps = {c: np.round(affordance_map(np.concatenate(p), cfg["bins"], cfg["extent"]), 6).tolist()
            for c, p in sorted(pts.items())}
    return {"humans": list(cfg["humans"]), "extent": cfg["extent"], "maps": maps}


def pool_of(rooms: list[RoomInput]) -> ModelPool:
    """The training rooms' objects as a model pool (sizes and models for the sampled rooms)."""
    rows = [{"category": c, "model_id": m, **dict(zip(BOX_COLUMNS, b)), **dict(zip(POSE_COLUMNS, p))}
            for r in rooms for c, m, b, p in zip(r.categories, r.model_ids, r.boxes, r.poses)]
    frame = pd.DataFrame(rows, columns=["category", "model_id", *BOX_COLUMNS, "px", "py", "pz", "sx", "sy", "sz"])
    return ModelPool(frame, {})


def child_counts(states: list[State], category: str, parent: str | None) -> np.ndarray:
    """``(n,)`` the category's count per training room; for a supported category (``parent``: its support's
    category), over the rooms that hold its parent only: its Set node hangs under the parent's in the parse tree,
    which draws it only where a parent was drawn (learned over every room, a monitor's count would be drawn
    independently of the desk's and zeroed without one: 0.07 monitors per sampled bedroom against 0.44)."""
    rooms = [s for s in states if parent is None or s.count(parent) > 0] or states
    return np.array([s.count(category) for s in rooms])


def grammar_of(room_type: str, states: list[State], nodes: pd.DataFrame, cfg: dict) -> dict:
    """Every piece of the grammar but the weights."""
    cats = sorted({it.category for s in states for it in s.items})
    walls, support = wall_fits(states, cfg), support_of(nodes)
    out = {}
    for c in cats:
        halves = np.array([s.boxes[k, 3:6] for s in states for k, it in enumerate(s.items) if it.category == c])
        parent = support[c] if c in support and support[c] in cats else None
        node = {"count": learn_set(child_counts(states, c, parent)),
                "size_bandwidth": [round(float(v), 5) for v in fit_size_kde(halves)["bandwidth"]]}
        if parent is not None:
            node["on"] = parent
        elif c in walls:
            node |= walls[c]
        out[c] = node
    return {"room_type": room_type, "categories": out, "groups": groups_of(nodes, cfg),
            "affordance": affordances(states, cfg["affordance"])}


def per_object(f: np.ndarray, state: State) -> np.ndarray:
    """A room's potentials per object: contrastive divergence's gradient on rooms of any size (a departure)."""
    return f / max(len(state.items), 1)


def learn_weights(grammar: dict, states: list[State], rooms: list[RoomInput], pool: ModelPool, config: dict,
                  seed: int) -> tuple[dict, list[dict]]:
    """Contrastive divergence from the configured initial weights: the potentials of the training rooms against
    those of rooms sampled under the current weights in the training architectures (short chains)."""
    cfg = config["saog"]
    preset = cfg["presets"][cfg["preset"]]
    data = np.array([per_object(features(s, grammar), s) for s in states])
    limits = limits_of(config, learn_support_floor(rooms, config["instantiate"]["checks"], config["floor_contact"]))

    def sample_features(w: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        weights = dict(zip(POTENTIALS, w))
        out = []
        for k in rng.choice(len(rooms), size=preset["cd_samples"]):
            state = empty_state(rooms[k], walls_of(rooms[k]))
            chain = sample_room(grammar, weights, (state, Hard(state, limits)), pool, cfg, max(preset["steps"] // 10, 10), rng)
            out.append(per_object(features(chain.best, grammar), chain.best))
        return np.array(out)

    w0 = np.array([cfg["initial_weights"][p] for p in POTENTIALS], float)
    if preset["cd_iters"] == 0:
        return dict(zip(POTENTIALS, w0.tolist())), []
    w, history = contrastive_divergence(data, sample_features, w0, cfg["cd_lr"], preset["cd_iters"], cfg["cd_tol"],
                                        seed)
    return {p: round(float(v), 5) for p, v in zip(POTENTIALS, w)}, history


def fit_grammar(config: dict, room_type: str, nodes: pd.DataFrame, edges: pd.DataFrame, inputs: dict,
                split: dict[str, str]) -> tuple[str, dict]:
    """The ``learn_program`` entry (``PROGRAM_LEARNERS['saog']``): the grammar as YAML text and a summary."""
    ids = sorted(r for r, s in split.items() if s in ("fit", "validation") and r in inputs)
    rooms = [inputs[r] for r in ids]
    train = nodes[nodes["room_id"].isin(ids)]
    parents = {f"{r}/{n}": p if isinstance(p, str) else None
               for r, n, p in zip(train["room_id"], train["node_id"], train["parent_id"])}
    states = [real_state(r, {o: parents.get(f"{r.room_id}/{o}") for o in r.object_ids}) for r in rooms]
    grammar = grammar_of(room_type, states, train, config["saog"])
    weights, history = learn_weights(grammar, states, rooms, pool_of(rooms), config, config["seed"])
    grammar["weights"] = weights
    header = (f"# S-AOG grammar of {room_type}, learned from {len(rooms)} training rooms by planit learn_program "
              "(Qi et al. 2018, sections 3-4).\n# categories: Set nodes (count distribution), size kernel bandwidths "
              "(m), support parent (on) or wall distance (log-normal) and angle (von Mises mixture);\n# groups: hub -> "
              "spoke distances (log-normal); affordance: where seats and beds stand in each object's frame; weights: "
              "contrastive divergence.\n")
    text = header + yaml.dump(to_plain(grammar), Dumper=getattr(yaml, "CSafeDumper", yaml.SafeDumper), sort_keys=False,
                               default_flow_style=None, width=120)
    return text, {"room_type": room_type, "training_rooms": len(rooms), "categories": len(grammar["categories"]),
                  "groups": len(grammar["groups"]), "weights": weights, "cd_history": history}


def to_plain(value):
    """NumPy scalars and arrays as plain Python (for YAML)."""
    if isinstance(value, dict):
        return {str(k): to_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [to_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value
