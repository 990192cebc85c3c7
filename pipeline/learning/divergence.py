"""The KL divergence of a diagonal Gaussian code from the standard normal prior, the term every VAE here (the string
VAE, GRAINS) adds to its reconstruction loss."""
from __future__ import annotations

from torch import Tensor


def gaussian_kl(mu: Tensor, logvar: Tensor) -> Tensor:
    """``(B, latent)`` nats: ``KL(N(mu, exp(logvar)) || N(0, 1))`` per example and latent dimension (sum over the last
    axis for an example's KL)."""
    return -0.5 * (1 + logvar - mu.pow(2) - logvar.exp())
