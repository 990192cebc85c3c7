"""Functional checks learned from the training split and scored on any room by the same code: does every target
of a category stand where the training rooms put it around an anchor of another category (region, gap, facing;
``geometry/function.py``), does every object of a wall category stand with its back to a wall, and are the contents
plausible (no category more often than in any training room, no category missing that (nearly) every training room
holds). A check is kept only where the training rooms show it with confidence: the Wilson 95% lower bound of its
share of training rooms is at least ``min_share``."""
from __future__ import annotations

from dataclasses import asdict, dataclass
from itertools import product
from typing import Any, cast

import numpy as np

from ..geometry.function import REGIONS, back_to_wall, equivalent_regions, facing_angles, plan_gaps
from ..room import RoomInput
from ..room.contents import implausible, learn_contents, wilson_lower

REGION_SETS: dict[str, tuple[str, ...] | None] = {"any": None, "side": ("side_front", "side_back"),
                                                   **{r: (r,) for r in REGIONS if r != "corner"}}
FACINGS = ("any", "faces", "away")
ROOM_COLUMNS = ("contents_excess", "contents_missing", "functional_all")  # per room, in the eval_scenes table


@dataclass(frozen=True)
class Predicate:
    """Where a target stands around an anchor: a region name of :data:`REGION_SETS`, a gap (m, None: any) and a
    facing of :data:`FACINGS`."""
    region: str
    gap: float | None
    facing: str

    def specificity(self) -> int:
        return ((self.region != "any") + (self.region not in ("any", "side"))
                + (self.gap is not None) + (self.facing != "any"))

    def implies(self, other: "Predicate") -> bool:
        allowed = REGION_SETS[other.region]
        within = allowed is None or set(REGION_SETS[self.region] or REGIONS) <= set(allowed)
        return within and (other.gap is None or (self.gap is not None and self.gap <= other.gap)) and (
            other.facing in ("any", self.facing))


def vocabulary(cfg: dict[str, Any]) -> list[Predicate]:
    """Every predicate but the empty one (any region, any gap, any facing)."""
    return [Predicate(r, g, f) for r, g, f in product(REGION_SETS, [None, *sorted(cfg["gaps"])], FACINGS)
            if (r, g, f) != ("any", None, "any")]


def kinds(room: RoomInput, symmetry: dict[str, str] | None) -> list[str] | None:
    """Each object's symmetry type from the model -> type table (None without one: literal fronts)."""
    return None if symmetry is None else [symmetry.get(m, "none") for m in room.model_ids]


def predicate_masks(room: RoomInput, preds: list[Predicate], cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> np.ndarray:
    """``(p, n, n)`` bool: predicate ``p`` holds for target ``j`` around anchor ``i`` (never ``i == j``); the region
    holds in any frame a symmetric anchor cannot be told apart from, the facing counts a symmetric target's
    equivalent fronts (``symmetry``: model id -> type)."""
    n = len(room.object_ids)
    kind = kinds(room, symmetry)
    region, gap, angle = equivalent_regions(room.boxes, kind), plan_gaps(room.boxes), facing_angles(room.boxes, kind)
    lim = np.radians(cfg["facing_angle"])
    facing = {"any": np.ones((n, n), bool), "faces": angle <= lim, "away": angle >= np.pi - lim}
    out = np.empty((len(preds), n, n), bool)
    for k, p in enumerate(preds):
        allowed = REGION_SETS[p.region]
        where = np.ones((n, n), bool) if allowed is None else np.isin(region, [REGIONS.index(r) for r in allowed]).any(0)
        out[k] = where & (gap <= (np.inf if p.gap is None else p.gap)) & facing[p.facing]
    out[:, np.arange(n), np.arange(n)] = False
    return out


def pair_outcomes(room: RoomInput, masks: np.ndarray, anchor: str, target: str) -> np.ndarray | None:
    """``(p,)`` bool: every ``target`` of the room has an ``anchor`` for which the predicate holds (None: the room
    lacks one of the two categories)."""
    cats = np.asarray(room.categories)
    a, t = np.flatnonzero(cats == anchor), np.flatnonzero(cats == target)
    if not len(a) or not len(t) or (anchor == target and len(t) < 2):
        return None
    held = cast(np.ndarray, masks[:, a][:, :, t].any(axis=1))  # (p, targets): the target has such an anchor
    return cast(np.ndarray, held.all(axis=1))


def learn_pair_checks(rooms: list[RoomInput], cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> list[dict[str, Any]]:
    """The confident (anchor, target, predicate) checks of the training rooms: per category pair the most specific
    confident predicate (ties: the higher training share), the pairs held by the most rooms first."""
    preds = vocabulary(cfg)
    tally: dict[tuple[str, str], list[np.ndarray]] = {}
    for room in rooms:
        masks = predicate_masks(room, preds, cfg, symmetry)
        for a, t in product(sorted(set(room.categories)), repeat=2):
            outcome = pair_outcomes(room, masks, a, t)
            if outcome is not None:
                tally.setdefault((a, t), []).append(outcome)
    checks = []
    for (a, t), outcomes in tally.items():
        passed, total = np.sum(outcomes, axis=0), len(outcomes)
        if total < cfg["min_rooms"]:
            continue
        ok = [k for k in range(len(preds)) if wilson_lower(int(passed[k]), total) >= cfg["min_share"]]
        best = [k for k in ok if not any(preds[m] != preds[k] and preds[m].implies(preds[k]) for m in ok)]
        if best:
            k = max(best, key=lambda k: (preds[k].specificity(), passed[k], -k))
            checks.append({"kind": "pair", "anchor": a, "target": t, **asdict(preds[k]), "train_rooms": total,
                           "train_share": round(float(passed[k] / total), 4)})
    checks.sort(key=lambda c: (-c["train_rooms"], c["anchor"], c["target"]))
    return checks[:cfg["max_checks"]]


def wall_outcome(room: RoomInput, category: str, cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> bool | None:
    """Every object of ``category`` stands with its back (a symmetric object: any equivalent back) to a wall (None:
    the room has none)."""
    k = [i for i, c in enumerate(room.categories) if c == category]
    if not k:
        return None
    sym = kinds(room, symmetry)
    return bool(back_to_wall(room.boxes[k], room.outline, cfg["wall"]["max_gap"], np.radians(cfg["wall"]["max_angle"]),
                             None if sym is None else [sym[i] for i in k]).all())


def learn_wall_checks(rooms: list[RoomInput], cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> list[dict[str, Any]]:
    """The categories whose objects the training rooms confidently stand with their backs to a wall."""
    out = []
    for cat in sorted({c for r in rooms for c in r.categories}):
        seen = [o for o in (wall_outcome(r, cat, cfg, symmetry) for r in rooms) if o is not None]
        if len(seen) >= cfg["min_rooms"] and wilson_lower(sum(seen), len(seen)) >= cfg["min_share"]:
            out.append({"kind": "wall", "target": cat, "train_rooms": len(seen),
                        "train_share": round(sum(seen) / len(seen), 4)})
    return out


def learn_checks(rooms: list[RoomInput], cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> dict[str, Any]:
    """Everything the functional checks learn from the training rooms (JSON-ready; ``symmetry``: model id -> type,
    so that facing and back-to-wall count a symmetric object's equivalent fronts)."""
    return {"checks": learn_pair_checks(rooms, cfg, symmetry) + learn_wall_checks(rooms, cfg, symmetry),
            "contents": learn_contents((r.categories for r in rooms), cfg["min_share"]), "training_rooms": len(rooms)}


def check_name(check: dict[str, Any]) -> str:
    """A short column name: ``fn:<target>@<anchor>`` or ``fn:<target>@wall``."""
    return f"fn:{check['target']}@{check.get('anchor', 'wall')}"


def score_room(room: RoomInput, learned: dict[str, Any], cfg: dict[str, Any], symmetry: dict[str, str] | None = None) -> dict[str, Any]:
    """One room's outcome per check (1.0 pass, 0.0 fail, NaN where the room lacks its categories), its contents
    (``contents_excess``, ``contents_missing``) and ``functional_all`` (1.0: every applicable check passes)."""
    row: dict[str, float] = {}
    pair = [c for c in learned["checks"] if c["kind"] == "pair"]
    preds = [Predicate(c["region"], c["gap"], c["facing"]) for c in pair]
    masks = predicate_masks(room, preds, cfg, symmetry) if pair else None
    for k, c in enumerate(pair):
        assert masks is not None  # pair is not empty
        o = pair_outcomes(room, masks[k:k + 1], c["anchor"], c["target"])
        row[check_name(c)] = np.nan if o is None else float(o[0])
    for c in (c for c in learned["checks"] if c["kind"] == "wall"):
        w = wall_outcome(room, c["target"], cfg, symmetry)
        row[check_name(c)] = np.nan if w is None else float(w)
    outcomes = [v for v in row.values() if v == v]
    excess, missing = implausible(room.categories, learned["contents"])
    row["contents_excess"], row["contents_missing"] = float(bool(excess)), float(bool(missing))
    row["functional_all"] = float(all(v == 1.0 for v in outcomes) and row["contents_excess"] == 0.0 and row["contents_missing"] == 0.0)
    return row
