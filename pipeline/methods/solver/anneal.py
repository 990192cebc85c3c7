"""The Metropolis-Hastings annealer and Infinigen's staged solving (Algorithm 1: large, then medium, then small
objects, each stage moving only its own objects). Acceptance follows Infinigen's released code: a move that lowers
the hard-violation count is accepted, one that raises it is rejected, and between states with as many violations
``min(1, exp((E - E') / T))`` decides."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .moves import MOVES, Proposer, Spec
from .schedule import move_weights, temperature
from .state import State
from .terms import Energy


@dataclass
class Chain:
    """A chain's current and best states with their (violations, energy), and its trace rows."""
    state: State
    score: tuple[int, float]
    best: State
    best_score: tuple[int, float]
    trace: list[dict] = field(default_factory=list)
    accepted: int = 0
    proposed: int = 0


def accept(old: tuple[int, float], new: tuple[int, float], temp: float, rng: np.random.Generator) -> bool:
    """Whether to move from a state scored ``old`` (violations, energy) to one scored ``new`` at temperature ``temp``."""
    if new[0] != old[0]:
        return new[0] < old[0]
    return new[1] <= old[1] or rng.random() < np.exp((old[1] - new[1]) / max(temp, 1e-12))


def anneal(chain: Chain, moves: tuple[Energy, Proposer], active: set[str], steps: int, cfg: dict,
           rng: np.random.Generator, record: tuple[str, int] = ("", 10)) -> Chain:
    """Propose ``steps`` moves (``moves``: the energy and the proposer) on the items of the ``active`` categories
    (``cfg``: the ``solver`` section: schedule, move weights at the start and end); keeps the best state seen;
    ``record``: the stage's name in the trace and how many steps apart it records one."""
    energy, proposer = moves
    stage, record_every = record
    names = list(MOVES)
    t = tries = 0
    while t < steps and tries < 10 * steps:  # a step is a proposed move: moves that do not apply are drawn again
        tries += 1
        temp = temperature(cfg["schedule"], t, steps)
        w = move_weights(cfg["moves"]["start"], cfg["moves"]["end"], t, steps)
        p = np.array([w.get(m, 0.0) for m in names])
        kind = names[int(rng.choice(len(names), p=p / p.sum()))]
        new = proposer.propose(chain.state, kind, active, temp, rng)
        if new is None:
            continue
        chain.proposed += 1
        v, e, _ = energy(new)
        if accept(chain.score, (v, e), temp, rng):
            chain.state, chain.score, chain.accepted = new, (v, e), chain.accepted + 1
            if chain.score < chain.best_score:
                chain.best, chain.best_score = new, chain.score
        if t % record_every == 0 or t == steps - 1:
            chain.trace.append({"stage": stage, "step": t, "temperature": temp, "violations": chain.score[0],
                                "energy": chain.score[1], "objects": len(chain.state.items)})
        t += 1
    return chain


def parents_first(specs: list[Spec]) -> list[Spec]:
    """``specs`` in their order, except that each comes after its support parent's category (when listed)."""
    by, out, seen = {s.category: s for s in specs}, [], set()

    def visit(s: Spec, path: frozenset) -> None:
        if s.category in seen or s.category in path:
            return
        if s.parent in by:
            visit(by[s.parent], path | {s.category})
        seen.add(s.category)
        out.append(s)

    for s in specs:
        visit(s, frozenset())
    return out


def start_stage(state: State, specs: dict[str, Spec], stage: str, proposer: Proposer,
                rng: np.random.Generator) -> State:
    """The state with each of the stage's categories added up to its minimum count, at random places; a support
    parent's category before its children's (a child added before any parent has nowhere to stand)."""
    for spec in parents_first([s for s in specs.values() if s.stage == stage]):
        for _ in range(max(spec.count[0] - state.count(spec.category), 0)):
            it = proposer.fresh(state, spec, rng)
            if it is not None:
                state = state.with_items([*state.items, it])
    return state


def solve(state: State, specs: dict[str, Spec], energy: Energy, proposer: Proposer, cfg: dict,
          rng: np.random.Generator, stages: tuple[str, ...] = ("large", "medium", "small")) -> Chain:
    """Staged solving: each stage starts from the previous stage's best state, adds its minimum counts and anneals
    ``cfg['steps'][stage]`` moves over its own objects."""
    v, e, _ = energy(state)
    chain = Chain(state, (v, e), state, (v, e))
    for stage in stages:
        active = {c for c, s in specs.items() if s.stage == stage}
        if not active:
            continue
        start = start_stage(chain.best, specs, stage, proposer, rng)
        v, e, _ = energy(start)
        chain.state, chain.score = start, (v, e)
        chain.best, chain.best_score = start, (v, e)
        chain = anneal(chain, (energy, proposer), active, int(cfg["steps"][stage]), cfg, rng, (stage, 10))
    return chain
