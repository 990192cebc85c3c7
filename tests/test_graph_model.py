"""The graph generative model (issue: learn and sample relation graphs): tiny preset, CPU, real procedural graphs."""
import subprocess
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from pipeline import config  # noqa: E402
from pipeline.corpus import procedural_rules  # noqa: E402
from pipeline.errors import InputError  # noqa: E402
from pipeline.evaluation import graphs as graph_metrics  # noqa: E402
from pipeline.graphs import (
    checks as graph_checks,  # noqa: E402
    data as graph_data,  # noqa: E402
)
from pipeline.graphs.checks import GraphRules  # noqa: E402
from pipeline.graphs.data import N_OBJECT_EDGES, OBJECT_EDGES, Graph  # noqa: E402
from pipeline.learning.epochs import Session  # noqa: E402
from pipeline.methods.planit.graph_model import (
    sampler,  # noqa: E402
    spec,  # noqa: E402
    train,  # noqa: E402
)

from conftest import ROOT  # noqa: E402

TINY = {**config.validate({})["graph_model"]["presets"]["tiny"]}


@pytest.fixture(scope="module")
def bedrooms(tmp_path_factory):
    """Final graphs of a few procedural bedrooms, through the real stages (ingest -> ... -> refinement)."""
    out = tmp_path_factory.mktemp("corpus")
    cfg = ROOT / "config" / "tiny.yaml"
    env = {"PATH": f"{Path(sys.executable).parent}:/usr/bin:/bin"}
    run = subprocess.run([str(Path(sys.executable).parent / "snakemake"), "-s", str(ROOT / "Snakefile"), "-d", str(out),
                          "--configfile", str(cfg), "--cores", "2", "results/graphs/ingested/edges.parquet"],
                         capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    import pandas as pd

    nodes = pd.read_parquet(out / "results/graphs/ingested/nodes.parquet")
    edges = pd.read_parquet(out / "results/graphs/ingested/edges.parquet")
    nodes, edges = nodes[nodes.room_type == "bedroom"], edges[edges.room_type == "bedroom"]
    vocab = graph_data.vocab_of(nodes)
    return vocab, graph_data.graphs_from_tables(nodes, edges, vocab)


def same_graph(a_classes, a_edges, b: Graph) -> bool:
    """Equal node classes in order and equal edge sets (node positions are the decision order for both)."""
    return list(a_classes) == b.node_class.tolist() and sorted(a_edges) == sorted(map(tuple, b.edges.tolist()))


def test_real_graphs_pass_the_validity_checks(bedrooms):
    _, graphs = bedrooms
    seen = graph_checks.seen_triples(graphs)
    assert all(not graph_checks.problems(g.node_class.tolist(), g.role.tolist(), [tuple(e) for e in g.edges.tolist()],
                                         g.n_arch, GraphRules(frozenset(seen))) for g in graphs)


def test_invalid_graphs_are_named():
    # wall 0; objects 1 (bed), 2 (nightstand), 3 (lamp); classes: 0 wall, 3 bed, 4 nightstand, 5 lamp
    cls, role = [0, 3, 4, 5], [0, 0, 0, 0]
    sup, left = OBJECT_EDGES.index("support"), OBJECT_EDGES.index("left/adjacent")
    wall = OBJECT_EDGES.index("front/adjacent")
    ok = [(0, 1, wall), (1, 2, left), (2, 3, sup)]
    seen = GraphRules(frozenset((cls[s], cls[t], c) for s, t, c in ok))
    assert graph_checks.problems(cls, role, ok, 1, seen) == []
    assert graph_checks.problems(cls, role, ok[:2], 1, seen) == ["disconnected"]
    assert graph_checks.problems(cls[:1], role[:1], [], 1, seen) == ["empty"]  # walls alone: no room to furnish
    assert "cyclic" in graph_checks.problems(cls, role, ok + [(3, 1, left)], 1, GraphRules(seen.seen | {(5, 3, left)}))
    assert graph_checks.problems(cls, role, ok + [(3, 2, left)], 1, seen) == ["cyclic", "unseen_edge"]
    chain = graph_checks.ROLES.index("chain")
    assert graph_checks.problems(cls, [0, chain, 0, 0], ok, 1, seen) == ["inconsistent_chain"]


def test_link_rules_hold_on_the_graphs_they_are_learned_from_and_name_what_breaks_them(bedrooms):
    """Every training graph keeps the link rules learned from them; a nightstand with no bed beside it is
    ``missing_link``, a bed with two lamps on it where every training bed holds at most one is ``excess_link``."""
    _, graphs = bedrooms
    rules = graph_checks.learn_links(graphs, 0.5)
    assert rules.required and rules.caps
    assert all(not graph_checks.link_problems(g.node_class.tolist(), [tuple(e) for e in g.edges.tolist()], g.n_arch, rules)
               for g in graphs)
    # wall 0; bed 1, nightstand 2, lamp 3; classes: 0 wall, 3 bed, 4 nightstand, 5 lamp
    cls = [0, 3, 4, 5]
    sup, left = OBJECT_EDGES.index("support"), OBJECT_EDGES.index("left/adjacent")
    wall = OBJECT_EDGES.index("front/adjacent")
    ok = [(0, 1, wall), (1, 2, left), (2, 3, sup)]
    hand = graph_checks.learn_links([Graph("r", ["w", "b", "n", "l"], np.array(cls), np.zeros(4, int), np.zeros(4, int),
                                           np.zeros(4), 1, np.array(ok), np.zeros(3))], 0.0)
    assert hand.required[4] == {(3, "left", "in"), (5, "support", "out")}
    assert graph_checks.link_problems(cls, ok, 1, hand) == []
    assert graph_checks.link_problems(cls, [(0, 1, wall), (0, 2, wall), (2, 3, sup)], 1, hand) == ["missing_link"]
    assert graph_checks.link_problems(cls + [5], ok + [(2, 4, sup)], 1, hand) == ["excess_link"]
    assert graph_checks.problems(cls + [5], [0] * 5, ok + [(2, 4, sup)], 1, GraphRules(
        frozenset([(0, 3, wall), (3, 4, left), (4, 5, sup)]), links=hand)) == ["excess_link"]
    assert graph_checks.link_problems(cls + [5], ok + [(2, 4, sup)], 1, graph_checks.learn_links([], 0.0)) == []


def bed_lamp_graph(real: Graph, vocab) -> Graph:
    """A real room's architecture holding a bed against wall_1, a nightstand on its left and a lamp on that."""
    a = real.n_arch
    inner = (real.edges[:, 0] < a) & (real.edges[:, 1] < a)
    cls = np.concatenate([real.node_class[:a], [vocab.category_index(c) for c in ("bed", "nightstand", "table_lamp")]])
    obj = [(real.node_ids.index("wall_1"), a, OBJECT_EDGES.index("front/adjacent")),
           (a, a + 1, OBJECT_EDGES.index("left/adjacent")), (a + 1, a + 2, OBJECT_EDGES.index("support"))]
    return Graph("hand", real.node_ids[:a] + ["bed", "nightstand", "lamp"], cls, np.zeros(a + 3, np.int64),
                 np.zeros(a + 3, np.int64), np.concatenate([real.length[:a], np.zeros(3)]), a,
                 np.concatenate([real.edges[inner], np.array(obj)]).astype(np.int64), np.concatenate([real.angle[inner], np.zeros(3)]))


def test_tiny_model_overfits_a_graph_and_greedy_sampling_reproduces_it(bedrooms, tmp_path):
    vocab, graphs = bedrooms
    g = bed_lamp_graph(graphs[0], vocab)
    run = train.train([g], [g], vocab, {**TINY, "max_epochs": 120, "patience": 120}, 10, Session(0, tmp_path / "ck.pt", "h"))
    assert run.history[-1]["validation_nll"] < 0.05 * run.history[0]["validation_nll"]
    out = sampler.sample(run.model, vocab, [g], seed=0, temperature=0.0, limits=sampler.Limits(25, 10))[0]
    assert same_graph(out.node_class, out.edges, g)


def test_resuming_from_a_checkpoint_gives_the_weights_of_an_uninterrupted_run(bedrooms, tmp_path):
    vocab, graphs = bedrooms
    tr, held = graphs[:-2], graphs[-2:]
    whole = train.train(tr, held, vocab, {**TINY, "max_epochs": 4, "patience": 99}, 10, Session(3, tmp_path / "a.pt", "h"))
    train.train(tr, held, vocab, {**TINY, "max_epochs": 2, "patience": 99}, 10, Session(3, tmp_path / "b.pt", "h"))  # interrupted
    resumed = train.train(tr, held, vocab, {**TINY, "max_epochs": 4, "patience": 99}, 10, Session(3, tmp_path / "b.pt", "h"))
    assert resumed.resumed_from == 2 and len(resumed.history) == 4
    for k, v in whole.model.state_dict().items():
        assert torch.equal(v, resumed.model.state_dict()[k]), k
    other = train.train(tr, held, vocab, {**TINY, "max_epochs": 1, "patience": 99}, 10, Session(3, tmp_path / "b.pt", "other"))
    assert other.resumed_from == 0  # a checkpoint of other settings is not resumed


@pytest.fixture(scope="module")
def model(bedrooms, tmp_path_factory):
    vocab, graphs = bedrooms
    run = train.train(graphs[:-1], graphs[-1:], vocab, {**TINY, "max_epochs": 15}, 10,
                      Session(0, tmp_path_factory.mktemp("m") / "ck.pt", "h"))
    return run.model


def test_sampling_with_a_seed_is_deterministic(bedrooms, model):
    vocab, graphs = bedrooms
    runs = [sampler.sample(model, vocab, graphs[:4], seed=s, temperature=1.0, limits=sampler.Limits(25, 10)) for s in (5, 5, 6)]
    key = lambda gs: [(g.node_class, g.edges) for g in gs]  # noqa: E731
    assert key(runs[0]) == key(runs[1]) and key(runs[0]) != key(runs[2])


def test_sampling_never_proposes_unseen_cyclic_or_second_parent_edges(bedrooms, model):
    vocab, graphs = bedrooms
    seen = GraphRules(frozenset(graph_checks.seen_triples(graphs)))
    out = sampler.sample(model, vocab, graphs * 4, seed=1, temperature=1.5, limits=sampler.Limits(25, 10, seen))
    for g in out:
        reasons = graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch, seen)
        assert "unseen_edge" not in reasons and "cyclic" not in reasons
        parents = [t for s, t, c in g.edges if c == 0]
        assert len(parents) == len(set(parents))


def test_an_edge_kind_that_joins_few_of_its_categorys_training_objects_is_never_proposed(bedrooms, model):
    # graph_model.sample.contents.min_edge_share: the kinds whose edges join under 20% of the training objects of
    # their target category drop out of the mask; the sampler, which draws some of them with every seen kind
    # allowed, then draws none
    vocab, graphs = bedrooms
    triples = lambda g: [(g.node_class[s], g.node_class[t], c) for s, t, c in g.edges if c < N_OBJECT_EDGES]
    edges, objects = Counter(t for g in graphs for t in triples(g)), Counter(c for g in graphs for c in g.node_class[g.n_arch:])
    every, common = graph_checks.seen_triples(graphs), graph_checks.seen_triples(graphs, 0.2)  # 5 rooms: 1 of 10 is rare
    rare = every - common
    assert every == set(edges) and rare and rare == {t for t, n in edges.items() if n < 0.2 * objects[t[1]]}
    draw = lambda seen: sampler.sample(model, vocab, graphs * 4, seed=1, temperature=1.5,
                                       limits=sampler.Limits(25, 10, GraphRules(frozenset(seen))))
    assert any(set(triples(g)) & rare for g in draw(every))
    assert not any(set(triples(g)) & rare for g in draw(common))


SPEC = """
room_type: bedroom
objects:
  - bed
  - side: nightstand
  - lamp: table_lamp
relations:
  side: {left_of: bed, distance: adjacent}
  lamp: {on_top_of: side}
"""


def test_completion_keeps_every_given_node_and_edge(bedrooms, model, tmp_path):
    vocab, graphs = bedrooms
    (tmp_path / "spec.yaml").write_text(SPEC)
    plan, arch = spec.load_spec(tmp_path / "spec.yaml", "bedroom", vocab)
    assert arch is None and len(plan.objects) == 3
    out = sampler.sample(model, vocab, graphs[:5], seed=2, temperature=1.0, limits=sampler.Limits(25, 10),
                         plans=[plan] * 5)
    cls = {c: vocab.category_index(c) for c in ("bed", "nightstand", "table_lamp")}
    for g in out:
        bed, side, lamp = (g.arch.n_arch + k for k in range(3))
        assert [g.node_class[k] for k in (bed, side, lamp)] == [cls["bed"], cls["nightstand"], cls["table_lamp"]]
        assert (bed, side, OBJECT_EDGES.index("left/adjacent")) in g.edges
        assert (side, lamp, OBJECT_EDGES.index("support")) in g.edges


@pytest.mark.parametrize("body, message", [
    ("room_type: bedroom\nobjects: [bed, harp]\n", "unknown category 'harp'"),
    ("room_type: bedroom\nobjects: [bed, nightstand]\nrelations:\n  nightstand: {left_of: bedd}\n", "no object named 'bedd'"),
    ("room_type: bedroom\nobjects: [bed, nightstand]\nrelations:\n  nightstand: {next_to: bed}\n", "unknown relation 'next_to'"),
    ("room_type: bedroom\nobjects: [bed]\nrelations:\n  sofa: {left_of: bed}\n", "no object named 'sofa'"),
    ("room_type: bedroom\nobjects: bed\n", "objects: 'bed' is not of type 'array'"),
    ("room_type: kitchen\nobjects: [bed]\n", "the model is for 'bedroom'"),
])
def test_invalid_specs_name_the_problem(bedrooms, tmp_path, body, message):
    vocab, _ = bedrooms
    (tmp_path / "bad.yaml").write_text(body)
    with pytest.raises(InputError, match=message.replace("(", r"\(")) as err:
        spec.load_spec(tmp_path / "bad.yaml", "bedroom", vocab)
    assert "bad.yaml" in str(err.value)


def test_example_specs_are_valid():
    import yaml

    from pipeline.corpus import furniture

    vocab = graph_data.Vocab(tuple(sorted(furniture.CATEGORIES)))  # every category the procedural corpus has
    files = sorted((ROOT / "config" / "specs").glob("*.yaml"))
    assert len(files) >= 2
    for f in files:
        plan, _ = spec.load_spec(f, yaml.safe_load(f.read_text())["room_type"], vocab)
        assert plan.objects and plan.edges


def test_metrics_separate_equal_and_different_sets(bedrooms):
    vocab, graphs = bedrooms
    same = graph_metrics.distances(graphs, graphs)
    assert same["category_kl"] < 1e-9 and same["node_count_tv"] == 0 and abs(same["degree_mmd"]) < 1e-9
    empty = [Graph(g.room_id, g.node_ids[:g.n_arch], g.node_class[:g.n_arch], g.symmetry[:g.n_arch], g.role[:g.n_arch],
                   g.length[:g.n_arch], g.n_arch, g.edges[(g.edges[:, 0] < g.n_arch) & (g.edges[:, 1] < g.n_arch)],
                   g.angle[(g.edges[:, 0] < g.n_arch) & (g.edges[:, 1] < g.n_arch)]) for g in graphs]
    assert graph_metrics.distances(graphs, empty)["node_count_tv"] == pytest.approx(1.0)
    nu = graph_metrics.novelty_uniqueness(graphs[:3] + graphs[:1], graphs[:2])
    assert nu["novelty"] == 0.25 and nu["uniqueness"] == 0.75


def test_procedural_rules_hold_on_real_graphs(bedrooms):
    vocab, graphs = bedrooms
    from pipeline.graphs.data import EDGE_CLASSES

    view = [([vocab.node_classes[c] for c in g.node_class], [(s, t, EDGE_CLASSES[c]) for s, t, c in g.edges]) for g in graphs]
    sat = procedural_rules.satisfaction(view)
    assert sat["against_wall"]["graphs"] == len(graphs) and sat["against_wall"]["share"] >= 0.8
    assert sat["small_things_on_surfaces"]["share"] == 1.0


def test_extraction_and_refinement_never_import_torch():
    code = ("import sys; import pipeline.extraction, pipeline.filtering, pipeline.graphs.refine, pipeline.stages.ingest, "
            "pipeline.stages.extract_graphs, pipeline.stages.refine_graphs, pipeline.cli, pipeline.graphs.data, "
            "pipeline.graphs.checks, pipeline.evaluation.graphs, pipeline.methods.planit.nets.data, "
            "pipeline.placement.search, pipeline.placement.checks, pipeline.placement.export, "
            "pipeline.placement.scene_metrics, pipeline.stages.instantiate, pipeline.stages.generate, "
            "pipeline.evaluation.distributions, pipeline.evaluation.physical, pipeline.room.walkability, "
            "pipeline.evaluation.render, pipeline.stages.evaluate; "
            "assert 'torch' not in sys.modules, 'torch'")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr


def test_device_is_chosen_automatically():
    assert train.pick_device("auto") == ("cuda" if torch.cuda.is_available() else "cpu")
    assert train.pick_device("cpu") == "cpu"


def test_batched_training_matches_one_graph_at_a_time(bedrooms):
    """The batch is a disjoint union: the NLL of a graph does not depend on the graphs batched with it."""
    from pipeline.methods.planit.graph_model.teacher import make_batch, nll

    vocab, graphs = bedrooms
    torch.manual_seed(0)
    m = train.build_model(vocab, TINY)
    rng = np.random.default_rng(0)
    seqs = [graph_data.sequence(g, rng, 10) for g in graphs[:4]]
    with torch.no_grad():
        together = nll(m, make_batch(seqs, vocab))
        alone = torch.cat([nll(m, make_batch([s], vocab)) for s in seqs])
    assert torch.allclose(together, alone, atol=1e-4)


def test_early_stopping_sees_validation_rooms_never_the_held_out_test_rooms():
    """The graph model picks its epoch on training rooms held back from fitting; the held-out rooms it is evaluated
    on (the same split the placement training and the evaluation use) take no part."""
    ids = [f"room_{k:03d}" for k in range(200)]
    gm = config.validate({})["graph_model"]

    def splits(seed):
        split = graph_data.room_splits(ids, gm["heldout_fraction"], gm["validation_fraction"], seed)
        return tuple(sorted(r for r, s in split.items() if s == part) for part in graph_data.SPLITS)

    fit, val, held = splits(0)
    assert sorted(fit + val + held) == ids and not (set(fit) & set(val)) and not (set(fit + val) & set(held))
    assert (len(held), len(val)) == (30, 17)  # 0.15 of 200, then 0.1 of the 170 left
    assert held == graph_data.split_heldout(ids, gm["heldout_fraction"], 0)[1]
    assert splits(0) == (fit, val, held) and splits(1)[1] != val


def test_count_caps_and_required_categories_keep_sampled_contents_plausible(bedrooms, model):
    """With every category capped at one, no sampled graph holds a category twice (at a high temperature, where the
    uncapped model repeats some); a graph without a required category is rejected by name."""
    vocab, graphs = bedrooms
    n_arch = len(graph_data.ARCH)
    cats = len(vocab.node_classes) - n_arch
    repeats = lambda gs: sum(len(g.node_class[g.arch.n_arch:]) != len(set(g.node_class[g.arch.n_arch:])) for g in gs)  # noqa: E731
    free = sampler.sample(model, vocab, graphs * 4, seed=3, temperature=2.0, limits=sampler.Limits(25, 10))
    allowed = frozenset((a, b, c) for a in range(len(vocab.node_classes)) for b in range(len(vocab.node_classes))
                        for c in range(graph_data.N_OBJECT_EDGES))  # every edge kind: only the caps differ
    capped = sampler.sample(model, vocab, graphs * 4, seed=3, temperature=2.0,
                            limits=sampler.Limits(25, 10, GraphRules(allowed, caps=np.ones(cats, int))))
    assert repeats(free) > 0 and repeats(capped) == 0
    assert not any(graph_checks.near_opposite_walls(g.node_class, g.edges) for g in capped)
    g = capped[0]
    absent = next(c for c in range(n_arch, len(vocab.node_classes)) if c not in g.node_class)
    assert "missing_required" in graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch,
                                                       GraphRules(frozenset(graph_checks.seen_triples(graphs)),
                                                                  frozenset({absent})))
    assert "missing_required" not in graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch,
                                                           GraphRules(frozenset(graph_checks.seen_triples(graphs)),
                                                                      frozenset({g.node_class[-1]})))


def test_every_training_graph_reads_back_from_random_strings(bedrooms):
    """Issue 31: parse(serialize(g)) is isomorphic to g for every procedural training graph and random orders."""
    from pipeline.methods.strings.serialize import arch_prefix, parse, serialize, serialize_room, string_graph

    from test_strings import isomorphic

    vocab, graphs = bedrooms
    rng = np.random.default_rng(0)
    for graph in graphs:
        g = string_graph(graph, vocab)
        assert len(g.edges) > len(g.names) - 1  # rings: the wall loop at least
        assert all(isomorphic(parse(serialize(g, rng)), g) for _ in range(5)), g
        prefix = arch_prefix(g, graph.n_arch)[0] + "."
        assert all((t := serialize_room(g, graph.n_arch, rng)).startswith(prefix) and isomorphic(parse(t), g)
                   for _ in range(5)), g


def test_a_room_string_is_read_back_into_its_room_and_broken_ones_are_rejected_by_cause(bedrooms):
    """Issue 31: the strings sampler's check (rooms.to_grown) gives a training room's own string back as the same
    graph in that room's architecture, and rejects a truncated string, an architecture atom written among the
    objects, a bond no training graph holds and an object standing apart, each by its cause."""
    from pipeline.methods.strings.rooms import Rules, to_grown
    from pipeline.methods.strings.serialize import StringGraph, serialize_room, string_graph

    from test_strings import isomorphic

    vocab, graphs = bedrooms
    rules = Rules(graphs, vocab, "neighbour", {"cap_counts": True, "required_share": 0.95, "links": "required",
                                              "min_edge_share": 0.0})
    room = graphs[0]
    text = serialize_room(string_graph(room, vocab), room.n_arch, np.random.default_rng(1))
    grown, bad = to_grown(text, room, vocab, rules)
    assert not bad and grown.arch is room
    back = StringGraph(tuple(vocab.node_classes[c] for c in grown.node_class), np.array(grown.edges))
    assert isomorphic(back, string_graph(room, vocab))
    arch = lambda edges: sorted(e for e in map(tuple, edges) if max(e[:2]) < room.n_arch)
    assert arch(grown.edges) == arch(room.edges[:, :3].tolist())  # the architecture node for node
    obj = next(c for c in vocab.categories if c in text)
    assert to_grown(text[:-3], room, vocab, rules)[1] == ["unparsable"]
    assert to_grown(text + ".[wall]{>support}@0", room, vocab, rules)[1] == ["unknown_object"]
    assert to_grown(text + f".[{obj}]{{>support}}@0", room, vocab, rules)[1] == ["grammar"]  # a wall on an object
    assert "disconnected" in to_grown(text + f".[{obj}]", room, vocab, rules)[1]
