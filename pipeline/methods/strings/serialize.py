"""Relation graphs as SMILES-like strings (Kalojanov et al. 2019, section 5.1), and back.

A string is a list of tokens:

- an *atom* ``[name]``: a node, named by its class (``wall``, ``door``, ``window`` or an object category);
- a *bond* ``{label|label}`` between an atom and the atom it leads to: the edges between the two nodes, each label
  an edge class (:data:`pipeline.graphs.data.EDGE_CLASSES`) after ``>`` (from the earlier atom to the later) or
  ``<`` (from the later to the earlier), sorted (every bond written holds at least one edge);
- ``(`` and ``)`` around every branch but the last of an atom;
- a *ring closure* ``%k``: after an atom, it opens ring ``k`` there; a later ``{bond}%k`` after another atom closes
  it with that bond (the edges of a cycle the depth-first traversal did not walk, as the wall loop's);
- ``.`` starts another connected component;
- a *reference* ``{bond}@k`` after an atom: that bond between it and the string's ``k``-th atom (0-based), written
  earlier. A room's string (:func:`serialize_room`) starts with its architecture's own string and refers to those
  atoms from the objects' components, so a sequence model can be given the architecture and write the rest
  (issue 31: conditioned on the room's walls and openings).

A graph has many strings, one per depth-first order (a start node and an order of each node's neighbours):
:func:`serialize` draws them from a generator, as the paper trains on several strings per shape. :func:`parse`
reads any of them back to the same graph (up to node numbering) and names the first malformed token otherwise.
Pure Python over :class:`~pipeline.graphs.data.Graph`'s arrays; no torch.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ...errors import PlanitError
from ...graphs.data import EDGE_CLASSES, Graph, Vocab

TOKEN = re.compile(r"\[[^\[\]{}()%@.]+\]|\{[^{}]*\}|%\d+|@\d+|[().]")


class StringError(PlanitError):
    """A malformed graph string: which token, where, and why."""


@dataclass(frozen=True)
class StringGraph:
    """A graph as strings see it. ``names (n,)``: node class names; ``edges (m, 3)``: source, target, edge class."""
    names: tuple[str, ...]
    edges: np.ndarray


def tokens(text: str) -> list[str]:
    """The tokens of a string (whitespace between them ignored); a character no token covers is an error."""
    out, pos = [], 0
    for m in TOKEN.finditer(text):
        gap = text[pos:m.start()]
        if gap.strip():
            raise StringError(f"character {pos + len(gap) - len(gap.lstrip())}: '{gap.strip()[0]}' begins no token")
        out.append(m.group())
        pos = m.end()
    if text[pos:].strip():
        raise StringError(f"character {pos}: '{text[pos:].strip()[0]}' begins no token")
    return out


def bond_token(labels: list[tuple[bool, int]]) -> str:
    """``{>c|<c}`` for ``(forward, edge class)`` pairs: forward edges run from the earlier atom to the later."""
    return "{" + "|".join(sorted(f"{'>' if fwd else '<'}{EDGE_CLASSES[c]}" for fwd, c in labels)) + "}"


def _bonds(graph: StringGraph) -> dict[frozenset, list[tuple[int, int, int]]]:
    """Unordered node pair -> its edges (source, target, class)."""
    out: dict[frozenset, list] = {}
    for s, t, c in graph.edges.tolist():
        out.setdefault(frozenset((s, t)), []).append((s, t, c))
    return out


def _labels(edges: list[tuple[int, int, int]], earlier: int) -> list[tuple[bool, int]]:
    return [(s == earlier, c) for s, _, c in edges]


def serialize(graph: StringGraph, rng: np.random.Generator | None = None) -> str:
    """One string of the graph: a depth-first traversal from node 0 (a random node with ``rng``), each node's
    unvisited neighbours in index order (a random order with ``rng``); each further component likewise."""
    return _serialize(graph, rng)[0]


def _serialize(graph: StringGraph, rng: np.random.Generator | None, after: dict | None = None) -> tuple[str, list[int]]:
    """:func:`serialize`'s string and its atoms' nodes in the string's order; ``after``: node -> tokens written
    right after its atom (its references)."""
    n = len(graph.names)
    bonds = _bonds(graph)
    neighbours = [[] for _ in range(n)]
    for pair in bonds:
        a, b = tuple(pair)  # no self-loops: a Graph has none
        neighbours[a].append(b)
        neighbours[b].append(a)
    order = (lambda xs: [xs[k] for k in rng.permutation(len(xs))]) if rng is not None else sorted
    starts = order(list(range(n)))
    visited, parts, atoms = [False] * n, [], []
    for root in starts:
        if not visited[root]:
            text, seen = _component(root, graph, bonds, [order(nb) for nb in neighbours], visited, after or {})
            parts.append(text)
            atoms += seen
    return ".".join(parts), atoms


def serialize_room(graph: StringGraph, n_arch: int, rng: np.random.Generator | None = None) -> str:
    """A room's string, conditioned on its architecture: :func:`arch_prefix` (nodes ``0 .. n_arch - 1``), then
    ``.`` and the objects' components (random orders with ``rng``), each object's bonds to the architecture written
    after its atom as references ``{bond}@k``."""
    return room_string(graph, n_arch, rng)[0]


def room_string(graph: StringGraph, n_arch: int, rng: np.random.Generator | None = None) -> tuple[str, list[int]]:
    """:func:`serialize_room`'s string and the graph's node of each of its atoms, in the string's order."""
    prefix, arch_order = arch_prefix(graph, n_arch)
    at = {node: k for k, node in enumerate(arch_order)}
    objects = _subgraph(graph, range(n_arch, len(graph.names)))
    refs: dict[int, list[str]] = {}
    for pair, edges in sorted(_bonds(graph).items(), key=lambda kv: sorted(kv[0])):
        a, o = sorted(pair)
        if a < n_arch <= o:
            refs.setdefault(o - n_arch, []).append(bond_token(_labels(edges, a)) + f"@{at[a]}")
    body, atoms = _serialize(objects, rng, refs)
    return prefix + ("." + body if body else ""), arch_order + [n_arch + a for a in atoms]


def arch_prefix(graph: StringGraph, n_arch: int) -> tuple[str, list[int]]:
    """The string of the architecture (nodes ``0 .. n_arch - 1`` and the edges among them, one fixed order) and its
    atoms' nodes in order: the ``k``-th atom of a room string is node ``order[k]`` for ``k < n_arch``."""
    return _serialize(_subgraph(graph, range(n_arch)), None)


def _subgraph(graph: StringGraph, nodes: range) -> StringGraph:
    """The nodes ``nodes`` (a range) and the edges among them, renumbered from 0."""
    e = graph.edges
    inside = (e[:, 0] >= nodes.start) & (e[:, 0] < nodes.stop) & (e[:, 1] >= nodes.start) & (e[:, 1] < nodes.stop)
    kept = e[inside].copy()
    kept[:, :2] -= nodes.start
    return StringGraph(graph.names[nodes.start:nodes.stop], kept)


def _component(root: int, graph: StringGraph, bonds: dict, neighbours: list[list[int]], visited: list[bool],
               after: dict) -> tuple[str, list[int]]:
    """The string of ``root``'s component and its nodes in the string's order: a first pass finds the traversal
    tree and the ring (back) edges, a second writes atoms, ring digits and branches."""
    children: dict[int, list[int]] = {}
    rings: list[tuple[int, int]] = []  # (opener: earlier in the string, closer)
    seen_at: dict[int, int] = {}  # node -> place in the string (the pops follow the tree's pre-order)
    stack = [(root, None)]
    while stack:
        node, parent = stack.pop()
        if visited[node]:
            continue
        visited[node] = True
        seen_at[node] = len(seen_at)
        if parent is not None:
            children.setdefault(parent, []).append(node)
        for nb in reversed(neighbours[node]):
            if not visited[nb]:
                stack.append((nb, node))
    tree = {frozenset((p, c)) for p, cs in children.items() for c in cs}
    for pair in bonds:
        if pair not in tree and all(k in seen_at for k in pair):
            a, b = sorted(pair, key=seen_at.get)
            rings.append((a, b))
    return _write(root, graph, bonds, children, rings, seen_at, after), sorted(seen_at, key=seen_at.get)


def _write(root: int, graph: StringGraph, bonds: dict, children: dict, rings: list, seen_at: dict, after: dict) -> str:
    """Emit the component in the traversal's order (iteratively: long chains do not hit the recursion limit). At an
    atom, the rings it closes come first (each with its bond), then the rings it opens, each on the smallest digit
    not in use."""
    opening: dict[int, list[int]] = {}
    closing: dict[int, list[int]] = {}
    for a, b in sorted(rings, key=lambda r: (seen_at[r[0]], seen_at[r[1]])):
        opening.setdefault(a, []).append(b)
        closing.setdefault(b, []).append(a)
    digit_of: dict[tuple[int, int], int] = {}
    out, stack = [], [("atom", root)]
    while stack:
        kind, value = stack.pop()
        if kind == "text":
            out.append(value)
            continue
        out.append(f"[{graph.names[value]}]")
        for a in closing.get(value, []):
            out.append(bond_token(_labels(bonds[frozenset((a, value))], a)) + f"%{digit_of.pop((a, value))}")
        for b in opening.get(value, []):
            used = set(digit_of.values())
            digit_of[(value, b)] = next(k for k in range(1, len(used) + 2) if k not in used)
            out.append(f"%{digit_of[(value, b)]}")
        out += after.get(value, [])
        kids = children.get(value, [])
        for i in range(len(kids) - 1, -1, -1):
            branch = i < len(kids) - 1
            stack += [("text", ")")] * branch + [("atom", kids[i]),
                       ("text", bond_token(_labels(bonds[frozenset((value, kids[i]))], value)))] + [("text", "(")] * branch
    return "".join(out)


def parse(text: str) -> StringGraph:
    """The graph of a string written by :func:`serialize` or :func:`serialize_room` (or generated in their grammar).
    Raises :class:`StringError` naming the first malformed token: an unknown edge class, a bond with no atom after
    it, an unclosed branch or ring, a ring closed without a bond, a ``)`` with no ``(``, a reference to no earlier
    atom."""
    return read_string(text).finish()


def read_string(text: str) -> "Reader":
    """The :class:`Reader` after every token of ``text`` (its ``bond_at`` names each edge's bond token)."""
    reader = Reader()
    for i, tok in enumerate(tokens(text)):
        reader.read(tok, i)
    return reader


class Reader:
    """The parser's state: atoms and edges so far, the current atom, a pending bond, open branches and rings.
    :meth:`fault` says whether a token may come next (a decoder masks the tokens that may not), :meth:`read` takes
    it."""

    def __init__(self):
        self.names: list[str] = []
        self.edges: list[tuple[int, int, int]] = []
        self.bond_at: list[int] = []  # per edge: the index of the bond token that wrote it
        self.current: int | None = None
        self.bond: str | None = None
        self.bond_index = -1
        self.branches: list[int] = []
        self.rings: dict[int, tuple[int, int]] = {}  # digit -> (opening atom, token index)
        self.branch_opened = False  # the last token was "(": a bond must come next

    def fault(self, tok: str) -> str | None:
        """Why ``tok`` may not come next (None: it may)."""
        atom, bonded = self.current is not None, self.bond is not None
        if self.branch_opened and not tok.startswith("{"):
            return "a branch starts with a bond"
        if tok.startswith("["):
            return "an atom after an atom needs a bond between them" if atom and not bonded else None
        if tok.startswith("{"):
            return "a bond must follow an atom" if not atom or bonded else label_fault(tok)
        if tok.startswith("%"):
            k = int(tok[1:])
            if not atom:
                return "a ring digit must follow an atom"
            if k not in self.rings:
                return f"ring {k} is opened with a bond (a bond goes where it closes)" if bonded else None
            if not bonded:
                return f"ring {k} is closed without a bond"
            return f"ring {k} closes on the atom that opened it" if self.rings[k][0] == self.current else None
        if tok.startswith("@"):
            if not atom or not bonded:
                return "a reference needs an atom and a bond before it"
            return f"atom {tok[1:]} is not an earlier atom (this is atom {self.current})" if int(tok[1:]) >= self.current else None
        if tok == "(":
            return "a branch must follow an atom" if not atom or bonded else None
        if tok == ")":
            return "no open branch" if not self.branches else "a bond with no atom after it" if bonded else None
        if not atom:
            return "'.' must follow an atom"
        if self.rings:
            return f"'.' with ring {next(iter(self.rings))} open (a ring closes within its component)"
        return "'.' inside a branch or after a bond" if bonded or self.branches else None

    def read(self, tok: str, i: int) -> None:
        """Take token ``i``; a :class:`StringError` names it when it may not come here."""
        fault = self.fault(tok)
        if fault is not None:
            raise StringError(f"token {i} '{tok}': {fault}")
        self.branch_opened = tok == "("
        if tok.startswith("["):
            self.names.append(tok[1:-1])
            if self.bond is not None:
                self._bonded(self.current, len(self.names) - 1)
            self.current, self.bond = len(self.names) - 1, None
        elif tok.startswith("{"):
            self.bond, self.bond_index = tok, i
        elif tok.startswith("%"):
            k = int(tok[1:])
            if k in self.rings:
                self._bonded(self.rings.pop(k)[0], self.current)
            else:
                self.rings[k] = (self.current, i)
            self.bond = None
        elif tok.startswith("@"):
            self._bonded(int(tok[1:]), self.current)
            self.bond = None
        elif tok == "(":
            self.branches.append(self.current)
        elif tok == ")":
            self.current = self.branches.pop()
        else:
            self.current = None

    def _bonded(self, earlier: int, later: int) -> None:
        new = _edges(self.bond, earlier, later)
        self.edges += new
        self.bond_at += [self.bond_index] * len(new)

    def end_fault(self) -> str | None:
        """Why the string may not end here (None: it may)."""
        if self.bond is not None:
            return "the string ends with a bond and no atom after it"
        if self.branches:
            return f"{len(self.branches)} branch(es) not closed at the end of the string"
        if self.rings:
            k, (_, i) = next(iter(self.rings.items()))
            return f"ring {k} opened at token {i} is never closed"
        return None

    def finish(self) -> StringGraph:
        fault = self.end_fault()
        if fault is not None:
            raise StringError(fault)
        return StringGraph(tuple(self.names), np.array(self.edges, np.int64).reshape(-1, 3))


def label_fault(bond: str) -> str | None:
    """Why a bond token's labels are malformed (None: each is ``>`` or ``<`` and an edge class)."""
    for label in filter(None, bond[1:-1].split("|")):
        if label[0] not in "<>" or label[1:] not in EDGE_CLASSES:
            return f"'{label}' in bond {bond} is not '>' or '<' and an edge class"
    return None


def _edges(bond: str, earlier: int, later: int) -> list[tuple[int, int, int]]:
    """The edges a (well-formed) bond token gives between two atoms."""
    out = []
    for label in filter(None, bond[1:-1].split("|")):
        cls = EDGE_CLASSES.index(label[1:])
        out.append((earlier, later, cls) if label[0] == ">" else (later, earlier, cls))
    return out


def string_graph(graph: Graph, vocab: Vocab) -> StringGraph:
    """A final graph (:func:`~pipeline.graphs.data.graphs_from_tables`) as strings see it: class names and edges."""
    return StringGraph(tuple(vocab.node_classes[c] for c in graph.node_class), graph.edges[:, :3].astype(np.int64))
