"""GRAINS's recursive VAE over room hierarchies (Li et al., ACM TOG 2019, section 5).

One encoder and one decoder per node kind, each a one-hidden-layer MLP with tanh (``Linear, tanh, Linear``; node
features pass through a final tanh, real values and logits are read off the output layer directly). Encoders fold a
tree bottom-up into one feature per node and the root's feature into the Gaussian code ``z``; decoders unfold ``z``
top-down: the root decoder gives the floor's half extents and four wall features, the wall decoder a wall's half
extents, whether it holds objects, its subtree's feature and the subtree's code, a node classifier picks which
decoder expands a subtree feature (leaf, support, surround, co-occurrence), and each decoder gives its children's
features and codes (a leaf: half extents and label logits).

Trees are batched: :func:`tensorize` flattens a list of trees into node rows, encoding runs one MLP call per (kind,
height) over the whole batch and training's decoding (teacher forcing with the true structure) one call per (kind,
depth). Lengths (half extents, code offsets) are divided by ``scale`` metres inside the network. The loss (after the
released code): squared errors of half extents and code reals, cross-entropy of the code's two-hot entries (one
softmax over the four x edge pairs, one over the four y edge pairs: :mod:`.relpos` sets one bit in each), binary
cross-entropy of its attachment and alignment bits and of a wall's "has objects", cross-entropy of
node kinds and leaf labels, plus the KL divergence of the code (weighted by the caller); all summed per tree and
averaged over trees.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import torch
import torch.nn.functional as fn
from torch import Tensor, nn

from ...learning.divergence import gaussian_kl
from . import relpos
from .hierarchy import KINDS, Node

CODE = relpos.CODE  # [0:3] reals (rotation / pi, x, y offsets, m), [3:19] two-hot, [19:23] attach, [23:28] align
REALS, BITS = slice(0, 3), slice(relpos.ATTACH.start, CODE)
# the two-hot entries of the x and y edge pairs (one bit set in each group)
PAIR_X = [relpos.PAIRS.start + a * 4 + b for a in relpos.X_EDGES for b in relpos.X_EDGES]
PAIR_Y = [relpos.PAIRS.start + a * 4 + b for a in relpos.Y_EDGES for b in relpos.Y_EDGES]
OBJECT_KINDS = ("leaf", "support", "surround", "cooc")  # the node classifier's classes, in this order
ARITY = {"leaf": 0, "support": 2, "surround": 3, "cooc": 2}
N_CODES = {"leaf": 0, "support": 1, "surround": 2, "cooc": 1}
MIN_HALF = 0.02  # decoded half extents are at least this (m)
assert tuple(KINDS[:4]) == OBJECT_KINDS


@dataclass
class Sizes:
    feature: int  # node feature size
    hidden: int  # hidden layer of node encoders, decoders and the classifier
    root_feature: int  # root feature, and the code z
    root_hidden: int  # hidden layer of the root encoder and decoder


PAPER = Sizes(feature=250, hidden=750, root_feature=350, root_hidden=1050)


@dataclass
class Forest:
    """A batch of trees flattened to ``N`` node rows (each tree's rows in pre-order)."""
    kind: np.ndarray  # (N,) index into KINDS
    height: np.ndarray  # (N,) 0 for leaves and empty walls, else 1 + the highest child
    depth: np.ndarray  # (N,) root 0, walls 1, a wall's subtree 2, ...
    tree: np.ndarray  # (N,) the tree's index in the batch
    children: np.ndarray  # (N, 4) child rows, -1 where none
    roots: np.ndarray  # (B,) root rows
    half: Tensor  # (N, 3) half extents / scale (leaf, wall, root; zeros elsewhere)
    codes: Tensor  # (N, 2, CODE) codes with offsets / scale (zeros where none)
    label: Tensor  # (N,) leaf label index, -1 elsewhere

    def rows(self, kind: str, height: int | None = None, depth: int | None = None) -> np.ndarray:
        """Rows of ``kind`` (at ``height`` / ``depth`` when given), ascending."""
        mask = self.kind == KINDS.index(kind)
        if height is not None:
            mask &= self.height == height
        if depth is not None:
            mask &= self.depth == depth
        return np.flatnonzero(mask)

    def ix(self, rows: np.ndarray) -> Tensor:
        """``rows`` as an index tensor on the batch's device."""
        return torch.as_tensor(np.asarray(rows, dtype=np.int64), device=self.half.device)


def _flatten(node: Node, tree: int, depth: int, out: list) -> tuple[int, int]:
    """Append ``node``'s subtree to ``out`` in pre-order as (node, tree, depth, height, child rows); its row and
    height."""
    row = len(out)
    out.append(None)
    kids = [_flatten(c, tree, depth + 1, out) for c in node.children]
    height = 1 + max((h for _, h in kids), default=-1)
    out[row] = (node, tree, depth, height, [r for r, _ in kids])
    return row, height


def _check(node: Node) -> None:
    """Refuse a node whose children and codes do not fit its kind."""
    arity, codes = {**ARITY, "wall": len(node.children), "root": 4}, {**N_CODES, "wall": len(node.children), "root": 0}
    if node.kind not in KINDS:
        raise ValueError(f"unknown node kind {node.kind!r}")
    if len(node.children) != arity[node.kind] or len(node.codes) != codes[node.kind] or len(node.children) > 4:
        raise ValueError(f"a {node.kind} node with {len(node.children)} children and {len(node.codes)} codes")
    if node.kind == "root" and any(c.kind != "wall" for c in node.children):
        raise ValueError("a root's children must be four wall nodes")


def normalise_code(code: np.ndarray, scale: float) -> np.ndarray:
    """A ``(CODE,)`` code with its offsets divided by ``scale``."""
    out = np.asarray(code, dtype=np.float32).copy()
    out[1:3] /= scale
    return out


def tensorize(trees: list[Node], index: dict[str, int], scale: float, device: str | torch.device = "cpu") -> Forest:
    """Flatten ``trees`` into a :class:`Forest`; ``index`` maps leaf labels to label indices."""
    flat: list = []
    roots = np.array([_flatten(t, b, 0, flat)[0] for b, t in enumerate(trees)], dtype=np.int64)
    n = len(flat)
    half, codes = np.zeros((n, 3), np.float32), np.zeros((n, 2, CODE), np.float32)
    children, label = np.full((n, 4), -1, np.int64), np.full(n, -1, np.int64)
    for row, (node, _, _, _, kids) in enumerate(flat):
        _check(node)
        children[row, :len(kids)] = kids
        if node.half is not None:
            half[row] = np.asarray(node.half, np.float32) / scale
        for j, code in enumerate(node.codes):
            codes[row, j] = normalise_code(code, scale)
        if node.kind == "leaf":
            if node.label not in index:
                raise ValueError(f"leaf label {node.label!r} is not one of the model's labels")
            label[row] = index[node.label]
    kind = np.array([KINDS.index(f[0].kind) for f in flat], np.int64)
    info = np.array([f[1:4] for f in flat], np.int64).reshape(n, 3)
    return Forest(kind, info[:, 2], info[:, 1], info[:, 0], children, roots, torch.from_numpy(half).to(device),
                  torch.from_numpy(codes).to(device), torch.from_numpy(label).to(device))


def mlp(n_in: int, hidden: int, n_out: int) -> nn.Sequential:
    """One hidden layer with tanh: ``(n, n_in) -> (n, n_out)``."""
    return nn.Sequential(nn.Linear(n_in, hidden), nn.Tanh(), nn.Linear(hidden, n_out))


def code_loss(pred: Tensor, true: Tensor) -> Tensor:
    """Per-code loss ``(...)`` of predicted ``(..., CODE)`` outputs against true (normalised) codes: squared error of
    the reals, cross-entropy of each edge-pair group (x, y) of the two-hot entries, BCE of the bits."""
    reals = ((pred[..., REALS] - true[..., REALS]) ** 2).sum(-1)
    two_hot = sum(-(true[..., g] * fn.log_softmax(pred[..., g], -1)).sum(-1) for g in (PAIR_X, PAIR_Y))
    bits = fn.binary_cross_entropy_with_logits(pred[..., BITS], true[..., BITS], reduction="none").sum(-1)
    return reals + two_hot + bits


def sse(pred: Tensor, true: Tensor) -> Tensor:
    """Summed squared error per row: ``(n, d), (n, d) -> (n,)``."""
    return ((pred - true) ** 2).sum(-1)


class Terms:
    """Per-tree loss sums ``(B,)`` by name, accumulated from per-node values."""

    def __init__(self, forest: Forest, names: tuple[str, ...]):
        self.forest = forest
        self.sums = {k: forest.half.new_zeros(len(forest.roots)) for k in names}

    def add(self, name: str, rows: np.ndarray, values: Tensor) -> None:
        """Add per-node ``values (len(rows),)`` to their trees' ``name`` sums."""
        self.sums[name] = self.sums[name].index_add(0, self.forest.ix(self.forest.tree[rows]), values)


class GrainsVAE(nn.Module):
    """GRAINS's recursive VAE; ``labels`` are the leaf categories, ``scale`` (m) divides lengths."""

    def __init__(self, labels: list[str], sizes: Sizes, scale: float = 2.0):
        super().__init__()
        self.labels, self.sizes, self.scale = list(labels), sizes, float(scale)
        self.index = {label: i for i, label in enumerate(self.labels)}
        f, h, r, rh, c = sizes.feature, sizes.hidden, sizes.root_feature, sizes.root_hidden, len(self.labels)
        self.enc = nn.ModuleDict({
            "leaf": mlp(3 + c, h, f), "support": mlp(2 * f + CODE, h, f), "cooc": mlp(2 * f + CODE, h, f),
            "surround": mlp(3 * f + 2 * CODE, h, f), "wall": mlp(3 + f + CODE + 1, h, f),
            "root": mlp(3 + 4 * f, rh, r)})
        self.empty = nn.Parameter(torch.zeros(f))  # a wall without objects: its "subtree feature"
        self.to_mu, self.to_logvar = nn.Linear(r, r), nn.Linear(r, r)
        self.dec = nn.ModuleDict({
            "leaf": mlp(f, h, 3 + c), "support": mlp(f, h, 2 * f + CODE), "cooc": mlp(f, h, 2 * f + CODE),
            "surround": mlp(f, h, 3 * f + 2 * CODE), "wall": mlp(f, h, 3 + 1 + f + CODE),
            "root": mlp(r, rh, 3 + 4 * f)})
        self.classify = mlp(f, h, len(OBJECT_KINDS))

    def spec(self) -> dict:
        """What rebuilds this network (JSON): labels, sizes and scale; see :meth:`from_spec`."""
        return {"labels": list(self.labels), "sizes": asdict(self.sizes), "scale": self.scale}

    @classmethod
    def from_spec(cls, spec: dict) -> GrainsVAE:
        """A fresh network of :meth:`spec`'s shape (load its state dict next)."""
        return cls(spec["labels"], Sizes(**spec["sizes"]), spec["scale"])

    @property
    def device(self) -> torch.device:
        return self.empty.device

    def tensorize(self, trees: list[Node]) -> Forest:
        return tensorize(trees, self.index, self.scale, self.device)

    # ----- encoding (bottom-up, one MLP call per kind and height) -----

    def encode(self, trees: list[Node]) -> tuple[Tensor, Tensor]:
        """The code's mean and log-variance, each ``(B, root_feature)``."""
        return self.encode_forest(self.tensorize(trees))

    def encode_forest(self, f: Forest) -> tuple[Tensor, Tensor]:
        """:meth:`encode` of a flattened batch."""
        feats = f.half.new_zeros(len(f.kind), self.sizes.feature)
        objects = f.kind < len(OBJECT_KINDS)
        for height in range(int(f.height[objects].max(initial=-1)) + 1):
            for kind in OBJECT_KINDS:
                rows = f.rows(kind, height=height)
                if len(rows):
                    out = torch.tanh(self.enc[kind](self._enc_input(kind, rows, f, feats)))
                    feats = feats.index_copy(0, f.ix(rows), out)
        walls = f.rows("wall")
        feats = feats.index_copy(0, f.ix(walls), torch.tanh(self.enc["wall"](self._wall_input(walls, f, feats))))
        x = torch.cat([f.half[f.ix(f.roots)]] + [feats[f.ix(f.children[f.roots, j])] for j in range(4)], 1)
        h = torch.tanh(self.enc["root"](x))
        return self.to_mu(h), self.to_logvar(h).clamp(-10.0, 10.0)

    def _enc_input(self, kind: str, rows: np.ndarray, f: Forest, feats: Tensor) -> Tensor:
        """An object node encoder's input ``(n, in)``: a leaf's half extents and one-hot label, else its children's
        features and its codes."""
        r = f.ix(rows)
        if kind == "leaf":
            return torch.cat([f.half[r], fn.one_hot(f.label[r], len(self.labels)).to(f.half.dtype)], 1)
        kids = [feats[f.ix(f.children[rows, j])] for j in range(ARITY[kind])]
        return torch.cat(kids + [f.codes[r, j] for j in range(N_CODES[kind])], 1)

    def _wall_input(self, rows: np.ndarray, f: Forest, feats: Tensor) -> Tensor:
        """The wall encoder's input ``(n, 3 + feature + CODE + 1)``: half extents, subtree feature (or the learned
        empty vector), code (zeros when empty) and the has-objects bit."""
        child = f.children[rows, 0]
        has = torch.as_tensor(child >= 0, device=self.device)[:, None]
        sub = torch.where(has, feats[f.ix(np.maximum(child, 0))], self.empty.expand(len(rows), -1))
        r = f.ix(rows)
        return torch.cat([f.half[r], sub, f.codes[r, 0], has.to(f.half.dtype)], 1)

    # ----- training: the loss with teacher-forced decoding -----

    def loss(self, trees: list[Node], kl_weight: float, gen: torch.Generator | None = None,
             sample: bool = True) -> dict[str, Tensor]:
        """Mean per-tree ``total`` (= recon + kind + label + kl_weight * kl), ``recon``, ``kind``, ``label`` and
        ``kl``; the code is drawn as ``mu + eps * std`` (``eps`` from ``gen``) when ``sample``, else it is ``mu``."""
        f = self.tensorize(trees)
        mu, logvar = self.encode_forest(f)
        z = mu
        if sample:
            z = mu + torch.randn(mu.shape, generator=gen).to(mu.device) * torch.exp(0.5 * logvar)
        terms = self.reconstruct(f, z)
        out = {k: v.mean() for k, v in terms.items()}
        out["kl"] = gaussian_kl(mu, logvar).sum(1).mean()
        out["total"] = out["recon"] + out["kind"] + out["label"] + kl_weight * out["kl"]
        return out

    def reconstruct(self, f: Forest, z: Tensor) -> dict[str, Tensor]:
        """Decode codes ``z (B, root_feature)`` along the true trees ``f``: per-tree loss sums ``(B,)`` ``recon``,
        ``kind`` and ``label``."""
        terms, n = Terms(f, ("recon", "kind", "label")), self.sizes.feature
        out = self.dec["root"](z)
        terms.add("recon", f.roots, sse(out[:, :3], f.half[f.ix(f.roots)]))
        walls = f.children[f.roots, :4].reshape(-1)
        feats = f.half.new_zeros(len(f.kind), n).index_copy(0, f.ix(walls), torch.tanh(out[:, 3:]).reshape(-1, n))
        feats = self._teach_walls(walls, f, feats, terms)
        for depth in range(2, int(f.depth.max()) + 1):
            rows = np.flatnonzero((f.depth == depth) & (f.kind < len(OBJECT_KINDS)))
            target = torch.as_tensor(f.kind[rows], device=self.device)
            terms.add("kind", rows, fn.cross_entropy(self.classify(feats[f.ix(rows)]), target, reduction="none"))
            for kind in OBJECT_KINDS:
                sub = f.rows(kind, depth=depth)
                if len(sub):
                    feats = self._teach(kind, sub, f, feats, terms)
        return terms.sums

    def _teach_walls(self, rows: np.ndarray, f: Forest, feats: Tensor, terms: Terms) -> Tensor:
        """Decode the walls ``rows``: add their losses to ``terms``; ``feats (N, feature)`` with their subtrees'
        features set."""
        n, r = self.sizes.feature, f.ix(rows)
        out = self.dec["wall"](feats[r])
        child = f.children[rows, 0]
        has = torch.as_tensor(child >= 0, device=self.device)
        loss = sse(out[:, :3], f.half[r])
        loss = loss + fn.binary_cross_entropy_with_logits(out[:, 3], has.float(), reduction="none")
        terms.add("recon", rows, loss + has * code_loss(out[:, 4 + n:], f.codes[r, 0]))
        full = np.flatnonzero(child >= 0)
        return feats.index_copy(0, f.ix(child[full]), torch.tanh(out[f.ix(full), 4:4 + n]))

    def _teach(self, kind: str, rows: np.ndarray, f: Forest, feats: Tensor, terms: Terms) -> Tensor:
        """Decode the object nodes ``rows`` of ``kind``: add their losses to ``terms``; ``feats`` with their
        children's features set."""
        n, r = self.sizes.feature, f.ix(rows)
        out = self.dec[kind](feats[r])
        if kind == "leaf":
            terms.add("recon", rows, sse(out[:, :3], f.half[r]))
            terms.add("label", rows, fn.cross_entropy(out[:, 3:], f.label[r], reduction="none"))
            return feats
        k, m = ARITY[kind], N_CODES[kind]
        codes = out[:, k * n:].reshape(len(rows), m, CODE)
        terms.add("recon", rows, code_loss(codes, f.codes[r, :m]).sum(1))
        kids = f.children[rows, :k].reshape(-1)
        return feats.index_copy(0, f.ix(kids), torch.tanh(out[:, :k * n]).reshape(-1, n))

    # ----- generation: greedy decoding of codes -----

    @torch.no_grad()
    def decode(self, z: Tensor, max_depth: int = 12, max_nodes: int = 200) -> list[Node]:
        """One tree per row of ``z (B, root_feature)``: argmax kinds, labels and two-hot entries, bits set where their
        logit is positive. Every tree has ``hierarchy.tree_depth <= max_depth`` (at least 3: root, walls, a leaf)
        and at most ``max_nodes`` nodes (at least 9): a node on the last level, or one whose children would pass
        the budget (nodes are expanded level by level, in order), is decoded as a leaf."""
        if max_depth < 3 or max_nodes < 9:
            raise ValueError(f"max_depth {max_depth} < 3 or max_nodes {max_nodes} < 9: no room for a leaf per wall")
        z, n = z.to(self.device, torch.float32), self.sizes.feature
        out = self.dec["root"](z)
        roots = [Node("root", half=self._half(row)) for row in out[:, :3].double().cpu().numpy()]
        walls, feats, nodes, owner = self._decode_walls(torch.tanh(out[:, 3:]).reshape(-1, n))
        for b, root in enumerate(roots):
            root.children = walls[4 * b:4 * b + 4]
        count = 5 + np.bincount(np.asarray(owner, dtype=np.int64), minlength=len(roots))  # nodes per tree so far
        depth = 3  # levels counted as hierarchy.tree_depth does: the root's is 1, the walls' 2
        while nodes:
            kinds = self._kinds(feats, owner, count, max_nodes) if depth < max_depth else np.zeros(len(nodes), int)
            feats, nodes, owner = self._decode_level(feats, nodes, owner, kinds)
            depth += 1
        return roots

    def _decode_walls(self, feats: Tensor) -> tuple[list[Node], Tensor, list[Node], list[int]]:
        """Wall nodes from wall features ``(4B, feature)``; their subtrees' features ``(m, feature)``, the (yet
        empty) subtree nodes and the trees they belong to."""
        out = self.dec["wall"](feats)
        rows, n = out.double().cpu().numpy(), self.sizes.feature
        walls, subtrees, owner = [], [], []
        for k, row in enumerate(rows):
            wall = Node("wall", half=self._half(row[:3]))
            if row[3] > 0:
                wall.children, wall.codes = [Node("leaf")], [self._code(row[4 + n:])]
                subtrees.append(wall.children[0])
                owner.append(k // 4)
            walls.append(wall)
        keep = torch.as_tensor(np.flatnonzero(rows[:, 3] > 0), dtype=torch.long, device=self.device)
        return walls, torch.tanh(out[keep, 4:4 + n]), subtrees, owner

    def _kinds(self, feats: Tensor, owner: list[int], count: np.ndarray, max_nodes: int) -> np.ndarray:
        """Classifier kinds ``(m,)`` (indices into OBJECT_KINDS) of the features ``(m, feature)``, leaves where the
        children would take their tree past ``max_nodes``; ``count`` (nodes per tree) grows by the children."""
        kinds = self.classify(feats).argmax(1).cpu().numpy()
        for i, tree in enumerate(owner):
            grow = ARITY[OBJECT_KINDS[kinds[i]]]
            if count[tree] + grow > max_nodes:
                kinds[i] = 0
            else:
                count[tree] += grow
        return kinds

    def _decode_level(self, feats: Tensor, nodes: list[Node], owner: list[int],
                      kinds: np.ndarray) -> tuple[Tensor, list[Node], list[int]]:
        """Fill ``nodes`` as ``kinds`` from their features ``(m, feature)``; their children's features, the (yet
        empty) child nodes and the trees they belong to."""
        n = self.sizes.feature
        next_feats, next_nodes, next_owner = [], [], []
        for k, kind in enumerate(OBJECT_KINDS):
            sel = np.flatnonzero(kinds == k)
            if not len(sel):
                continue
            out = self.dec[kind](feats[torch.as_tensor(sel, device=self.device)])
            for i, row in zip(sel, out.double().cpu().numpy()):
                kids = self._fill(nodes[i], kind, row)
                next_nodes += kids
                next_owner += [owner[i]] * len(kids)
            if kind != "leaf":
                next_feats.append(torch.tanh(out[:, :ARITY[kind] * n]).reshape(-1, n))
        return (torch.cat(next_feats) if next_feats else feats[:0]), next_nodes, next_owner

    def _fill(self, node: Node, kind: str, out: np.ndarray) -> list[Node]:
        """Set ``node`` to ``kind`` from its decoder's output row; its new (yet empty) children."""
        node.kind = kind
        if kind == "leaf":
            node.half, node.label = self._half(out[:3]), self.labels[int(np.argmax(out[3:]))]
            return []
        k, start = ARITY[kind], ARITY[kind] * self.sizes.feature
        node.children = [Node("leaf") for _ in range(k)]
        node.codes = [self._code(out[start + j * CODE:start + (j + 1) * CODE]) for j in range(N_CODES[kind])]
        return node.children

    def _half(self, out: np.ndarray) -> np.ndarray:
        """Half extents (m, ``(3,)``, at least MIN_HALF) from normalised outputs."""
        return np.maximum(np.asarray(out, float) * self.scale, MIN_HALF)

    def _code(self, out: np.ndarray) -> np.ndarray:
        """A ``(CODE,)`` code from decoder outputs: reals in metres (rotation / pi within [-1, 1]), the largest
        two-hot entry of the x and of the y edge pairs and the bits with positive logits set to 1."""
        out = np.asarray(out, float)
        code = np.zeros(CODE)
        code[0] = np.clip(out[0], -1.0, 1.0)
        code[1:3] = out[1:3] * self.scale
        for group in (PAIR_X, PAIR_Y):
            code[group[int(np.argmax(out[group]))]] = 1.0
        code[BITS] = (out[BITS] > 0).astype(float)
        return code
