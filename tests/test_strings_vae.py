"""The string VAE (issue 31, item 3): token vocabularies, syntax-masked decoding, exact resumption and a known
answer (one room learned by heart is decoded back from its code). The workflow runs it as the `strings` method in
test_e2e.py."""
from __future__ import annotations

import numpy as np
import torch

from pipeline.learning.epochs import Session
from pipeline.methods.strings import sample as decoding, train
from pipeline.methods.strings.grammar import learn_grammar
from pipeline.methods.strings.serialize import StringError, arch_prefix, parse, serialize_room
from pipeline.methods.strings.vocab import EOS, UNK, learn_vocab

from test_strings import bedroom, isomorphic

PRESET = {"embed": 16, "hidden": 48, "latent": 8, "layers": 1, "batch_size": 16, "lr": 0.01, "max_epochs": 3,
          "patience": 50, "kl_anneal": 2, "strings_per_room": 4, "word_dropout": 0.0, "max_length": 200, "clip": 5.0,
          "free_bits": 0.0}
ROOM = (bedroom(), 4)


def vocab_of(rooms):
    return learn_vocab([t for t, _ in train.room_strings(rooms, np.random.default_rng(0), 20)])


def test_strings_encode_to_padded_indices_and_decode_back():
    vocab = vocab_of([ROOM])
    text = serialize_room(*ROOM)
    rows = vocab.encode([text, "[wall].[sofa]"])
    assert rows.shape[0] == 2 and rows[0, 0] == vocab.index["<bos>"] and vocab.decode(rows[0]) == text
    assert rows[1].tolist()[:5] == [vocab.index[t] for t in ("<bos>", "[wall]", ".", UNK, EOS)]
    assert (rows[1, 5:] == 0).all()  # padding
    cut = vocab.encode([text], max_length=6)[0]
    assert len(cut) == 6 and cut[-1] == vocab.index[EOS]


def test_syntax_masked_decoding_writes_only_strings_that_parse():
    """An untrained VAE draws near-uniform tokens: without the mask almost nothing parses; with it every string that
    ends parses, and its first atoms are the forced architecture."""
    vocab = vocab_of([ROOM])
    torch.manual_seed(0)
    model = train.build_model(vocab, PRESET)
    prefix = vocab.encode([arch_prefix(*ROOM)[0] + "."])[0, 1:-1].tolist()
    gen = torch.Generator().manual_seed(1)
    z = decoding.prior_codes(64, PRESET["latent"], gen)

    def parsed(syntax):
        rows = decoding.decode(model, z, [prefix] * 64, vocab, (120, 1.0, gen), syntax)
        ended = [vocab.decode(r) for r in rows if vocab.index[EOS] in r]
        ok = []
        for text in ended:
            try:
                ok.append(parse(text))
            except StringError:
                pass
        return ended, ok

    ended, ok = parsed(decoding.Syntax(vocab, 64, {vocab.index["[wall]"]}))
    assert ended and len(ok) == len(ended)
    assert all(g.names[:4] == ("wall",) * 4 and "wall" not in g.names[4:] for g in ok)
    raw_ended, raw_ok = parsed(None)
    assert len(raw_ok) < len(ok)


def test_the_grammar_mask_writes_only_graphs_the_training_grammar_holds():
    """With the grammar and count caps learned from one bedroom, every string an untrained VAE ends (not at a dead
    end) gives a graph the grammar accepts and with at most one bed: the mask, not the network, keeps it."""
    vocab = vocab_of([ROOM])
    torch.manual_seed(0)
    model = train.build_model(vocab, PRESET)
    grammar = learn_grammar([ROOM[0]], "edge")
    prefix = vocab.encode([arch_prefix(*ROOM)[0] + "."])[0, 1:-1].tolist()
    gen = torch.Generator().manual_seed(2)
    mask = decoding.Syntax(vocab, 32, {vocab.index["[wall]"]}, grammar, {"bed": 1, "nightstand": 1, "table_lamp": 1})
    rows = decoding.decode(model, decoding.prior_codes(32, PRESET["latent"], gen), [prefix] * 32, vocab, (120, 1.0, gen),
                           mask)
    graphs = [parse(vocab.decode(r)) for k, r in enumerate(rows) if vocab.index[EOS] in r and k not in mask.dead]
    assert graphs and all(grammar.valid(g) and g.names.count("bed") <= 1 for g in graphs)
    assert any("bed" in g.names for g in graphs)


def test_an_interrupted_training_resumes_to_the_same_weights(tmp_path):
    rooms = [ROOM] * 3
    vocab = vocab_of(rooms)
    straight = train.train(rooms, [ROOM], vocab, {**PRESET, "max_epochs": 4}, Session(0, tmp_path / "a.pt", "h"))
    train.train(rooms, [ROOM], vocab, {**PRESET, "max_epochs": 2}, Session(0, tmp_path / "b.pt", "h"))
    resumed = train.train(rooms, [ROOM], vocab, {**PRESET, "max_epochs": 4}, Session(0, tmp_path / "b.pt", "h"))
    assert resumed.resumed_from == 2 and len(resumed.history) == 4
    for k, v in straight.model.state_dict().items():
        assert torch.equal(v, resumed.model.state_dict()[k]), k
    other = train.train(rooms, [ROOM], vocab, {**PRESET, "max_epochs": 4}, Session(0, tmp_path / "b.pt", "other settings"))
    assert other.resumed_from == 0  # a progress file of other settings is not resumed


def test_a_room_learned_by_heart_decodes_back_from_its_code(tmp_path):
    vocab = vocab_of([ROOM])
    preset = {**PRESET, "max_epochs": 150, "kl_anneal": 50, "lr": 0.01}
    run = train.train([ROOM], [ROOM], vocab, preset, Session(0, tmp_path / "p.pt", "h"))
    text = serialize_room(*ROOM)
    mu = decoding.encode_means(run.model, [text], vocab, 200)
    prefix = vocab.encode([arch_prefix(*ROOM)[0] + "."])[0, 1:-1].tolist()
    rows = decoding.decode(run.model, mu, [prefix], vocab, (200, 0.0, torch.Generator().manual_seed(0)),
                           decoding.Syntax(vocab, 1))
    assert isomorphic(parse(vocab.decode(rows[0])), ROOM[0])
    path = decoding.path_codes(mu[0], torch.zeros_like(mu[0]), 32)
    assert path.shape == (32, PRESET["latent"]) and torch.allclose(path[0], mu[0]) and path[-1].abs().max() == 0


def test_free_bits_hold_each_latent_dimensions_kl_at_its_floor():
    """Two dimensions over a batch of two: one collapsed (mu 0, var 1: KL 0), one carrying 2 nats on average; with
    0.25 free bits the collapsed one counts 0.25 and gives no gradient, the other counts its own KL; with none, the
    objective is the plain KL's batch mean."""
    import torch

    from pipeline.methods.strings.model import kl_objective, losses

    mu = torch.tensor([[0.0, 2.0], [0.0, -2.0]], requires_grad=True)
    logvar = torch.zeros(2, 2)
    logits, x = torch.zeros(2, 1, 3), torch.tensor([[1, 2], [1, 2]])
    _, kl = losses(logits, x, mu, logvar)
    assert kl.tolist() == [2.0, 2.0] and float(kl_objective(mu, logvar, 0.0)) == 2.0
    held = kl_objective(mu, logvar, 0.25)
    assert float(held) == 2.25
    held.backward()
    assert mu.grad[:, 0].abs().sum() == 0 and mu.grad[:, 1].abs().sum() > 0
