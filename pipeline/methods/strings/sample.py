"""Decoding room strings from the sequence VAE, many at once: codes from the prior or on a straight path between
two rooms' codes (32 points in the paper), each decoded after a forced prefix (the room's architecture string and
``.``), token by token at a temperature."""
from __future__ import annotations

from collections import Counter

import numpy as np
import torch

from ...graphs.data import EDGE_CLASSES, N_OBJECT_EDGES
from .grammar import Grammar, bonds_of
from .model import SeqVAE
from .serialize import Reader, label_fault
from .vocab import BOS, EOS, PAD, SPECIAL, TokenVocab


def prior_codes(n: int, latent: int, gen: torch.Generator) -> torch.Tensor:
    """``(n, latent)`` codes from the standard normal prior."""
    return torch.randn(n, latent, generator=gen)


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
    With a ``grammar`` (``caps``: category -> most per room; ``seen``: (source class, target class, edge class)
    triples; ``required``: categories every room holds), a token that would give a node a bond the training graphs
    never hold, more of one than they hold, an edge of a kind never seen between its two classes, or a category more
    often than any training room is masked too, and the string may end only once it holds the required categories
    (as PlanIT's sampler masks unseen edges and counts)."""

    def __init__(self, vocab: TokenVocab, n: int, banned: set[int] = frozenset(), grammar: Grammar | None = None,
                 caps: dict[str, int] | None = None, seen: set[tuple[str, str, int]] | None = None,
                 required: set[str] = frozenset()):
        self.tokens, self.ix = vocab.tokens, vocab.index
        self.readers = [Reader() for _ in range(n)]
        self.open = [k for k, t in enumerate(vocab.tokens) if t not in SPECIAL and k not in banned]
        self.given = {vocab.tokens[k][1:-1] for k in banned}  # classes of the forced prefix only: referred to
        self.grammar, self.caps, self.seen, self.required = grammar, caps or {}, seen, set(required)
        self.dead: set[int] = set()  # rows where no token fitted
        self.base = [None] * n  # atoms of the forced prefix (the architecture), at the first "."
        self.start = [0] * n  # the first atom of the component being written
        self.labels = {t: [(lab[0] == ">", EDGE_CLASSES.index(lab[1:])) for lab in filter(None, t[1:-1].split("|"))]
                       for t in vocab.tokens if t.startswith("{") and label_fault(t) is None}

    def take(self, row: int, token: int) -> None:
        tok, reader = self.tokens[token], self.readers[row]
        if tok not in SPECIAL:
            reader.read(tok, len(reader.names))
        if tok == ".":
            self.base[row] = len(reader.names) if self.base[row] is None else self.base[row]
            self.start[row] = len(reader.names)

    def _anchored(self, row: int) -> bool:
        """The component being written has an edge to the architecture (else it would stand apart)."""
        base, start = self.base[row], self.start[row]
        return base is None or any(min(s, t) < base <= start <= max(s, t) for s, t, _ in self.readers[row].edges)

    def mask(self, rows: list[int]) -> torch.Tensor:
        """``(len(rows), vocab)`` bool: allowed next tokens of each row."""
        out = torch.zeros(len(rows), len(self.tokens), dtype=torch.bool)
        for r, row in enumerate(rows):
            reader = self.readers[row]
            held = self._held(reader) if reader.current is not None and self.grammar else None
            allowed = [k for k in self.open if reader.fault(self.tokens[k]) is None and self._fits(reader, k, held)]
            if held is not None and not any(self.tokens[k].startswith("{") for k in allowed):
                allowed = [k for k in allowed if not self._opens(reader, self.tokens[k])]  # nothing could go on there
            closes = held is None or self._anchored(row)
            out[r, [k for k in allowed if closes or self.tokens[k] != "."]] = True
            out[r, self.ix[EOS]] = reader.end_fault() is None and (held is None or (
                closes and self.required <= set(reader.names)))
            if not out[r].any():  # nothing fits: the string ends here, unfinished (counted as a dead end)
                out[r, self.ix[EOS]] = True
                self.dead.add(row)
        return out

    @staticmethod
    def _opens(reader: Reader, tok: str) -> bool:
        """A branch or a new ring: tokens that need a bond later."""
        return tok == "(" or (tok.startswith("%") and int(tok[1:]) not in reader.rings)

    def _held(self, reader: Reader) -> list[Counter]:
        """Every node's bonds so far, at the grammar's detail."""
        return bonds_of(reader.names, reader.edges, self.grammar.detail)

    def _under_cap(self, reader: Reader, name: str) -> bool:
        return reader.names.count(name) < self.caps.get(name, len(reader.names) + 1)

    def _takers(self, reader: Reader, held: list[Counter], bond: str) -> bool:
        """Whether some atom can take ``bond`` from the current atom: a new one of a class seen beside it, an earlier
        one of a given class (a reference) or one with an open ring (closing it)."""
        if any(o != reader.current and self._bond_fits(reader, held, reader.names[o], o, bond)
               for o, _ in reader.rings.values()):
            return True
        for name in self.grammar.neighbours(reader.names[reader.current]):
            if name in self.given:
                if any(self._bond_fits(reader, held, name, k, bond) for k, n in enumerate(reader.names[:reader.current])
                       if n == name):
                    return True
            elif self._under_cap(reader, name) and self._bond_fits(reader, held, name, None, bond):
                return True
        return False

    def _fits(self, reader: Reader, k: int, held: list[Counter] | None) -> bool:
        """Whether token ``k`` keeps the string within the caps and the grammar (syntax aside)."""
        tok = self.tokens[k]
        if tok.startswith("["):
            name = tok[1:-1]
            if not self._under_cap(reader, name):
                return False
            return held is None or reader.bond is None or self._bond_fits(reader, held, name, None)
        if held is not None and tok.startswith("{"):  # a bond some atom can take (a look ahead: fewer dead ends)
            return self._takers(reader, held, tok)
        if held is None or reader.bond is None or tok[0] not in "%@" or (tok[0] == "%" and int(tok[1:]) not in reader.rings):
            return True
        target = reader.rings[int(tok[1:])][0] if tok[0] == "%" else int(tok[1:])
        return self._bond_fits(reader, held, reader.names[target], target)

    def _bond_fits(self, reader: Reader, held: list[Counter], name: str, target: int | None,
                   bond: str | None = None) -> bool:
        """The pending bond (or ``bond``) between the current atom and ``target`` (None: a new atom of class ``name``,
        written after it; else an earlier atom) within both nodes' grammar."""
        mine, theirs, here = [], [], reader.names[reader.current]
        for fwd, c in self.labels.get(bond or reader.bond, []):
            out = fwd if target is None else not fwd  # fwd: from the earlier atom to the later
            if self.seen is not None and c < N_OBJECT_EDGES and ((here, name, c) if out else (name, here, c)) not in self.seen:
                return False
            mine.append(self.grammar.bond(out, c, name))
            theirs.append(self.grammar.bond(not out, c, here))
        other = Counter() if target is None else held[target]
        return self.grammar.fits(here, held[reader.current], mine) and self.grammar.fits(name, other, theirs)


def decode(model: SeqVAE, z: torch.Tensor, prefixes: list[list[int]], vocab: TokenVocab,
           draw: tuple[int, float, torch.Generator], syntax: Syntax | None = None) -> np.ndarray:
    """``(n, <= max_length)`` token rows: ``<bos>``, each row's forced ``prefixes[k]`` tokens, then drawn tokens
    until ``<eos>`` (temperature 0: the most likely) or ``max_length``; ``draw``: (max_length, temperature, the
    generator drawn from); ``syntax`` masks what may not come next."""
    max_length, temperature, gen = draw
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
