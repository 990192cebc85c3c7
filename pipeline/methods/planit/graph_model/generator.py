"""PlanIT's graph model as a graph generator of the generation interface (``pipeline.methods.GraphGenerator``)."""
from __future__ import annotations

from pathlib import Path

from ....graphs.data import Graph, Vocab
from ....learning.fitted import Fitted
from .fit import fit_room_type
from .sample import sample_room_type


class GraphModel:
    def fit(self, config: dict, vocab: Vocab, graphs: list[Graph], split: dict[str, str], room_type: str,
            progress_file: Path, threads: int = 1) -> Fitted:
        return fit_room_type(config, vocab, graphs, split, room_type, progress_file, threads)

    def sample(self, config: dict, model: Path, graphs: list[Graph], nodes: Path, edges: Path, room_type: str,
               spec: Path | None = None, count: int | None = None, threads: int = 1,
               prefix: str | None = None) -> tuple[list[dict], list[dict], dict]:
        return sample_room_type(config, model, graphs, nodes, edges, room_type, spec, count, threads, prefix)
