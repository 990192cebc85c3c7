"""Scores of extracted graphs against a source's ground-truth relations. Pure functions over DataFrames."""
from __future__ import annotations

from collections import Counter

import pandas as pd


def extraction_counts(nodes: pd.DataFrame, edges: pd.DataFrame, gt: pd.DataFrame) -> Counter:
    """The integer counts behind the extraction scores for one set of rooms (sums over shards stay exact)."""
    objs = nodes[nodes["kind"].astype(str) == "object"][["room_id", "node_id", "parent_id"]]
    truth = gt[gt["relation"].astype(str) == "support"][["room_id", "anchor_id", "target_id"]]
    truth = truth.rename(columns={"anchor_id": "true_parent", "target_id": "node_id"})
    merged = objs.merge(truth, on=["room_id", "node_id"], how="left")
    got = merged["parent_id"].astype(object).where(merged["parent_id"].notna(), None)
    want = merged["true_parent"].astype(object).where(merged["true_parent"].notna(), None)
    correct = (got == want) | (got.isna() & want.isna())
    supported = want.notna()
    adjacent = gt[gt["relation"].astype(str) == "adjacent"][["room_id", "anchor_id", "target_id", "direction", "label"]]
    sp = edges[edges["edge_type"].astype(str) == "spatial"][["room_id", "source", "target", "direction", "distance"]]
    pairs = adjacent.merge(sp.rename(columns={"source": "anchor_id", "target": "target_id", "direction": "got_direction"}),
                           on=["room_id", "anchor_id", "target_id"], how="left")
    found = pairs["distance"].astype(str) == "adjacent"
    same_dir = found & (pairs["got_direction"].astype(str) == pairs["direction"].astype(str))
    case = pairs["label"].astype(object).fillna("unlabelled").astype(str)
    per_case = {**{f"intended:{c}": int(v) for c, v in case.value_counts().items()},
                **{f"found:{c}": int(v) for c, v in found.groupby(case).sum().items()}}
    return Counter({**per_case, "rooms": int(nodes["room_id"].nunique()), "objects": len(merged), "correct": int(correct.sum()),
                    "supported": int(supported.sum()), "correct_supported": int((correct & supported).sum()),
                    "intended": len(pairs), "found": int(found.sum()), "same_dir": int(same_dir.sum()),
                    "any_edge": int(pairs["distance"].notna().sum())})


def extraction_scores(c: Counter) -> dict:
    """Support-parent accuracy (every object: GT parent or floor) and recall (supported objects); recall of intended
    adjacent relations as extracted adjacent spatial edges, and direction agreement."""
    return {"rooms": c["rooms"], "objects": c["objects"], "support_parent_accuracy": _ratio(c["correct"], c["objects"]),
            "supported_objects": c["supported"], "support_parent_recall": _ratio(c["correct_supported"], c["supported"]),
            "intended_adjacent": c["intended"], "adjacent_recall": _ratio(c["found"], c["intended"]),
            "adjacent_direction_agreement": _ratio(c["same_dir"], c["found"]),
            "intended_pairs_with_any_edge": _ratio(c["any_edge"], c["intended"]),
            "adjacent_recall_by_case": _by_case(c)}


def _by_case(c: Counter) -> dict:
    """Adjacent recall per placement case of the ground truth (gap, flush, overlap, turned; unlabelled sources)."""
    cases = sorted(k.split(":", 1)[1] for k in c if k.startswith("intended:"))
    return {case: {"intended": c[f"intended:{case}"], "recall": _ratio(c[f"found:{case}"], c[f"intended:{case}"])}
            for case in cases}


def _ratio(a, b) -> float | None:
    return round(float(a) / float(b), 4) if b else None


def _groups(frame: pd.DataFrame, anchor: str, member: str) -> set[tuple]:
    """(room, anchor, frozenset of members) per group."""
    out = set()
    for (room, _), g in frame.groupby(["room_id", "group_id"]):
        out.add((room, g[anchor].iloc[0], frozenset(g[member])))
    return out


def superstructure_scores(supers: pd.DataFrame, gt: pd.DataFrame) -> dict:
    """Hub and chain precision / recall against the generator's groups (exact hub + spoke set, exact chain member set)."""
    out = {}
    for kind in ("hub", "chain"):
        truth = gt[gt["relation"].astype(str) == kind]
        found = supers[supers["kind"].astype(str) == kind]
        t = _groups(truth, "anchor_id", "target_id") if len(truth) else set()
        f = _groups(found, "anchor_id", "member_id") if len(found) else set()
        if kind == "chain":  # a chain is the same whichever end it is read from
            t = {(r, m) for r, _, m in t}
            f = {(r, m) for r, _, m in f}
        hit = len(t & f)
        out[f"{kind}s_true"] = len(t)
        out[f"{kind}s_found"] = len(f)
        out[f"{kind}_precision"] = _ratio(hit, len(f)) if t else None  # a source without such ground truth scores nothing
        out[f"{kind}_recall"] = _ratio(hit, len(t))
    return out
