"""The grammar of the training graphs (Kalojanov et al. 2019, section 3): for each node class, the bonds it was seen
with (which way, the relation, the neighbour's class) and how many of each one node held at most. A generated graph
that breaks it is rejected and counted (valid before rejection, issue 31).

How fine a relation is (``detail``): ``edge`` the whole edge class (``front/adjacent``), ``relation`` without its
direction (``adjacent``; support and the architecture's edges as they are), ``neighbour`` none (only which way and
the neighbour's class). The finer, the more held-out real graphs it rejects (docs/benchmarks.md)."""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

from ...graphs.data import EDGE_CLASSES
from .serialize import StringGraph

Bond = tuple[str, str, str]  # (">" out of the node or "<" into it, relation at the grammar's detail, neighbour class)
DETAILS = ("edge", "relation", "neighbour")


def relation(edge_class: int, detail: str) -> str:
    """An edge class at a grammar's detail."""
    name = EDGE_CLASSES[edge_class]
    if detail == "edge":
        return name
    if detail == "relation":
        return name.split("/")[1] if "/" in name and not name.startswith("wall_") else name
    return ""


def bond(out: bool, edge_class: int, neighbour: str, detail: str) -> Bond:
    """A bond at ``detail``: ``out`` of the node (or into it), its edge class, the neighbour's class."""
    return (">" if out else "<", relation(edge_class, detail), neighbour)


def bonds_of(names, edges, detail: str = "edge") -> list[Counter]:
    """Per node of ``names``, its bonds among ``edges`` (source, target, edge class) at ``detail`` counted."""
    out: list[Counter[Bond]] = [Counter() for _ in names]
    for s, t, c in edges:
        out[s][bond(True, c, names[t], detail)] += 1
        out[t][bond(False, c, names[s], detail)] += 1
    return out


@dataclass(frozen=True)
class Grammar:
    """Node class -> bond -> the most of that bond one node of the class held in a training graph."""
    most: dict[str, dict[Bond, int]]
    detail: str = "edge"
    _neighbours: dict = field(default_factory=dict, compare=False, repr=False)

    def violations(self, graph: StringGraph) -> list[str]:
        """What a graph does that no training graph did: an unseen class, an unseen bond, more of a bond than seen."""
        out = []
        for k, (name, counts) in enumerate(zip(graph.names, bonds_of(graph.names, graph.edges.tolist(), self.detail))):
            seen = self.most.get(name)
            if seen is None:
                out.append(f"node {k}: class '{name}' is in no training graph")
                continue
            for bond, n in sorted(counts.items()):
                if bond not in seen:
                    out.append(f"node {k} ({name}): bond {''.join(bond[:2])} {bond[2]} never seen")
                elif n > seen[bond]:
                    out.append(f"node {k} ({name}): {n} x {''.join(bond[:2])} {bond[2]}, at most {seen[bond]} seen")
        return out

    def valid(self, graph: StringGraph) -> bool:
        return not self.violations(graph)

    def neighbours(self, name: str) -> set[str]:
        """The classes a node of class ``name`` was seen bonded to."""
        if name not in self._neighbours:
            self._neighbours[name] = {b[2] for b in self.most.get(name, {})}
        return self._neighbours[name]

    def fits(self, name: str, held: Counter, added: list[Bond]) -> bool:
        """Whether a node of class ``name`` holding the bonds ``held`` may take the bonds ``added`` too."""
        seen = self.most.get(name)
        if seen is None:
            return False
        more = Counter(added)
        return all(seen.get(b, 0) >= held[b] + k for b, k in more.items())

    def bond(self, out: bool, edge_class: int, neighbour: str) -> Bond:
        """:func:`bond` at this grammar's detail."""
        return bond(out, edge_class, neighbour, self.detail)


def learn_grammar(graphs: list[StringGraph], detail: str = "edge") -> Grammar:
    """The grammar of a training split's graphs at ``detail`` (:data:`DETAILS`)."""
    if detail not in DETAILS:
        raise ValueError(f"grammar detail '{detail}' is not one of {DETAILS}")
    most: dict[str, dict[Bond, int]] = {}
    for g in graphs:
        for name, counts in zip(g.names, bonds_of(g.names, g.edges.tolist(), detail)):
            acc = most.setdefault(name, {})
            for bond, n in counts.items():
                acc[bond] = max(acc.get(bond, 0), n)
    return Grammar(most, detail)
