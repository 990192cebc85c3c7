"""Sampling a room from the S-AOG (paper section 5): a parse tree (how many of each category, each supported object
on an object of its parent category) and sizes drawn from the grammar, then MCMC over the poses with the weighted
potentials as the energy (the shared annealer, one stage, the logarithmic schedule)."""
from __future__ import annotations

import numpy as np

from ...placement.retrieval import Instance, ModelPool, nearest
from ..solver.anneal import Chain, solve
from ..solver.moves import Proposer, Spec, Steps
from ..solver.state import State
from ..solver.terms import Energy, Hard
from .potentials import terms_of
from .stats import sample_node, sample_size


def parse_tree(grammar: dict, rng: np.random.Generator) -> dict[str, int]:
    """Category -> count drawn from the Set nodes; a supported category has none when its parent category has
    none."""
    counts = {c: int(sample_node(node["count"], rng)) for c, node in grammar["categories"].items()}
    for c, node in grammar["categories"].items():
        if node.get("on") and counts.get(node["on"], 0) == 0:
            counts[c] = 0
    return counts


def sized_pick(grammar: dict, pool: ModelPool):
    """``pick(spec, rng)``: a size drawn from the category's kernel density over the training instances' half
    extents, and the instance whose extents are nearest to it."""
    def pick(spec: Spec, rng: np.random.Generator) -> Instance:
        points = np.array([i.half for i in pool.by_cat[spec.category]])
        bw = grammar["categories"][spec.category].get("size_bandwidth", [0.01] * 3)
        return nearest(pool, spec.category, sample_size({"points": points, "bandwidth": bw}, rng)[0])
    return pick


def specs_of(grammar: dict, counts: dict[str, int], pool: ModelPool) -> dict[str, Spec]:
    return {c: Spec(c, (n, n), "all", "on" if grammar["categories"][c].get("on") else "floor",
                    grammar["categories"][c].get("on"))
            for c, n in counts.items() if n > 0 and pool.has(c)}


def sample_room(grammar: dict, weights: dict, room: tuple[State, Hard], pool: ModelPool, cfg: dict, steps: int,
                rng: np.random.Generator) -> Chain:
    """One sampled room in the architecture of ``room`` (its empty state and hard constraints; ``cfg``: the saog
    section)."""
    state, hard = room
    specs = specs_of(grammar, parse_tree(grammar, rng), pool)
    s = cfg["step"]
    proposer = Proposer(specs, pool, Steps(s["scale"], s["least"], s["most"], np.deg2rad(s["quantum"])),
                        violations=hard.total, attempts=20, pick=sized_pick(grammar, pool))
    energy = Energy(hard, terms_of(grammar, weights))
    solver_cfg = {"schedule": cfg["schedule"], "moves": cfg["moves"], "steps": {"all": steps}}
    return solve(state, specs, energy, proposer, solver_cfg, rng, stages=("all",))
