"""Relation graphs as strings (issue 31, items 1-2): SMILES-like serialisation, parsing with precise errors, and
the grammar learned from training graphs. Round trips on real and procedural graphs are in test_graph_model.py and
test_sources.py (they reuse those files' pipeline runs)."""
from __future__ import annotations

import re

import networkx as nx
import numpy as np
import pytest

from pipeline.graphs.data import EDGE_CLASSES
from pipeline.methods.strings.grammar import learn_grammar
from pipeline.methods.strings.serialize import Reader, StringError, StringGraph, arch_prefix, parse, serialize, serialize_room, tokens

E = EDGE_CLASSES.index


def bedroom() -> StringGraph:
    """Four walls in a loop (wall 0 -> 1 both ways), a bed against wall 0, a nightstand right of the bed and against
    wall 0, a lamp on the nightstand."""
    edges = [(0, 1, E("wall_adjacent/left")), (1, 0, E("wall_adjacent/right")), (1, 2, E("wall_adjacent/left")),
             (2, 3, E("wall_adjacent/left")), (3, 0, E("wall_adjacent/left")), (0, 4, E("front/adjacent")),
             (4, 5, E("right/adjacent")), (5, 6, E("support")), (0, 5, E("front/adjacent"))]
    return StringGraph(("wall",) * 4 + ("bed", "nightstand", "table_lamp"), np.array(edges))


def isomorphic(a: StringGraph, b: StringGraph) -> bool:
    """Same graph up to node numbering: node classes and every directed edge with its class (multi-edges kept)."""
    def nx_graph(g: StringGraph) -> nx.MultiDiGraph:
        out = nx.MultiDiGraph()
        out.add_nodes_from((k, {"name": n}) for k, n in enumerate(g.names))
        out.add_edges_from((s, t, {"cls": c}) for s, t, c in g.edges.tolist())
        return out

    return nx.is_isomorphic(nx_graph(a), nx_graph(b), node_match=lambda x, y: x["name"] == y["name"],
                            edge_match=nx.algorithms.isomorphism.categorical_multiedge_match("cls", None))


def round_trips(graph: StringGraph, orders: int, seed: int = 0) -> bool:
    rng = np.random.default_rng(seed)
    return all(isomorphic(parse(serialize(graph, rng)), graph) for _ in range(orders))


def test_a_hand_built_room_gives_the_expected_canonical_string():
    assert serialize(bedroom()) == (
        "[wall]%1%2({<wall_adjacent/right|>wall_adjacent/left}[wall]{>wall_adjacent/left}[wall]"
        "{>wall_adjacent/left}[wall]{<wall_adjacent/left}%1){>front/adjacent}[bed]{>right/adjacent}[nightstand]"
        "{>front/adjacent}%2{>support}[table_lamp]")  # the wall loop and the nightstand's wall edge close rings
    assert isomorphic(parse(serialize(bedroom())), bedroom())


def test_random_depth_first_orders_all_read_back_to_the_same_graph():
    strings = {serialize(bedroom(), np.random.default_rng(s)) for s in range(40)}
    assert len(strings) > 10  # many strings per graph, as the paper trains on
    assert all(isomorphic(parse(s), bedroom()) for s in strings)
    assert any(not s.startswith("[wall]") for s in strings)  # random starts


def test_components_long_chains_and_digit_reuse_round_trip():
    chain = StringGraph(("wall",) + ("shelf",) * 1500, np.array([(k, k + 1, E("left/adjacent")) for k in range(1500)]))
    assert round_trips(chain, 2)  # iterative: no recursion limit
    apart = StringGraph(("wall", "wall", "rug", "plant"), np.array([(0, 1, E("wall_opposite")), (3, 2, E("support"))]))
    text = serialize(apart)
    assert "." in text and isomorphic(parse(text), apart)
    k5 = StringGraph(("x",) * 5, np.array([(a, b, E("front/distant")) for a in range(5) for b in range(a + 1, 5)]))
    assert round_trips(k5, 20)  # 6 ring closures, digits freed and reused
    digits = re.findall(r"%\d+", serialize(k5))
    assert len(digits) == 12 and max(int(t[1:]) for t in digits) == 5  # 6 rings, 5 open at once at most


@pytest.mark.parametrize("text, message", [
    ("[bed]{>front/adjacent}", "ends with a bond"),
    ("[bed][nightstand]", "token 1 '[nightstand]': an atom after an atom needs a bond"),
    ("[bed]({>support}[lamp]", "1 branch(es) not closed"),
    ("[bed]){>support}[lamp]", "token 1 ')': no open branch"),
    ("[bed]%1{>support}[lamp]", "ring 1 opened at token 1 is never closed"),
    ("[bed]%1{>support}[lamp]%1", "token 4 '%1': ring 1 is closed without a bond"),
    ("[bed]{>sideways/adjacent}[lamp]", "'>sideways/adjacent' in bond {>sideways/adjacent} is not"),
    ("{>support}[lamp]", "token 0 '{>support}': a bond must follow an atom"),
    ("[bed] ! [lamp]", "character 6: '!' begins no token"),
    ("[bed]{>support}@1", "token 2 '@1': atom 1 is not an earlier atom (this is atom 0)"),
    ("[bed]@0", "token 1 '@0': a reference needs an atom and a bond before it"),
    ("[bed]%1{>support}%1", "token 3 '%1': ring 1 closes on the atom that opened it"),
])
def test_malformed_strings_name_the_token_and_the_fault(text, message):
    with pytest.raises(StringError, match=re.escape(message)):
        parse(text)


def test_the_grammar_learned_from_training_graphs_rejects_unseen_bonds_classes_and_counts():
    grammar = learn_grammar([bedroom()])
    assert grammar.valid(bedroom())
    two_lamps = StringGraph(bedroom().names + ("table_lamp",), np.vstack([bedroom().edges, [(5, 7, E("support"))]]))
    assert grammar.violations(two_lamps) == ["node 5 (nightstand): 2 x >support table_lamp, at most 1 seen"]
    lamp_on_bed = StringGraph(bedroom().names, np.vstack([bedroom().edges[:-2], [(4, 6, E("support"))], bedroom().edges[-1:]]))
    assert "node 4 (bed): bond >support table_lamp never seen" in grammar.violations(lamp_on_bed)
    sofa = StringGraph(bedroom().names + ("sofa",), np.vstack([bedroom().edges, [(0, 7, E("front/adjacent"))]]))
    assert "node 7: class 'sofa' is in no training graph" in grammar.violations(sofa)


def test_a_coarser_grammar_accepts_what_the_edge_grammar_rejects():
    """At detail 'relation' a nightstand left of the bed instead of right is the same bond; at 'neighbour' a lamp
    proximal instead of on it is too; a class never seen is rejected at every detail."""
    moved = StringGraph(bedroom().names, bedroom().edges.copy())
    moved.edges[6, 2] = E("left/adjacent")  # bed -> nightstand
    assert learn_grammar([bedroom()], "edge").violations(moved) == [
        "node 4 (bed): bond >left/adjacent nightstand never seen", "node 5 (nightstand): bond <left/adjacent bed never seen"]
    assert learn_grammar([bedroom()], "relation").valid(moved)
    far = StringGraph(bedroom().names, bedroom().edges.copy())
    far.edges[7, 2] = E("front/proximal")  # nightstand -> lamp
    assert not learn_grammar([bedroom()], "relation").valid(far) and learn_grammar([bedroom()], "neighbour").valid(far)
    with pytest.raises(ValueError, match="grammar detail 'coarse'"):
        learn_grammar([bedroom()], "coarse")


def relabelled(graph: StringGraph, order: list[int]) -> set:
    """The edges of ``graph`` with its nodes renamed by ``order`` (node k -> order[k]), with their names."""
    return {(order[a], order[b], c, graph.names[a], graph.names[b]) for a, b, c in graph.edges.tolist()}


def test_a_room_string_starts_with_its_architecture_and_reads_back_to_the_same_nodes():
    """The prefix is the architecture's own string, the same for every order; the objects refer to its atoms, so
    the parsed graph's first atoms are the architecture's nodes in the prefix's order: the same graph, node for
    node, not only up to isomorphism."""
    g, n_arch = bedroom(), 4
    prefix, order = arch_prefix(g, n_arch)
    assert serialize_room(g, n_arch) == prefix + ".[bed]{>front/adjacent}@0{>right/adjacent}[nightstand]" \
                                              "{>front/adjacent}@0{>support}[table_lamp]"
    rng = np.random.default_rng(3)
    texts = {serialize_room(g, n_arch, rng) for _ in range(30)}
    assert len(texts) > 3 and all(t.startswith(prefix + ".") for t in texts)
    for text in texts:
        back = parse(text)
        objects = [k for k in range(n_arch, len(back.names))]
        assert sorted(back.names[n_arch:]) == sorted(g.names[n_arch:]) and back.names[:n_arch] == g.names[:n_arch]
        assert isomorphic(back, g)
        # architecture atoms map back exactly; objects by their (unique) names
        to_g = {**dict(enumerate(order)), **{k: g.names.index(back.names[k]) for k in objects}}
        assert relabelled(back, [to_g[k] for k in range(len(back.names))]) == relabelled(g, list(range(len(g.names))))


def test_the_parsers_fault_is_what_a_decoder_masks():
    """Reader.fault, asked token by token, allows exactly the tokens parse takes: every prefix of a valid string
    allows its next token, and the end only where parse accepts the string."""
    text = serialize_room(bedroom(), 4, np.random.default_rng(0))
    reader = Reader()
    toks = tokens(text)
    for i, tok in enumerate(toks):
        assert reader.fault(tok) is None
        assert (reader.end_fault() is None) == _parses("".join(toks[:i]))
        reader.read(tok, i)
    assert reader.end_fault() is None and reader.fault("[bed]") is not None  # an atom after an atom


def _parses(text: str) -> bool:
    try:
        parse(text)
        return True
    except StringError:
        return False
