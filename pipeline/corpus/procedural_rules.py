"""The procedural generator's arrangement rules as checks over a relation graph (an oracle for generated graphs).

The generator (``procedural.py``) knows what it builds: beds against a wall between nightstands, lamps on
nightstands, TVs on stands facing sofas, desks against a wall with a chair in front, rows of units along walls...
Each rule below says whether one graph obeys one such habit. A rule applies to a graph only when the graph holds
the categories it speaks of. Graphs are given as ``categories`` (per node: a category, or wall / door / window)
and ``edges`` rows ``(source, target, kind)`` with kind 'support', '<direction>/<distance>' or an architecture kind.
"""
from __future__ import annotations

from typing import Callable

SURFACES = {"nightstand", "side_table", "dresser", "sideboard", "desk", "vanity", "kitchen_cabinet", "cabinet",
            "tv_stand", "dining_table", "round_table", "meeting_table"}
AGAINST_WALL = {"bed", "wardrobe", "toilet", "refrigerator", "kitchen_cabinet", "stove", "sink_cabinet", "dishwasher",
                "tv_stand", "vanity", "desk", "dresser", "sideboard", "pantry", "bathtub", "shower", "washing_machine",
                "dryer"}


def _near_wall(cats, edges, k) -> bool:
    return any(t == k and cats[s] == "wall" and kind == "front/adjacent" for s, t, kind in edges)


def _parent(cats, edges, k) -> str | None:
    return next((cats[s] for s, t, kind in edges if t == k and kind == "support"), None)


def _linked(edges, a, b, kinds=None) -> bool:
    return any({s, t} == {a, b} and (kinds is None or kind in kinds) for s, t, kind in edges)


def against_wall(cats, edges) -> bool | None:
    """Beds, wardrobes, desks, dressers, toilets, baths, kitchen and laundry units, TV stands and vanities stand against
    a wall (wall -> it, adjacent)."""
    ks = [k for k, c in enumerate(cats) if c in AGAINST_WALL]
    return all(_near_wall(cats, edges, k) for k in ks) if ks else None


def small_things_on_surfaces(cats, edges) -> bool | None:
    """Lamps, TVs, monitors, keyboards, laptops, vases and bowls stand on a surface (a support parent among tables,
    nightstands, dressers, cabinets, stands and desks)."""
    small = {"table_lamp", "tv", "monitor", "keyboard", "laptop", "vase", "fruit_bowl", "printer", "microwave", "kettle"}
    ks = [k for k, c in enumerate(cats) if c in small]
    return all(_parent(cats, edges, k) in SURFACES for k in ks) if ks else None


def nightstands_beside_bed(cats, edges) -> bool | None:
    """Every nightstand is adjacent to a bed, on its left or right."""
    beds = [k for k, c in enumerate(cats) if c == "bed"]
    ns = [k for k, c in enumerate(cats) if c == "nightstand"]
    if not beds or not ns:
        return None
    side = {"left/adjacent", "right/adjacent"}
    return all(any(_linked(edges, b, n, side) for b in beds) for n in ns)


def tv_on_stand(cats, edges) -> bool | None:
    """Every TV stands on a TV stand."""
    ks = [k for k, c in enumerate(cats) if c == "tv"]
    return all(_parent(cats, edges, k) == "tv_stand" for k in ks) if ks else None


def desk_with_chair(cats, edges) -> bool | None:
    """Every desk has a chair related to its front (either way)."""
    desks = [k for k, c in enumerate(cats) if c == "desk"]
    chairs = [k for k, c in enumerate(cats) if c in ("chair", "office_chair")]
    if not desks or not chairs:
        return None
    return all(any(_linked(edges, d, c) for c in chairs) for d in desks)


def chairs_at_tables(cats, edges) -> bool | None:
    """Every dining chair is related to a dining or round table."""
    tables = [k for k, c in enumerate(cats) if c in ("dining_table", "round_table")]
    chairs = [k for k, c in enumerate(cats) if c == "dining_chair"]
    if not tables or not chairs:
        return None
    return all(any(_linked(edges, t, c) for t in tables) for c in chairs)


RULES: dict[str, Callable] = {f.__name__: f for f in (against_wall, small_things_on_surfaces, nightstands_beside_bed,
                                                      tv_on_stand, desk_with_chair, chairs_at_tables)}


def satisfaction(graphs) -> dict[str, dict]:
    """Per rule: graphs it applies to and the share of them that obey it. ``graphs``: (categories, edges) pairs."""
    out = {}
    for name, rule in RULES.items():
        verdicts = [v for v in (rule(c, e) for c, e in graphs) if v is not None]
        out[name] = {"graphs": len(verdicts), "share": round(sum(verdicts) / len(verdicts), 4) if verdicts else None}
    return out
