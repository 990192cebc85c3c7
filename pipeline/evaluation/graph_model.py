"""The metrics of a room type's generated relation graphs: held-out NLL, generated vs held-out real graphs beside the
sampling floor (fit graphs against held-out ones), validity, novelty, uniqueness and (procedural corpus) the
generator's own arrangement rules. Any graph generator's graphs are scored by this one function."""
from __future__ import annotations

from typing import Any

from ..corpus.procedural_rules import satisfaction
from ..graphs.data import EDGE_CLASSES, Graph, Vocab
from ..seeding import rng_for
from . import graphs as gm

# the quality goals: each distance within this factor of its floor
FLOOR_FACTOR = 1.5


def _rule_view(g: Graph, vocab: Vocab) -> tuple[list[str], list[tuple[int, int, str]]]:
    """(categories, edges with kind names) of a graph, for the procedural rules."""
    cats = [vocab.node_classes[c] for c in g.node_class]
    return cats, [(int(s), int(t), EDGE_CLASSES[int(c)]) for s, t, c in g.edges]


def graph_model_metrics(config: dict[str, Any], room_type: str, vocab: Vocab, sets: dict[str, list[Graph]],
                        heldout_nll: dict[str, Any] | None, valid_before_rejection: float) -> dict[str, Any]:
    """The metrics and goals of one room type's generated graphs against its held-out real graphs; ``sets``: the
    ``real`` graphs (all), the ``train`` and ``heldout`` ones and the ``generated`` ones."""
    real, train, held, gen = sets["real"], sets["train"], sets["heldout"], sets["generated"]
    rng = rng_for(config["seed"], "graph-floor")
    floor_set = [train[i] for i in rng.permutation(len(train))[:min(len(gen) or len(train), len(train))]]
    floor = gm.distances(held, floor_set)
    got = gm.distances(held, gen) if gen else {k: None for k in floor}  # nothing valid was sampled
    out = {
        "room_type": room_type, "graphs": {"train": len(train), "heldout": len(held), "generated": len(gen),
                                           "floor_sample": len(floor_set)},
        "heldout_nll": heldout_nll,  # the chosen epoch's, scored once after training
        "generated_vs_heldout": _rounded(got), "floor_real_vs_heldout": _rounded(floor),
        "ratio_to_floor": {k: round(got[k] / floor[k], 3) if got[k] is not None and floor[k] > 0 else None for k in got},
        "structures": {"generated": gm.structure_counts(gen), "heldout": gm.structure_counts(held)},
        "valid_before_rejection": valid_before_rejection,
        **gm.novelty_uniqueness(gen, train),
        "heldout_novelty": gm.novelty_uniqueness(held, train)["novelty"],
    }
    if config["source"] == "procedural":
        out["rules"] = {"generated": satisfaction([_rule_view(g, vocab) for g in gen]),
                        "real": satisfaction([_rule_view(g, vocab) for g in real])}
    out["goals"] = _goals(out)
    return out


def _rounded(d: dict[str, Any]) -> dict[str, Any]:
    return {k: None if v is None else round(v, 5) for k, v in d.items()}


def _goals(m: dict[str, Any]) -> dict[str, Any]:
    """The issue's quality goals, met or not (reported, never tuned against)."""
    r = m["ratio_to_floor"]
    goals = {f"{k}_within_{FLOOR_FACTOR}x_floor": (r[k] is not None and r[k] <= FLOOR_FACTOR)
             for k in ("category_kl", "edge_type_kl", "node_count_tv")}
    goals["valid_before_rejection_at_least_0.8"] = m["valid_before_rejection"] >= 0.8
    goals["novelty_at_least_0.5"] = m["novelty"] >= 0.5
    if "rules" in m:
        gaps = [abs(g["share"] - m["rules"]["real"][k]["share"]) for k, g in m["rules"]["generated"].items()
                if g["share"] is not None and m["rules"]["real"][k]["share"] is not None]
        goals["rules_within_5_points"] = bool(gaps) and max(gaps) <= 0.05
    return goals
