"""Decoding room strings from the sequence VAE, many at once: codes from the prior, from a training room's code
perturbed (the paper's section 5.2: up to ``radius`` per dimension) or on a straight path between two rooms' codes
(32 points in the paper), each decoded after a forced prefix (the room's architecture string and ``.``), token by
token at a temperature."""
from __future__ import annotations

from collections import Counter

import numpy as np
import torch

from ...graphs.data import EDGE_CLASSES

from .model import SeqVAE
from .grammar import Grammar, node_bonds
from .serialize import Reader, label_fault
from .vocab import BOS, EOS, PAD, SPECIAL, TokenVocab


def prior_codes(n: int, latent: int, gen: torch.Generator) -> torch.Tensor:
    """``(n, latent)`` codes from the standard normal prior."""
    return torch.randn(n, latent, generator=gen)


def perturbed_codes(mu: torch.Tensor, radius: float, gen: torch.Generator) -> torch.Tensor:
    """``mu (n, latent)`` moved by up to ``radius`` per dimension (uniform)."""
    return mu + (torch.rand(mu.shape, generator=gen) * 2 - 1) * radius


def path_codes(a: torch.Tensor, b: torch.Tensor, points: int) -> torch.Tensor:
    """``(points, latent)`` codes evenly spaced from ``a`` to ``b`` (both ends included)."""
    t = torch.linspace(0, 1, points)[:, None]
    return (1 - t) * a[None] + t * b[None]


def encode_means(model: SeqVAE, strings: list[str], vocab: TokenVocab, max_length: int) -> torch.Tensor:
    """``(n, latent)`` the code means of ``strings``."""
    model.eval()
    x = torch.from_numpy(vocab.encode(strings, max_length))
    with torch.no_grad():
        mu, _ = model.encode(x, (x != 0).sum(1))
    return mu


class Syntax:
    """Per string a parser over its tokens so far: the tokens it may take next (``banned`` token indices never).
    With a ``grammar`` (and ``caps``: category -> most per room), a token that would give a node a bond the training
    graphs never hold, more of one than they hold, or a category more often than any training room is masked too
    (as PlanIT's sampler masks unseen edges and counts)."""

    def __init__(self, vocab: TokenVocab, n: int, banned: set[int] = frozenset(), grammar: Grammar | None = None,
                 caps: dict[str, int] | None = None):
        self.tokens, self.ix = vocab.tokens, vocab.index
        self.readers = [Reader() for _ in range(n)]
        self.open = [k for k, t in enumerate(vocab.tokens) if t not in SPECIAL and k not in banned]
        self.grammar, self.caps = grammar, caps or {}
        self.dead: set[int] = set()  # rows where no token fitted
        self.labels = {t: [(lab[0] == ">", EDGE_CLASSES.index(lab[1:])) for lab in filter(None, t[1:-1].split("|"))]
                       for t in vocab.tokens if t.startswith("{") and label_fault(t) is None}

    def take(self, row: int, token: int) -> None:
        tok = self.tokens[token]
        if tok not in SPECIAL:
            self.readers[row].read(tok, len(self.readers[row].names))

    def mask(self, rows: list[int]) -> torch.Tensor:
        """``(len(rows), vocab)`` bool: allowed next tokens of each row."""
        out = torch.zeros(len(rows), len(self.tokens), dtype=torch.bool)
        for r, row in enumerate(rows):
            reader = self.readers[row]
            held = self._held(reader, reader.current) if reader.current is not None and self.grammar else None
            out[r, [k for k in self.open if reader.fault(self.tokens[k]) is None and self._fits(reader, k, held)]] = True
            out[r, self.ix[EOS]] = reader.end_fault() is None
            if not out[r].any():  # nothing fits: the string ends here, unfinished (counted as a dead end)
                out[r, self.ix[EOS]] = True
                self.dead.add(row)
        return out

    def _held(self, reader: Reader, node: int) -> Counter:
        return node_bonds(reader.names, reader.edges, node, self.grammar)

    def _fits(self, reader: Reader, k: int, held: Counter | None) -> bool:
        """Whether token ``k`` keeps the string within the caps and the grammar (syntax aside)."""
        tok = self.tokens[k]
        if tok.startswith("["):
            name = tok[1:-1]
            if reader.names.count(name) >= self.caps.get(name, len(reader.names) + 1):
                return False
            return held is None or reader.bond is None or self._bond_fits(reader, held, name, None)
        if held is not None and tok.startswith("{"):  # a bond some new atom can take (a look ahead, no dead end)
            return any(self._bond_fits(reader, held, name, None, tok) for name in self.grammar.neighbours(
                reader.names[reader.current]) if reader.names.count(name) < self.caps.get(name, len(reader.names) + 1))
        if held is None or reader.bond is None or tok[0] not in "%@" or (tok[0] == "%" and int(tok[1:]) not in reader.rings):
            return True
        target = reader.rings[int(tok[1:])][0] if tok[0] == "%" else int(tok[1:])
        return self._bond_fits(reader, held, reader.names[target], target)

    def _bond_fits(self, reader: Reader, held: Counter, name: str, target: int | None, bond: str | None = None) -> bool:
        """The pending bond (or ``bond``) between the current atom and ``target`` (None: a new atom of class ``name``,
        written after it; else an earlier atom) within both nodes' grammar."""
        mine, theirs, here = [], [], reader.names[reader.current]
        for fwd, c in self.labels.get(bond or reader.bond, []):
            out = fwd if target is None else not fwd  # fwd: from the earlier atom to the later
            mine.append(self.grammar.bond(out, c, name))
            theirs.append(self.grammar.bond(not out, c, here))
        other = Counter() if target is None else self._held(reader, target)
        return self.grammar.fits(here, held, mine) and self.grammar.fits(name, other, theirs)


def decode(model: SeqVAE, z: torch.Tensor, prefixes: list[list[int]], vocab: TokenVocab, max_length: int,
           temperature: float, gen: torch.Generator, syntax: Syntax | None = None) -> np.ndarray:
    """``(n, <= max_length)`` token rows: ``<bos>``, each row's forced ``prefixes[k]`` tokens, then drawn tokens
    until ``<eos>`` (temperature 0: the most likely) or ``max_length``; ``syntax`` masks what may not come next."""
    model.eval()
    ix, n = vocab.index, len(z)
    forced = np.zeros((n, max_length), np.int64)
    for k, p in enumerate(prefixes):
        forced[k, :min(len(p), max_length)] = p[:max_length]
    plen = torch.tensor([len(p) for p in prefixes])
    out = torch.full((n, max_length), ix[PAD], dtype=torch.long)
    out[:, 0] = ix[BOS]
    done, h, forced_t = torch.zeros(n, dtype=torch.bool), model.initial(z), torch.from_numpy(forced)
    with torch.no_grad():
        for t in range(1, max_length):
            logits, h = model.decode(z, out[:, t - 1:t], h)
            logits = logits[:, -1]
            free = ((t > plen) & ~done).nonzero()[:, 0].tolist()
            if syntax is not None and free:
                logits[free] = logits[free].masked_fill(~syntax.mask(free), -torch.inf)
            nxt = (logits.argmax(1) if temperature <= 0
                   else torch.multinomial(torch.softmax(logits / temperature, 1), 1, generator=gen)[:, 0])
            nxt = torch.where(t <= plen, forced_t[:, t - 1], nxt)
            out[:, t] = torch.where(done, torch.full_like(nxt, ix[PAD]), nxt)
            if syntax is not None:
                for row in (~done).nonzero()[:, 0].tolist():
                    syntax.take(row, int(out[row, t]))
            done |= out[:, t] == ix[EOS]
            if bool(done.all()):
                break
    return out.numpy()
