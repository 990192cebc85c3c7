"""Deriving a room type's Infinigen-style program from the training split's final relation graphs (``final_nodes``
and ``final_edges`` tables): which categories, how many, which stage, and the relations each keeps, every choice a
share of the training rooms or instances against a threshold of ``infinigen.derive`` in the config. Only rooms of
the room type whose split is ``fit`` or ``validation`` are read, and only kept edges (support edges always).

What the graph tables say, as read here (checked on the AI2-THOR final graphs):

* **against a wall**: a ``spatial`` edge from a ``wall`` node (source) to the object with ``distance`` adjacent. A
  wall's edges all point ``front`` (into the room, the wall's front), and the refinement keeps every adjacent wall
  edge (rule ``keep_wall_adjacent``) while it prunes most proximal and distant ones, so adjacency is the signal.
* **on**: a ``support`` edge, source = the support parent, target = the object.
* **next to**: the object is a ``spoke`` of a hub of that category (``role`` / ``group_id`` of the nodes), or failing
  that, an object of that category anchors an adjacent ``left`` / ``right`` spatial edge to it (it stands beside it).
* **facing**: an object of that category anchors an adjacent or proximal ``front`` spatial edge to it (the object
  stands in front of the anchor, as a chair before a desk); never its next_to category nor its support parent.

No torch."""
from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pandas as pd

from ...errors import InputError
from .program import DEFAULT_WEIGHTS, STAGES, ObjectRule, Program, Recipe, dump_program

CFG_KEYS = ("count_percentiles", "min_room_share", "against_wall_share", "support_share", "next_to_share",
            "facing_share", "stage_areas", "recipes")
TRAINING = ("fit", "validation")
Key = tuple[str, str]  # (room_id, node_id): one object instance


# ---------------------------------------------------------------- the training rooms' tables

def _check_cfg(cfg: dict) -> None:
    """Every derivation setting is present (they live in config under ``infinigen.derive``)."""
    missing = [k for k in CFG_KEYS if k not in cfg]
    if missing:
        raise InputError(f"infinigen.derive: missing setting(s) {', '.join(missing)}")


def training_rooms(nodes: pd.DataFrame, split: dict[str, str], room_type: str) -> list[str]:
    """The sorted ids of the room type's rooms whose split is fit or validation."""
    ids = nodes.loc[nodes["room_type"].astype(object) == room_type, "room_id"].unique()
    return sorted(r for r in ids if split.get(r) in TRAINING)


def _objects(nodes: pd.DataFrame, rooms: list[str]) -> pd.DataFrame:
    """The training rooms' object nodes: room_id, node_id, category, role, group_id, area (footprint, m^2)."""
    obj = nodes[nodes["room_id"].isin(rooms) & (nodes["kind"].astype(object) == "object")]
    out = pd.DataFrame({"room_id": obj["room_id"].astype(str), "node_id": obj["node_id"].astype(str),
                        "category": obj["category"].astype(str),
                        "role": obj["role"].astype(object).fillna("none").astype(str),
                        "group_id": obj["group_id"].astype(object),
                        "area": 4.0 * obj["hx"].astype(float) * obj["hy"].astype(float)})
    return out.reset_index(drop=True)


def _links(edges: pd.DataFrame, nodes: pd.DataFrame, rooms: list[str]) -> pd.DataFrame:
    """The training rooms' kept and support edges with the source's kind and category and the target's category."""
    if "status" not in edges.columns:
        raise InputError("edges: status: missing (derivation reads the final graph tables)")
    e = edges[edges["room_id"].isin(rooms)]
    e = e[(e["status"].astype(object) == "kept") | (e["edge_type"].astype(object) == "support")]
    cols = ["edge_type", "direction", "distance"]
    out = pd.DataFrame({"room_id": e["room_id"].astype(str), "source": e["source"].astype(str),
                        "target": e["target"].astype(str), **{c: e[c].astype(object) for c in cols}})
    info = pd.DataFrame({"room_id": nodes["room_id"].astype(str), "node_id": nodes["node_id"].astype(str),
                         "kind": nodes["kind"].astype(str), "category": nodes["category"].astype(str)})
    out = out.merge(info.rename(columns={"node_id": "source", "kind": "source_kind", "category": "source_category"}),
                    on=["room_id", "source"], how="left")
    return out.merge(info[["room_id", "node_id", "category"]].rename(
        columns={"node_id": "target", "category": "target_category"}), on=["room_id", "target"], how="left")


# ---------------------------------------------------------------- per-instance relations

def _anchors(links: pd.DataFrame) -> dict[Key, set[str]]:
    """Target instance -> the categories of the anchors of the given edges."""
    out: dict[Key, set[str]] = {}
    for room, target, category in zip(links["room_id"], links["target"], links["source_category"]):
        out.setdefault((room, target), set()).add(category)
    return out


def _wall_targets(links: pd.DataFrame) -> set[Key]:
    """Instances standing against a wall: the target of an adjacent spatial edge from a wall (direction front)."""
    m = ((links["source_kind"] == "wall") & (links["edge_type"] == "spatial") & (links["distance"] == "adjacent")
         & (links["direction"] == "front"))
    return set(zip(links.loc[m, "room_id"], links.loc[m, "target"]))


def _support_parents(links: pd.DataFrame) -> dict[Key, set[str]]:
    """Instance -> the category of its support parent (support edges: source = parent)."""
    return _anchors(links[(links["edge_type"] == "support") & (links["source_kind"] == "object")])


def _hub_of(objects: pd.DataFrame) -> dict[Key, set[str]]:
    """Spoke instance -> the category of its hub (same room and group_id)."""
    roles = objects["role"].str.split("+")
    hubs = objects[roles.apply(lambda r: "hub" in r)]
    hub_cat = {(r, g): c for r, g, c in zip(hubs["room_id"], hubs["group_id"], hubs["category"])}
    spokes = objects[roles.apply(lambda r: "spoke" in r)]
    return {(r, n): {hub_cat[(r, g)]} for r, n, g in zip(spokes["room_id"], spokes["node_id"], spokes["group_id"])
            if (r, g) in hub_cat}


def _beside(objects: pd.DataFrame, links: pd.DataFrame) -> dict[Key, set[str]]:
    """Instance -> the categories it stands beside: its hub's if it is a spoke of another category's hub, failing
    that the anchors of adjacent left / right spatial edges to it (objects of its own category left out)."""
    own = dict(zip(zip(objects["room_id"], objects["node_id"]), objects["category"]))
    m = ((links["source_kind"] == "object") & (links["edge_type"] == "spatial") & (links["distance"] == "adjacent")
         & links["direction"].isin(["left", "right"]))
    side, hub = _anchors(links[m]), _hub_of(objects)
    out = {}
    for key, category in own.items():
        cats = hub.get(key, set()) - {category} or side.get(key, set()) - {category}
        if cats:
            out[key] = cats
    return out


def _in_front_of(links: pd.DataFrame) -> dict[Key, set[str]]:
    """Instance -> the categories of the anchors of adjacent or proximal front spatial edges to it."""
    m = ((links["source_kind"] == "object") & (links["edge_type"] == "spatial") & (links["direction"] == "front")
         & links["distance"].isin(["adjacent", "proximal"]))
    return _anchors(links[m])


def _best(instances: list[Key], sets: dict[Key, set[str]], exclude: str) -> tuple[str | None, float]:
    """The category most of ``instances`` relate to (never ``exclude``; ties by name) and that share of them."""
    tally = Counter(c for key in instances for c in sets.get(key, ()) if c != exclude)
    if not tally or not instances:
        return None, 0.0
    category, n = min(tally.items(), key=lambda kv: (-kv[1], kv[0]))
    return category, n / len(instances)


# ---------------------------------------------------------------- per-category statistics

def _count_range(per_room: pd.Series, percentiles: list[float]) -> tuple[tuple[int, int], list[float]]:
    """(min, max) instances per room from percentiles of the per-room counts (zeros included): min floored, max
    ceiled and at least 1; and the raw percentile values."""
    low, high = (float(np.percentile(per_room.to_numpy(dtype=float), p)) for p in percentiles)
    lo, hi = math.floor(low + 1e-9), max(1, math.ceil(high - 1e-9))
    return (min(lo, hi), hi), [round(low, 3), round(high, 3)]


def _stage(area: float, areas: list[float]) -> str:
    """small below the first area, medium below the second, else large."""
    return STAGES[2] if area < areas[0] else STAGES[1] if area < areas[1] else STAGES[0]


def room_counts(objects: pd.DataFrame, rooms: list[str]) -> pd.DataFrame:
    """``(rooms, categories)`` instances of each category in each training room (0 where none)."""
    return pd.crosstab(objects["room_id"], objects["category"]).reindex(rooms, fill_value=0)


def count_percentiles(cfg: dict) -> list[float]:
    """The percentiles of the per-room counts a count range spans: with recipes the whole range (0, 100), so that no
    recipe is cut by its rules; else ``count_percentiles``."""
    return [0, 100] if cfg["recipes"] else list(cfg["count_percentiles"])


def _category_stats(objects: pd.DataFrame, links: pd.DataFrame, counts: pd.DataFrame, cfg: dict) -> dict[str, dict]:
    """Category -> the statistics behind every choice, before the choices are reconciled across categories
    (``counts``: :func:`room_counts`)."""
    walls, parents = _wall_targets(links), _support_parents(links)
    beside, front = _beside(objects, links), _in_front_of(links)
    out = {}
    for category, group in objects.groupby("category", sort=True):
        keys = list(zip(group["room_id"], group["node_id"]))
        count, raw = _count_range(counts[category], count_percentiles(cfg))
        out[category] = {
            "rooms_share": round(float((counts[category] > 0).mean()), 3), "instances": len(keys),
            "count_percentiles": raw, "count": list(count),
            "wall_share": round(sum(k in walls for k in keys) / len(keys), 3),
            "median_area": round(float(group["area"].median()), 3),
            "support": _choice(*_best(keys, parents, category)),
            "next_to": _choice(*_best(keys, beside, category)),
            "facing": _choice(*_best(keys, front, category))}
    return out


def _choice(category: str | None, share: float) -> dict:
    """A candidate relation as the ``why`` dict records it (``kept`` is decided later)."""
    return {"category": category, "share": round(share, 3), "kept": False}


def recipes_of(counts: pd.DataFrame, members: list[str]) -> list[Recipe]:
    """The training rooms' contents over the program's categories (``counts``: :func:`room_counts`), each distinct
    count vector once with the rooms that held it (most rooms first, then by counts)."""
    tally = Counter(tuple(int(n) for n in row) for row in counts[members].to_numpy())
    ranked = sorted(tally.items(), key=lambda kv: (-kv[1], [-n for n in kv[0]]))
    return [Recipe(n, {c: k for c, k in zip(members, vec) if k > 0}) for vec, n in ranked]


# ---------------------------------------------------------------- choices

def _decide_support(why: dict[str, dict], members: list[str], threshold: float) -> dict[str, str]:
    """Category -> support parent category: strongest shares first, a parent outside the program or one that would
    close a support cycle is dropped."""
    on: dict[str, str] = {}
    ranked = sorted(members, key=lambda c: (-why[c]["support"]["share"], c))
    for cat in ranked:
        cand = why[cat]["support"]
        parent = cand["category"]
        if parent is None or parent not in members or cand["share"] < threshold:
            continue
        chain = parent
        while chain is not None and chain != cat:
            chain = on.get(chain)
        if chain == cat:
            cand["dropped"] = "support cycle"
            continue
        on[cat], cand["kept"] = parent, True
    return on


def _decide(cand: dict, members: list[str], threshold: float, exclude: dict[str, str] | None = None) -> str | None:
    """A candidate relation's category when its share passes ``threshold``, it is in the program and not a key of
    ``exclude`` (category -> why not); None otherwise (the reason is noted in ``cand``)."""
    if cand["category"] is None or cand["share"] < threshold:
        return None
    if cand["category"] not in members:
        cand["dropped"] = "not in the program"
        return None
    if cand["category"] in (exclude or {}):
        cand["dropped"] = exclude[cand["category"]]
        return None
    cand["kept"] = True
    return cand["category"]


def _rules(why: dict[str, dict], members: list[str], cfg: dict) -> list[ObjectRule]:
    """The program's object rules, ordered large, medium, small and then by category."""
    on = _decide_support(why, members, cfg["support_share"])
    rules = []
    for cat in members:
        w = why[cat]
        next_to = _decide(w["next_to"], members, cfg["next_to_share"])
        facing = _decide(w["facing"], members, cfg["facing_share"],
                         exclude={next_to: "it is the next_to category", on.get(cat): "it is the support parent"})
        stage = STAGES[2] if cat in on else _stage(w["median_area"], cfg["stage_areas"])
        w["stage"] = stage
        rules.append(ObjectRule(category=cat, count=tuple(w["count"]), stage=stage,
                                against_wall=w["wall_share"] >= cfg["against_wall_share"], on=on.get(cat),
                                next_to=next_to, facing=facing))
    return sorted(rules, key=lambda r: (STAGES.index(r.stage), r.category))


def derive_program(nodes: pd.DataFrame, edges: pd.DataFrame, split: dict[str, str], room_type: str,
                   cfg: dict) -> tuple[Program, dict]:
    """The room type's program from its training rooms' final graphs, and ``why``: category -> the statistics
    behind each choice (every category seen in a training room; ``in_program`` says whether it made it)."""
    _check_cfg(cfg)
    rooms = training_rooms(nodes, split, room_type)
    if not rooms:
        raise InputError(f"room type '{room_type}': no training (fit or validation) room to derive a program from")
    objects = _objects(nodes, rooms)
    counts = room_counts(objects, rooms)
    why = _category_stats(objects, _links(edges, nodes, rooms), counts, cfg)
    members = sorted(c for c, w in why.items() if w["rooms_share"] >= cfg["min_room_share"])
    if not members:
        raise InputError(f"room type '{room_type}': no category occurs in {cfg['min_room_share']} of the "
                         f"{len(rooms)} training rooms (infinigen.derive.min_room_share)")
    for cat, w in why.items():
        w["in_program"] = cat in members
    rules = _rules(why, members, cfg)
    program = Program(room_type=room_type, objects={r.category: r for r in rules}, weights=dict(DEFAULT_WEIGHTS),
                      source=f"derived:{room_type}", recipes=recipes_of(counts, members) if cfg["recipes"] else [])
    return program, why


def program_header(room_type: str, n_rooms: int, cfg: dict) -> list[str]:
    """Comment lines for a derived program file: what derived it, from what, the thresholds, how to pass it back."""
    shares = (f"against_wall {cfg['against_wall_share']}, on {cfg['support_share']}, "
              f"next_to {cfg['next_to_share']}, facing {cfg['facing_share']}")
    return [
        (f"{room_type}: Infinigen-style program derived by pipeline.methods.infinigen.derive from the relation "
         f"graphs of {n_rooms} training rooms (fit + validation)."),
        (f"Thresholds (infinigen.derive): count = percentiles {count_percentiles(cfg)} of per-room counts; "
         f"room share >= {cfg['min_room_share']}; instance shares >= {shares}; "
         f"stage by median footprint, m^2 {list(cfg['stage_areas'])}."),
        ("Fields: count [min, max] per room; stage large | medium | small; against_wall; on / next_to / facing "
         "name a category of this program; weights of the soft terms; recipes: the training rooms' contents as "
         "wholes (a scene draws one, in proportion to its rooms; without recipes each count is drawn in its range)."),
        "Edit and pass back with: planit generate --method infinigen --program FILE",
    ]


def fit_program(config: dict, room_type: str, nodes: pd.DataFrame, edges: pd.DataFrame, inputs: dict,
                split: dict[str, str]) -> tuple[str, dict]:
    """The ``learn_program`` entry (``PROGRAM_LEARNERS['infinigen']``): the derived program as YAML text with its
    header, and a summary of the statistics behind each choice."""
    cfg = config["infinigen"]["derive"]
    program, why = derive_program(nodes, edges, split, room_type, cfg)
    rooms = training_rooms(nodes, split, room_type)
    text = dump_program(program, program_header(room_type, len(rooms), cfg))
    return text, {"room_type": room_type, "training_rooms": len(rooms), "objects": len(program.objects),
                  "derive": cfg, "why": why}
