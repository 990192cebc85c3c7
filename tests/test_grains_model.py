"""GRAINS's recursive VAE (pipeline/methods/grains/model.py, train.py): batched encoding and teacher-forced decoding
equal tree-by-tree ones; one bedroom learned by heart decodes back from its code (structure, labels, half extents,
codes, and so the laid-out centres); trees decoded from the prior are always well formed; training resumes exactly
from its progress file and starts over under another config hash."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
import torch

from pipeline.learning import checkpoint
from pipeline.learning.epochs import Session
from pipeline.methods.grains import train
from pipeline.methods.grains.hierarchy import KINDS, Node, build_tree, describe, layout, leaves, room_rect, tree_depth
from pipeline.methods.grains.model import CODE, GrainsVAE, Sizes
from pipeline.room import RoomInput

BEDROOM = ("root(wall(surround(bed,support(nightstand,table_lamp),support(nightstand,table_lamp))),"
           "wall(),wall(cooc(desk,chair)),wall())")
SMALL = {"feature": 32, "hidden": 64, "root_feature": 32, "root_hidden": 64, "batch_size": 4, "lr": 1e-3,
         "max_epochs": 3, "patience": 10, "kl_weight": 0.1}


@pytest.fixture(autouse=True)
def one_thread():
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


def box(cx: float, cy: float, hx: float, hy: float, hz: float, yaw: float = 0.0, base: float = 0.0) -> np.ndarray:
    return np.array([cx, cy, base + hz, hx, hy, hz, yaw])


def make_room(w: float, d: float, objects: list[tuple[str, str, np.ndarray]]) -> RoomInput:
    """A ``w`` x ``d`` m rectangular room holding ``objects`` ``(id, category, box)``."""
    outline = np.array([[0, 0], [w, 0], [w, d], [0, d]], float)
    n = len(objects)
    return RoomInput("r", "bedroom", 2.6, outline, [f"wall_{k}" for k in range(4)],
                     np.stack([outline, np.roll(outline, -1, 0)], 1), np.full(4, 0.1), [],
                     [o[0] for o in objects], [o[1] for o in objects], [f"m_{o[1]}" for o in objects],
                     np.array([o[2] for o in objects]).reshape(n, 7), np.zeros((n, 7)))


def bedroom(rng: np.random.Generator | None = None) -> tuple[RoomInput, dict[str, str | None]]:
    """About 4 x 3 m: a bed on the bottom wall flanked by nightstands with lamps, a desk on the top wall with a
    chair before it; ``rng`` jitters the room, the bed and the desk."""
    jit = (lambda s: float(rng.uniform(-s, s))) if rng is not None else (lambda s: 0.0)
    w, d, top = 4.0 + jit(0.5), 3.0 + jit(0.4), 0.55 + jit(0.05)
    bx, bhx, dx = w / 2 + jit(0.2), 0.8 + jit(0.1), 1.0 + jit(0.2)
    objects = [("bed", "bed", box(bx, 1.0, bhx, 1.0, 0.3)),
               ("ns_l", "nightstand", box(bx - bhx - 0.3, 0.25, 0.25, 0.25, top / 2)),
               ("ns_r", "nightstand", box(bx + bhx + 0.3, 0.25, 0.25, 0.25, top / 2)),
               ("lamp_l", "table_lamp", box(bx - bhx - 0.3, 0.25, 0.12, 0.12, 0.2, 0.3, top)),
               ("lamp_r", "table_lamp", box(bx + bhx + 0.3, 0.2, 0.12, 0.12, 0.2, -0.3, top)),
               ("desk", "desk", box(dx, d - 0.35, 0.6, 0.35, 0.38, math.pi)),
               ("chair", "chair", box(dx, d - 0.95, 0.25, 0.25, 0.45, 0.2))]
    return make_room(w, d, objects), {"lamp_l": "ns_l", "lamp_r": "ns_r"}


def small_rooms(n: int, seed: int) -> list[Node]:
    """``n`` jittered bedrooms, every third without its desk and chair, every fourth empty."""
    rng, out = np.random.default_rng(seed), []
    for k in range(n):
        room, parents = bedroom(rng)
        keep = 0 if k % 4 == 3 else 5 if k % 3 == 2 else 7
        room = make_room(float(room.outline[1, 0]), float(room.outline[2, 1]),
                         list(zip(room.object_ids, room.categories, room.boxes))[:keep])
        out.append(build_tree(room, parents))
    return out


LABELS = ["bed", "chair", "desk", "nightstand", "table_lamp", "wardrobe"]


def code_pairs(a: Node, b: Node):
    """(code of a, code of b) over two trees of one structure."""
    yield from zip(a.codes, b.codes)
    for x, y in zip(a.children, b.children):
        yield from code_pairs(x, y)


def test_batched_encoding_and_loss_equal_tree_by_tree():
    trees = [build_tree(*bedroom())] + small_rooms(7, 1)
    torch.manual_seed(0)
    model = GrainsVAE(LABELS, Sizes(24, 40, 20, 48))
    mu, logvar = model.encode(trees)
    assert mu.shape == logvar.shape == (8, 20)
    for k, tree in enumerate(trees):
        one_mu, one_logvar = model.encode([tree])
        assert torch.allclose(mu[k], one_mu[0], atol=1e-5) and torch.allclose(logvar[k], one_logvar[0], atol=1e-5)
    with torch.no_grad():
        batch = model.loss(trees, 0.1, sample=False)
        alone = [model.loss([t], 0.1, sample=False) for t in trees]
    for name in ("total", "recon", "kind", "label", "kl"):
        assert abs(float(batch[name]) - np.mean([float(a[name]) for a in alone])) < 1e-4 * (1 + abs(float(batch[name])))


@pytest.fixture(scope="module")
def learned() -> tuple[GrainsVAE, Node, RoomInput]:
    """A small VAE that has learned one bedroom by heart (500 Adam steps, no KL)."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    room, parents = bedroom()
    tree = build_tree(room, parents)
    torch.manual_seed(0)
    model = GrainsVAE(LABELS, Sizes(64, 128, 64, 128))
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    for _ in range(500):
        opt.zero_grad()
        model.loss([tree], 0.0, sample=False)["total"].backward()
        opt.step()
    torch.set_num_threads(threads)
    return model.eval(), tree, room


def test_a_bedroom_learned_by_heart_decodes_back(learned):
    model, tree, room = learned
    assert describe(tree) == BEDROOM
    out = model.decode(model.encode([tree])[0])[0]
    assert describe(out) == BEDROOM
    for a, b in zip(leaves(tree), leaves(out)):
        assert a.label == b.label and np.abs(a.half - b.half).max() < 0.02
    for a, b in zip(tree.children, out.children):
        assert np.abs(a.half - b.half).max() < 0.02
    for a, b in code_pairs(tree, out):
        assert np.abs(a[:3] - b[:3]).max() < 0.02 and np.array_equal(a[3:], b[3:])
    for (la, _, ba), (lb, _, bb) in zip(layout(tree, room_rect(room)), layout(out, room_rect(room))):
        assert la == lb and np.linalg.norm(ba[:3] - bb[:3]) < 0.05
    copy = GrainsVAE.from_spec(json.loads(json.dumps(model.spec())))
    copy.load_state_dict(model.state_dict())
    assert describe(copy.decode(copy.encode([tree])[0])[0]) == BEDROOM


def size(node: Node) -> int:
    return 1 + sum(size(c) for c in node.children)


def well_formed(node: Node, labels: list[str]) -> bool:
    """Children, codes and values as the tree format asks: finite, half extents >= 0.02 m, bits exactly 0/1."""
    if node.kind not in KINDS:
        return False
    if node.half is not None and not (np.isfinite(node.half).all() and node.half.min() >= 0.02):
        return False
    if node.kind == "leaf" and (node.label not in labels or node.half is None):
        return False
    for code in node.codes:
        if code.shape != (CODE,) or not np.isfinite(code).all() or not np.isin(code[3:], (0.0, 1.0)).all():
            return False
        if code[3:19].sum() != 2 or not -1 <= code[0] <= 1:
            return False
    return all(well_formed(c, labels) for c in node.children)


@pytest.mark.parametrize("trained", [False, True])
def test_trees_decoded_from_the_prior_are_well_formed(learned, trained):
    torch.manual_seed(1)
    model = learned[0] if trained else GrainsVAE(LABELS, Sizes(64, 128, 64, 128))
    trees = model.decode(torch.randn(200, 64, generator=torch.Generator().manual_seed(2)))
    good = [t for t in trees if t.kind == "root" and len(t.children) == 4 and tree_depth(t) <= 12 and size(t) <= 200
            and all(w.kind == "wall" and len(w.children) == len(w.codes) <= 1 for w in t.children)
            and well_formed(t, LABELS)]
    assert len(trees) == 200 and len(good) >= 198
    model.encode(trees)  # decoded trees are valid input (tensorize checks every node's children and codes)
    assert all(np.isfinite(b).all() for t in trees for _, _, b in layout(t, (0.0, 0.0, 4.0, 3.0)))
    assert max(tree_depth(t) for t in model.decode(torch.randn(50, 64), max_depth=3)) <= 3
    assert max(size(t) for t in model.decode(torch.randn(50, 64), max_nodes=20)) <= 20


def strip(history: list[dict]) -> list[dict]:
    """A history without its timings."""
    return [{k: v for k, v in row.items() if k not in ("seconds", "trees_per_s")} for row in history]


def test_training_resumes_exactly_and_starts_over_under_another_hash(tmp_path):
    fit, val = small_rooms(12, 3), small_rooms(4, 4)
    whole = train.train(fit, val, LABELS, SMALL, Session(5, tmp_path / "a.pt", "h1"))
    assert whole.resumed_from == 0 and [r["epoch"] for r in whole.history] == [1, 2, 3]
    assert all(set(r) == {"epoch", "train_loss", "train_kl", "validation_loss", "seconds", "trees_per_s"}
               for r in whole.history)
    assert whole.history[-1]["train_loss"] < whole.history[0]["train_loss"]
    saved = checkpoint.load(tmp_path / "a.pt", train.PROGRESS, "h1")
    assert saved.record["epoch"] == 3
    ticks = []
    cut = train.train(fit, val, LABELS, {**SMALL, "max_epochs": 2}, Session(5, tmp_path / "b.pt", "h1",
                                                                                 tick=lambda e, row: ticks.append(e)))
    assert ticks == [1, 2] and cut.resumed_from == 0
    resumed = train.train(fit, val, LABELS, SMALL, Session(5, tmp_path / "b.pt", "h1"))
    assert resumed.resumed_from == 2 and strip(resumed.history) == strip(whole.history)
    assert resumed.best_epoch == whole.best_epoch
    for p, q in zip(resumed.model.parameters(), whole.model.parameters()):
        assert torch.equal(p, q)
    other = train.train(fit, val, LABELS, SMALL, Session(5, tmp_path / "b.pt", "h2"))
    assert other.resumed_from == 0 and strip(other.history) == strip(whole.history)


def test_selection_by_samples_keeps_the_checked_epoch_whose_prior_is_nearest_the_validation_rooms(tmp_path):
    """``select: samples``: every ``select_every`` epochs the prior's samples are scored against the validation
    trees (category KL), the kept weights are those of the lowest score, and they reproduce it."""
    fit, val = small_rooms(12, 3), small_rooms(4, 4)
    preset = {**SMALL, "max_epochs": 6, "patience": 6, "select": "samples", "select_every": 2, "select_samples": 8}
    run = train.train(fit, val, LABELS, preset, Session(5, tmp_path / "a.pt", "h1"))
    checked = {r["epoch"]: r["sample_kl"] for r in run.history if "sample_kl" in r}
    assert list(checked) == [2, 4, 6] and all(np.isfinite(v) and v >= 0 for v in checked.values())
    assert run.best_epoch == min(checked, key=checked.get)
    assert train.sample_kl(run.model, val, preset, 5) == pytest.approx(checked[run.best_epoch], abs=1e-9)


def test_selection_by_samples_stops_after_patience_epochs_without_a_gain(tmp_path):
    """Patience counts epochs, checked or not: with a check every 2 epochs and patience 3, a run stops at most 3
    epochs after its best check."""
    fit, val = small_rooms(12, 3), small_rooms(4, 4)
    preset = {**SMALL, "max_epochs": 40, "patience": 3, "select": "samples", "select_every": 2, "select_samples": 8}
    run = train.train(fit, val, LABELS, preset, Session(5, tmp_path / "a.pt", "h1"))
    assert len(run.history) < 40 and len(run.history) - run.best_epoch <= 3
