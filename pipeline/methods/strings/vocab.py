"""Token vocabularies of room strings: the tokens the training strings hold, plus padding, start, end and unknown,
and strings as padded ``(batch, length)`` index arrays for the sequence VAE. Pure NumPy."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .serialize import tokens

PAD, BOS, EOS, UNK = "<pad>", "<bos>", "<eos>", "<unk>"
SPECIAL = (PAD, BOS, EOS, UNK)


@dataclass(frozen=True)
class TokenVocab:
    """``tokens``: index -> token, the four specials first."""
    tokens: tuple[str, ...]

    @property
    def index(self) -> dict[str, int]:
        return {t: k for k, t in enumerate(self.tokens)}

    def __len__(self) -> int:
        return len(self.tokens)

    def encode(self, strings: list[str], max_length: int | None = None) -> np.ndarray:
        """``(batch, length)`` int64: ``<bos>``, each string's tokens (unknown ones as ``<unk>``), ``<eos>``, padding;
        ``max_length`` cuts longer strings (their ``<eos>`` kept last)."""
        ix = self.index
        rows = [[ix[BOS], *(ix.get(t, ix[UNK]) for t in tokens(s)), ix[EOS]] for s in strings]
        if max_length is not None:
            rows = [r if len(r) <= max_length else r[:max_length - 1] + [ix[EOS]] for r in rows]
        out = np.zeros((len(rows), max((len(r) for r in rows), default=2)), np.int64)
        for k, r in enumerate(rows):
            out[k, :len(r)] = r
        return out

    def decode(self, row: np.ndarray) -> str:
        """The string of one index row: its tokens after ``<bos>`` up to ``<eos>`` (specials dropped)."""
        out = []
        for k in np.asarray(row).tolist():
            tok = self.tokens[k]
            if tok == EOS:
                break
            if tok not in SPECIAL:
                out.append(tok)
        return "".join(out)


def learn_vocab(strings: list[str]) -> TokenVocab:
    """The specials and every token of ``strings``, sorted (the same strings give the same indices)."""
    return TokenVocab(SPECIAL + tuple(sorted({t for s in strings for t in tokens(s)})))
