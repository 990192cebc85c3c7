"""The pure statistical pieces of S-AOG (Qi et al., "Human-centric indoor scene synthesis using stochastic grammar",
CVPR 2018), over NumPy arrays; no torch.

- Log-normal fits of distances (section 4.1, the relative-distance potentials of the pairwise and wall terms).
- Von Mises mixtures of relative orientations (section 4.1; the released code fits mixtures of angles).
- The grammar's Set nodes (section 3: how many of a category a room holds; the paper's Or nodes are flattened away,
  ``docs/departures.md``), learned as frequencies (section 4.2, maximum likelihood), drawn from when a room is sampled
  (section 5).
- Object sizes as a kernel density over the training half-extents (section 4.2).
- Affordance maps (section 4.1, l_hum; Table 2): where the "humans" (the centres of seats and beds) stand in an
  object's frame, 20 x 20 bins over +-2 m as in the released code.
- Contrastive divergence for the potentials' weights (section 4.2, eq. 21, one short chain per step).

Angles are in radians, lengths in metres. Energies are negative log densities."""
from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.special import i0e, i1e, logsumexp

LOG_2PI = float(np.log(2 * np.pi))


# ---------------------------------------------------------------- log-normal (section 4.1)

def fit_lognormal(x: np.ndarray, floor: float = 1e-3) -> tuple[float, float]:
    """Maximum-likelihood (mu, sigma) of log(max(x, floor)) over the values ``x`` (any shape, m); sigma >= 1e-3."""
    y = np.log(np.maximum(np.asarray(x, dtype=float).ravel(), floor))
    if y.size == 0:
        raise ValueError("fit_lognormal needs at least one value")
    return float(y.mean()), float(max(y.std(), 1e-3))


def lognormal_energy(x: np.ndarray, mu: float, sigma: float, floor: float = 1e-3) -> np.ndarray:
    """Negative log density of the log-normal (mu, sigma) at ``x`` (elementwise; x <= 0 is read as ``floor``)."""
    xs = np.maximum(np.asarray(x, dtype=float), floor)
    y = np.log(xs)
    return y + np.log(sigma) + 0.5 * LOG_2PI + (y - mu) ** 2 / (2 * sigma ** 2)


# ---------------------------------------------------------------- von Mises mixtures (section 4.1)

def _von_mises_logpdf(theta: np.ndarray, mu: np.ndarray, kappa: np.ndarray) -> np.ndarray:
    """(n,) angles against (k,) components -> (n, k) log densities; log I0(kappa) = log i0e(kappa) + kappa."""
    d = np.cos(theta[:, None] - mu[None, :]) - 1.0
    return kappa[None, :] * d - LOG_2PI - np.log(i0e(kappa))[None, :]


def _kappa_from_resultant(r: np.ndarray, newton_steps: int = 2, lo: float = 1e-3, hi: float = 500.0) -> np.ndarray:
    """A^-1(r) for mean resultant lengths ``r`` (k,): Banerjee's r(2-r^2)/(1-r^2), then ``newton_steps`` Newton
    steps on A(kappa) = I1/I0 = r (Sra 2012; 0 keeps the plain approximation), clipped to [lo, hi]."""
    r = np.clip(np.asarray(r, dtype=float), 0.0, 1.0 - 1e-9)
    kappa = np.clip(r * (2 - r ** 2) / (1 - r ** 2), lo, hi)
    for _ in range(newton_steps):
        a = i1e(kappa) / i0e(kappa)
        slope = np.maximum(1 - a ** 2 - a / kappa, 1e-12)
        kappa = np.clip(kappa - (a - r) / slope, lo, hi)
    return kappa


def _circular_kmeanspp(theta: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """(k,) initial means: k-means++ on the circle with the chord distance 1 - cos."""
    centres = [theta[rng.integers(theta.size)]]
    for _ in range(1, k):
        d = np.min(1 - np.cos(theta[:, None] - np.asarray(centres)[None, :]), axis=1) ** 2
        p = d / d.sum() if d.sum() > 0 else None
        centres.append(theta[rng.choice(theta.size, p=p)])
    return np.asarray(centres, dtype=float)


def fit_von_mises_mixture(theta: np.ndarray, k: int = 4, iters: int = 100, seed: int = 0, *,
                          newton_steps: int = 2, kappa_range: tuple[float, float] = (1e-3, 500.0),
                          min_weight: float = 1e-6) -> dict:
    """EM for a k-component von Mises mixture of the angles ``theta`` (n,) (rad). Means start by k-means++ on the
    circle (seeded); kappa by Banerjee's approximation refined by ``newton_steps`` Newton steps (0: Banerjee alone).
    k=1 is the plain von Mises MLE. Returns ``{"weights", "mu", "kappa"}``, each a list of k floats."""
    theta = np.mod(np.asarray(theta, dtype=float).ravel(), 2 * np.pi)
    if theta.size == 0:
        raise ValueError("fit_von_mises_mixture needs at least one angle")
    mu = _circular_kmeanspp(theta, k, np.random.default_rng(seed))
    kappa, weights = np.ones(k), np.full(k, 1.0 / k)
    for _ in range(iters if k > 1 else 1):
        if k > 1:
            logp = np.log(weights)[None, :] + _von_mises_logpdf(theta, mu, kappa)
            resp = np.exp(logp - logsumexp(logp, axis=1, keepdims=True))
        else:
            resp = np.ones((theta.size, 1))
        mass = np.maximum(resp.sum(axis=0), 1e-12)
        c, s = resp.T @ np.cos(theta), resp.T @ np.sin(theta)
        mu = np.arctan2(s, c)
        kappa = _kappa_from_resultant(np.hypot(c, s) / mass, newton_steps, *kappa_range)
        weights = np.maximum(mass / theta.size, min_weight)
        weights = weights / weights.sum()
    return {"weights": [float(w) for w in weights], "mu": [float(m) for m in mu], "kappa": [float(v) for v in kappa]}


def von_mises_energy(theta: np.ndarray, mix: dict) -> np.ndarray:
    """Negative log density of the mixture ``mix`` (from fit_von_mises_mixture) at the angles ``theta`` (any shape)."""
    theta = np.asarray(theta, dtype=float)
    logp = np.log(np.asarray(mix["weights"], dtype=float))[None, :] + _von_mises_logpdf(
        theta.ravel(), np.asarray(mix["mu"], dtype=float), np.asarray(mix["kappa"], dtype=float))
    return -logsumexp(logp, axis=1).reshape(theta.shape)


# ---------------------------------------------------------------- grammar nodes (sections 3, 4.2)

def learn_set(counts: np.ndarray, max_count: int | None = None) -> dict:
    """A Set node: the empirical distribution of a category's count per training room (``counts`` (n,), ints >= 0;
    counts above ``max_count`` are read as ``max_count``). Returns ``{"values": sorted ints, "probs": floats}``."""
    c = np.asarray(counts).ravel().astype(int)
    if c.size == 0 or (c < 0).any():
        raise ValueError("learn_set needs at least one count, all non-negative")
    if max_count is not None:
        c = np.minimum(c, max_count)
    values, freq = np.unique(c, return_counts=True)
    return {"values": [int(v) for v in values], "probs": [float(f) for f in freq / c.size]}


def sample_node(node: dict, rng: np.random.Generator) -> int:
    """One draw from a Set node: a count."""
    return int(node["values"][rng.choice(len(node["values"]), p=node["probs"])])


# ---------------------------------------------------------------- sizes by kernel density (section 4.2)

def fit_size_kde(sizes: np.ndarray, min_bandwidth: float = 1e-3, single_scale: float = 0.01) -> dict:
    """A Gaussian KDE over half-extents ``sizes`` (n, 3) (m), bandwidth per dimension by Scott's rule
    std * n^(-1/(d+4)) floored at ``min_bandwidth``; one point gets ``single_scale`` * its size.
    Returns ``{"points": (n, 3) list, "bandwidth": (3,) list}``."""
    pts = np.asarray(sizes, dtype=float).reshape(-1, 3)
    if len(pts) == 0:
        raise ValueError("fit_size_kde needs at least one size")
    if len(pts) == 1:
        bw = np.maximum(single_scale * np.abs(pts[0]), min_bandwidth)
    else:
        bw = np.maximum(pts.std(axis=0, ddof=1) * len(pts) ** (-1.0 / (pts.shape[1] + 4)), min_bandwidth)
    return {"points": pts.tolist(), "bandwidth": bw.tolist()}


def sample_size(kde: dict, rng: np.random.Generator, count: int = 1, min_fraction: float = 0.5) -> np.ndarray:
    """(count, 3) half-extents (m) drawn from ``kde``: a training point plus Gaussian noise of the bandwidth, clipped
    to >= ``min_fraction`` * the smallest point per dimension."""
    pts, bw = np.asarray(kde["points"], dtype=float), np.asarray(kde["bandwidth"], dtype=float)
    out = pts[rng.integers(len(pts), size=count)] + rng.normal(size=(count, pts.shape[1])) * bw
    return np.maximum(out, min_fraction * pts.min(axis=0))


# ---------------------------------------------------------------- affordance maps (section 4.1, Table 2)

def _bin_index(local_xy: np.ndarray, bins: int, extent: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(n, 2) points in an object's frame -> (rows, cols, inside), each (n,); the upper edge is in the last bin."""
    xy = np.asarray(local_xy, dtype=float).reshape(-1, 2)
    idx = np.floor((xy + extent) / (2 * extent) * bins).astype(int)
    inside = np.all((xy >= -extent) & (xy <= extent), axis=1)
    idx = np.clip(idx, 0, bins - 1)
    return idx[:, 1], idx[:, 0], inside


def affordance_map(local_xy: np.ndarray, bins: int = 20, extent: float = 2.0, prior: float = 1e-3) -> np.ndarray:
    """(bins, bins) map of human positions ``local_xy`` (n, 2) (m, x right, y forward in the object's frame, within
    +-``extent``): counts per cell (row = y bin, col = x bin) plus ``prior``, normalised to sum 1 (uniform if empty)."""
    rows, cols, inside = _bin_index(local_xy, bins, extent)
    amap = np.full((bins, bins), float(prior))
    np.add.at(amap, (rows[inside], cols[inside]), 1.0)
    total = amap.sum()
    return amap / total if total > 0 else np.full((bins, bins), 1.0 / bins ** 2)


def affordance_energy(amap: np.ndarray, local_xy: np.ndarray, extent: float = 2.0,
                      outside: float | None = None, floor: float = 1e-12) -> float:
    """l_hum: -log of the best map value over the humans ``local_xy`` (n, 2) (m, object frame); a point outside the
    map scores ``outside`` (default the map's smallest cell, i.e. its normalised prior). No humans: 0.0."""
    xy = np.asarray(local_xy, dtype=float).reshape(-1, 2)
    if len(xy) == 0:
        return 0.0
    amap = np.asarray(amap, dtype=float)
    rows, cols, inside = _bin_index(xy, amap.shape[0], extent)
    fallback = float(amap.min()) if outside is None else outside
    values = np.where(inside, amap[rows, cols], fallback)
    return float(-np.log(max(values.max(), floor)))


# ---------------------------------------------------------------- contrastive divergence (section 4.2, eq. 21)

def contrastive_divergence(data_features: np.ndarray,
                           sample_features: Callable[[np.ndarray, np.random.Generator], np.ndarray],
                           weights: np.ndarray, lr: float = 0.01, iters: int = 200, tol: float = 0.1,
                           seed: int = 0) -> tuple[np.ndarray, list[dict]]:
    """Weights of the energy E = sum_t w_t f_t by contrastive divergence. ``data_features`` (n, T): the potentials on
    the training rooms; ``sample_features(w, rng)`` (m, T): the same on rooms sampled under ``w``. Step:
    w <- max(0, w + lr * (mean f(samples) - mean f(data))); stops once the gradient's norm < ``tol``.
    Returns the weights (T,) and one history row per step: iter, grad_norm, w0..w{T-1} (the weights sampled under)."""
    data_mean = np.asarray(data_features, dtype=float).mean(axis=0)
    w = np.asarray(weights, dtype=float).copy()
    rng = np.random.default_rng(seed)
    history: list[dict] = []
    for it in range(iters):
        grad = np.asarray(sample_features(w.copy(), rng), dtype=float).mean(axis=0) - data_mean
        norm = float(np.linalg.norm(grad))
        history.append({"iter": it, "grad_norm": norm, **{f"w{t}": float(v) for t, v in enumerate(w)}})
        if norm < tol:
            break
        w = np.maximum(w + lr * grad, 0.0)
    return w, history
