"""The string method's layout generator with the paper's own instantiation (issue 31, row (b)): a graph generator's
sampled graphs, each edge tagged with a relative-pose cluster by the edge tagger (voting over several strings of
the graph), assembled breadth-first from the walls with repair (:mod:`.assemble`)."""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Iterator

import numpy as np
import torch

from ... import tables
from ...errors import InputError
from ...graphs.data import N_OBJECT_EDGES, Graph, Vocab, graphs_from_tables
from ...learning import checkpoint
from ...log import progress
from ...placement.layout import with_objects
from ...placement.plan import ScenePlan, plans_from_tables
from ...placement.search import Kit
from ...seeding import seed_of
from ..interface import Scene, Task
from ..placing import load_context, scene_of
from . import tagger
from .assemble import assemble
from .poses import Clusters
from .serialize import string_graph
from .vocab import TokenVocab

log = logging.getLogger("planit.instantiate")


def load_tagger(path: Path) -> tuple[dict, Clusters, TokenVocab, tagger.EdgeTagger]:
    """The checkpoint's record, clusters, token vocabulary and tagger (eval mode, CPU)."""
    ckpt = checkpoint.load(path, tagger.KIND)
    rec = ckpt.record
    clusters, tokens = Clusters.from_record(rec["clusters"]), TokenVocab(tuple(rec["tokens"]))
    model = tagger.build_model(tokens, clusters.size, rec["preset"])
    model.load_state_dict(ckpt.state["model"])
    model.eval()
    return rec, clusters, tokens, model


def tags_of(g: Graph, vocab: Vocab, clusters: Clusters, model, tokens: TokenVocab, votes: int, seed: int) -> dict:
    """Plan edge key (anchor id, target id, edge class) -> its triple's clusters (pose, spread) ranked by the voted
    probability; an edge of an unseen triple has none."""
    names, ids = vocab.node_classes, g.node_ids
    triples = {(s, t, c): (names[g.node_class[s]], names[g.node_class[t]], c)
               for s, t, c in g.edges[:, :3].tolist() if c < N_OBJECT_EDGES}
    room = tagger.Room(string_graph(g, vocab), g.n_arch, triples, {})
    out = {}
    for (s, t, c), p in tagger.vote(model, room, clusters, tokens, votes, seed).items():
        tr = triples[(s, t, c)]
        lo = clusters.offset[tr]
        ranked = np.argsort(-p[lo:lo + len(clusters.centres[tr])], kind="stable")
        out[(ids[s], ids[t], c)] = [(clusters.centres[tr][j], clusters.spread[tr][j]) for j in ranked]
    return out


class TaggedLayout:
    """Sampled graphs (``task.graphs``) placed by the tagger's clusters (``task.model``: the ``tagger`` placement
    learner's checkpoint)."""

    def __init__(self, config: dict, name: str):
        self.config, self.name = config, name
        self.info = {"instantiation": "tagged clusters, breadth-first from the walls", **config["strings"]["tagger"]["placement"]}

    def plans(self, task: Task, vocab: Vocab) -> tuple[list[ScenePlan], dict[str, Graph]]:
        flt = [("room_type", "=", task.corpus.room_type)]
        nodes = tables.read(task.graphs[0], "generated_nodes", filters=flt).to_pandas()
        edges = tables.read(task.graphs[1], "generated_edges", filters=flt).to_pandas()
        unknown = sorted(set(nodes.loc[nodes["kind"].astype(str) == "object", "category"].astype(str)) - set(vocab.categories))
        if unknown:
            raise InputError(f"{task.graphs[0]}: categories the edge tagger was not trained on: {', '.join(unknown)}")
        count = task.count or self.config["instantiate"]["scenes"]
        plans = plans_from_tables(nodes, edges, "full", self.config["seed"], limit=count)
        graphs = {g.room_id: g for g in graphs_from_tables(nodes, edges, vocab)}
        return plans, graphs

    def generate(self, task: Task) -> Iterator[Scene]:
        torch.set_num_threads(task.threads)
        rec, clusters, tokens, model = load_tagger(task.model)
        vocab = Vocab(tuple(rec["categories"]))
        ctx = load_context(self.config, task.corpus)
        plans, graphs = self.plans(task, vocab)
        pc = self.config["strings"]["tagger"]["placement"]
        for plan in progress(plans, total=len(plans), desc=f"assemble {task.corpus.room_type} ({self.name})"):
            seed = seed_of(self.config["seed"], self.name, plan.scene_id)
            tags = tags_of(graphs[plan.scene_id], vocab, clusters, model, tokens, rec["preset"]["votes"], seed)
            source = ctx.corpus.inputs[plan.room_id]
            outcome, walls, unanchored = assemble(plan, with_objects(source, []), tags, Kit(ctx.pool, ctx.checker), pc,
                                                  self.config["instantiate"], seed)
            scene = scene_of(plan, ctx, outcome, walls)
            scene.record["unanchored_objects"] = unanchored
            yield scene
