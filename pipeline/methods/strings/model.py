"""The sequence VAE of room strings (Kalojanov et al. 2019, section 5, after the chemical VAE and Bowman et al.): a
bidirectional GRU encodes a string's tokens to a Gaussian code, a GRU decodes the code back token by token (the code
given at every step and as the first hidden state). Sizes come from the ``strings`` presets."""
from __future__ import annotations

import torch
from torch import nn
from torch.nn.utils.rnn import pack_padded_sequence

from ...learning.divergence import gaussian_kl


class SeqVAE(nn.Module):
    def __init__(self, vocab_size: int, embed: int, hidden: int, latent: int, layers: int = 1):
        super().__init__()
        self.layers, self.hidden = layers, hidden
        self.embed = nn.Embedding(vocab_size, embed, padding_idx=0)
        self.encoder = nn.GRU(embed, hidden, layers, batch_first=True, bidirectional=True)
        self.to_mu, self.to_logvar = nn.Linear(2 * hidden, latent), nn.Linear(2 * hidden, latent)
        self.to_hidden = nn.Linear(latent, layers * hidden)
        self.decoder = nn.GRU(embed + latent, hidden, layers, batch_first=True)
        self.out = nn.Linear(hidden, vocab_size)

    def encode(self, x: torch.Tensor, lengths: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """``x (B, T)`` token indices, ``lengths (B,)``: the code's mean and log-variance, each ``(B, latent)``."""
        packed = pack_padded_sequence(self.embed(x), lengths.cpu(), batch_first=True, enforce_sorted=False)
        _, h = self.encoder(packed)  # (layers * 2, B, hidden)
        last = torch.cat([h[-2], h[-1]], dim=1)
        return self.to_mu(last), self.to_logvar(last).clamp(-10.0, 10.0)

    def initial(self, z: torch.Tensor) -> torch.Tensor:
        """The decoder's first hidden state ``(layers, B, hidden)`` from codes ``z (B, latent)``."""
        return torch.tanh(self.to_hidden(z)).view(len(z), self.layers, self.hidden).transpose(0, 1).contiguous()

    def decode(self, z: torch.Tensor, inputs: torch.Tensor, h: torch.Tensor | None = None):
        """Logits ``(B, T, vocab)`` of the next token after each of ``inputs (B, T)`` (teacher forcing), and the last
        hidden state."""
        h = self.initial(z) if h is None else h
        steps = torch.cat([self.embed(inputs), z[:, None].expand(-1, inputs.shape[1], -1)], dim=2)
        y, h = self.decoder(steps, h)
        return self.out(y), h

    def forward(self, x: torch.Tensor, lengths: torch.Tensor, inputs: torch.Tensor | None = None,
                noise: torch.Tensor | None = None):
        """Logits of ``x[:, 1:]`` given ``inputs`` (default ``x[:, :-1]``; word dropout passes a masked copy), the
        code's mean and log-variance. The code is ``mu + noise * std`` (``noise (B, latent)``, standard normal;
        None: the mean)."""
        mu, logvar = self.encode(x, lengths)
        z = mu if noise is None else mu + noise.to(mu.device) * torch.exp(0.5 * logvar)
        logits, _ = self.decode(z, x[:, :-1] if inputs is None else inputs)
        return logits, mu, logvar


def kl_objective(mu: torch.Tensor, logvar: torch.Tensor, free_bits: float) -> torch.Tensor:
    """The KL term a training step minimises, a scalar per string: each latent dimension's KL averaged over the
    batch ``mu, logvar (B, latent)`` and held at ``free_bits`` nats at least (Kingma et al. 2016), summed over the
    dimensions; 0: the plain KL's batch mean."""
    return torch.clamp(gaussian_kl(mu, logvar).mean(0), min=free_bits).sum()


def losses(logits: torch.Tensor, x: torch.Tensor, mu: torch.Tensor, logvar: torch.Tensor,
           forced: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
    """Per string ``(B,)``: the reconstruction NLL of ``x[:, 1:]`` (padding ignored; with ``forced (B,)`` the first
    ``forced`` tokens too: the architecture a sampled string is given, not drawn) and the KL from the prior."""
    target = x[:, 1:]
    if forced is not None:
        target = target.masked_fill(torch.arange(target.shape[1], device=x.device)[None] < forced[:, None], 0)
    nll = nn.functional.cross_entropy(logits.transpose(1, 2), target, ignore_index=0, reduction="none").sum(1)
    return nll, gaussian_kl(mu, logvar).sum(1)
