"""The pure statistics of S-AOG (pipeline.methods.saog.stats), each against a known truth."""
import numpy as np
from scipy import stats

from pipeline.methods.saog.stats import (
    affordance_energy,
    affordance_map,
    contrastive_divergence,
    fit_lognormal,
    fit_size_kde,
    fit_von_mises_mixture,
    learn_set,
    lognormal_energy,
    sample_node,
    sample_size,
    von_mises_energy,
)


def _circ(a, b):
    return abs(np.angle(np.exp(1j * (a - b))))


def test_lognormal_fit_and_energy():
    x = np.random.default_rng(0).lognormal(0.3, 0.4, size=20_000)
    mu, sigma = fit_lognormal(x)
    assert abs(mu - 0.3) < 0.02 * 0.3 and abs(sigma - 0.4) < 0.02 * 0.4
    pts = np.array([0.2, 1.0, 1.7, 4.0])
    want = -stats.lognorm.logpdf(pts, s=sigma, scale=np.exp(mu))
    np.testing.assert_allclose(lognormal_energy(pts, mu, sigma), want, rtol=1e-10)
    assert np.isfinite(lognormal_energy(np.array([0.0, -1.0]), mu, sigma)).all()


def test_von_mises_single():
    theta = np.random.default_rng(1).vonmises(1.0, 4.0, size=20_000)
    mix = fit_von_mises_mixture(theta, k=1)
    assert mix["weights"] == [1.0]
    assert _circ(mix["mu"][0], 1.0) < 0.02
    assert abs(mix["kappa"][0] - 4.0) < 0.02 * 4.0
    # the energy is the von Mises density's negative log
    pts = np.array([-2.0, 0.0, 1.0, 3.0])
    want = -stats.vonmises.logpdf(pts, mix["kappa"][0], loc=mix["mu"][0])
    np.testing.assert_allclose(von_mises_energy(pts, mix), want, rtol=1e-8)


def test_von_mises_mixture_recovers_two_modes():
    rng = np.random.default_rng(2)
    n = 20_000
    first = rng.random(n) < 0.3
    theta = np.where(first, rng.vonmises(0.0, 8.0, n), rng.vonmises(np.pi, 8.0, n))
    mix = fit_von_mises_mixture(theta, k=2, seed=0)
    for mu_true, w_true in ((0.0, 0.3), (np.pi, 0.7)):
        j = int(np.argmin([_circ(m, mu_true) for m in mix["mu"]]))
        assert _circ(mix["mu"][j], mu_true) < 0.05
        assert abs(mix["weights"][j] - w_true) < 0.03
        assert abs(mix["kappa"][j] - 8.0) < 0.1 * 8.0
    assert abs(sum(mix["weights"]) - 1) < 1e-9


def test_set_node_learns_and_samples():
    rng = np.random.default_rng(3)
    truth = np.array([0.2, 0.3, 0.5])
    n = 2000
    counts = rng.choice(3, size=n, p=truth)
    node = learn_set(counts)
    assert node["values"] == [0, 1, 2]
    probs = np.array(node["probs"])
    assert (np.abs(probs - truth) < 3 * np.sqrt(truth * (1 - truth) / n)).all()  # three binomial standard errors
    draws = np.array([sample_node(node, rng) for _ in range(5000)])
    observed = np.array([(draws == v).sum() for v in node["values"]])
    assert stats.chisquare(observed, probs * len(draws)).pvalue > 0.01
    assert learn_set(np.array([0, 5, 7]), max_count=5)["values"] == [0, 5]


def test_size_kde():
    rng = np.random.default_rng(5)
    sizes = np.abs(rng.normal([0.4, 0.3, 0.45], [0.05, 0.04, 0.03], size=(200, 3)))
    kde = fit_size_kde(sizes)
    assert np.all(np.array(kde["bandwidth"]) > 0)
    draws = sample_size(kde, rng, count=5000)
    assert draws.shape == (5000, 3) and (draws > 0).all()
    assert np.all(np.abs(draws.mean(axis=0) - sizes.mean(axis=0)) < 0.05 * sizes.mean(axis=0))
    one = fit_size_kde(np.array([[0.5, 0.2, 0.4]]))
    np.testing.assert_allclose(one["bandwidth"], [0.005, 0.002, 0.004])


def test_affordance_map():
    rng = np.random.default_rng(6)
    # a chair pulled up at (0, 0.6) in ten rooms, other seats scattered around the desk
    chairs = np.concatenate([np.tile([0.0, 0.6], (10, 1)), rng.uniform(-2, 2, size=(40, 2))])
    amap = affordance_map(chairs)
    assert amap.shape == (20, 20) and abs(amap.sum() - 1) < 1e-12
    peak = np.unravel_index(np.argmax(amap), amap.shape)
    assert peak == (13, 10)  # row: y = 0.6 m in bin 13 of 20 over +-2 m; column: x = 0 in bin 10
    empty = np.array([[-1.9, -1.9]])
    assert affordance_energy(amap, np.array([[0.0, 0.6]])) < affordance_energy(amap, empty)
    # the best human counts: adding a far one changes nothing; outside scores the prior; no humans: 0
    both = np.array([[0.0, 0.6], [-1.9, -1.9]])
    assert affordance_energy(amap, both) == affordance_energy(amap, np.array([[0.0, 0.6]]))
    assert affordance_energy(amap, np.array([[5.0, 5.0]])) == affordance_energy(amap, empty)
    assert affordance_energy(amap, np.zeros((0, 2))) == 0.0


def test_contrastive_divergence_recovers_weights():
    g = np.linspace(-2, 2, 41)
    grid = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    feats = np.stack([grid[:, 0] ** 2, np.abs(grid[:, 1])], axis=1)

    def sample(w, rng, m=2000):
        logits = -feats @ w
        p = np.exp(logits - logits.max())
        return feats[rng.choice(len(feats), size=m, p=p / p.sum())]

    w_true = np.array([2.0, 1.5])
    data = sample(w_true, np.random.default_rng(7), 5000)
    start = 0.5 * w_true
    w, history = contrastive_divergence(data, sample, start, lr=0.05, iters=300, tol=1e-3, seed=8)
    assert np.all(np.abs(w - w_true) < np.abs(start - w_true))
    assert np.all(np.abs(w - w_true) < 0.15 * w_true)
    assert len(history) > 1 and history[0]["w0"] == 1.0 and {"iter", "grad_norm", "w1"} <= set(history[-1])
    assert history[-1]["grad_norm"] < history[0]["grad_norm"]
