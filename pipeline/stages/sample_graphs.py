"""Sample relation graphs of one room type from its trained graph model: from scratch in held-out rooms'
architectures, or completing a partial graph given as a YAML spec. Invalid graphs are resampled (a budget);
the ones still invalid are counted, never written."""
from __future__ import annotations

import logging
import zlib
from collections import Counter
from pathlib import Path

from .. import tables
from ..errors import InputError
from ..log import progress
from ..stage import Files
from .train_graph_model import room_graphs

log = logging.getLogger("planit.sample_graphs")


def spec_room_type(spec: Path) -> str:
    """The room type a spec file names (the spec is validated in full when sampling)."""
    import yaml

    try:
        value = (yaml.safe_load(Path(spec).read_text()) or {}).get("room_type")
    except (OSError, yaml.YAMLError, AttributeError) as exc:
        raise InputError(f"{spec}: cannot read the spec ({exc})") from exc
    if not isinstance(value, str):
        raise InputError(f"{spec}: room_type: missing (a room type such as bedroom)")
    return value


def load_model(path: Path):
    """The model file's dict and the rebuilt model (weights loaded, on the CPU, eval mode)."""
    from ..graphs import data as graph_data
    from ..learning import checkpoint
    from ..methods.planit.graph_model import train

    ckpt = checkpoint.load(path, train.KIND)
    saved = ckpt.record
    vocab = graph_data.Vocab(tuple(saved["categories"]))
    model = train.build_model(vocab, saved["preset"])
    model.load_state_dict(ckpt.state["model"])
    model.eval()
    return saved, vocab, model


def run(config: dict, inp: Files, out: Files, room_type: str, count: int | None = None, threads: int = 1) -> dict:
    """Write ``count`` (default ``graph_model.sample.graphs``) valid graphs and a summary of the sampling; with
    ``inp.spec``, graphs that complete that partial graph."""
    model, nodes, edges, spec = inp.model, inp.nodes, inp.edges, inp.spec
    out_nodes, out_edges, out_summary = out.nodes, out.edges, out.summary
    import torch

    from ..methods.planit.graph_model.spec import load_spec

    sc = config["graph_model"]["sample"]
    torch.set_num_threads(threads)
    saved, vocab, net = load_model(model)
    _, graphs = room_graphs(nodes, edges, room_type)
    by_id = {g.room_id: g for g in graphs}
    held = [by_id[i] for i in saved["heldout_ids"] if i in by_id]
    seen = {tuple(t) for t in saved["seen"]}
    plan = None
    if spec is not None:
        plan, arch_from = load_spec(spec, room_type, vocab)
        if arch_from and arch_from not in by_id:
            raise InputError(f"{spec}: architecture.room: no room '{arch_from}' of type {room_type} in {nodes}")
        held = [by_id[arch_from]] if arch_from else held
        seen |= _plan_triples(plan)  # what the spec asks for is allowed, seen in training or not
    if not held:
        raise InputError(f"{model}: none of its held-out rooms is in {nodes}; retrain (snakemake --forcerun train_graph_model)")
    n = count or sc["graphs"]
    base_seed = zlib.crc32(f"{config['seed']}/{room_type}/{spec or ''}".encode())
    kept, first_try, reasons = _sample_valid(net, vocab, held, n, sc, seen, plan, base_seed, saved["max_edges"], room_type)
    _write(kept, vocab, nodes, edges, room_type, out_nodes, out_edges)
    summary = {"room_type": room_type, "requested": n, "written": len(kept), "failed_after_budget": n - len(kept),
               "valid_before_rejection": round(first_try / max(n, 1), 4), "rejections": dict(reasons),
               "temperature": sc["temperature"], "spec": str(spec) if spec else None}
    tables.write_json(out_summary, summary)
    log.info("%s", summary)
    return summary


def _plan_triples(plan) -> set[tuple[int, int, int]]:
    from ..graphs.data import ARCH

    cls = [len(ARCH) + c for c, _, _ in plan.objects]
    return {(cls[k], cls[j], c) if d == 0 else (cls[j], cls[k], c) for k, d, c, j in plan.edges}


def _sample_valid(net, vocab, held, n, sc, seen, plan, base_seed, max_edges, room_type) -> tuple[dict, int, Counter]:
    """Graph index -> (valid graph, seed); how many were valid at the first try; rejections by reason. A graph that
    fails the checks is sampled again, up to ``resample_budget`` times."""
    from ..graphs import checks as graph_checks
    from ..methods.planit.graph_model.sampler import sample

    kept, first_try, reasons = {}, 0, Counter()
    pending = list(range(n))
    for attempt in range(sc["resample_budget"] + 1):
        for k in progress(range(0, len(pending), sc["batch_size"]), desc=f"sample {room_type}, try {attempt + 1}"):
            part = pending[k:k + sc["batch_size"]]
            seed = base_seed + 1_000_003 * attempt + k
            grown = sample(net, vocab, [held[i % len(held)] for i in part], seed, sc["temperature"], sc["max_objects"],
                           max_edges, [plan] * len(part) if plan else None, seen)
            for i, g in zip(part, grown):
                bad = graph_checks.problems(g.node_class, g.role, g.edges, g.arch.n_arch, seen)
                reasons.update(bad)
                first_try += attempt == 0 and not bad
                if not bad:
                    kept[i] = (g, seed)
        pending = [i for i in pending if i not in kept]
        if not pending:
            break
    return kept, first_try, reasons


def _write(kept: dict, vocab, nodes: Path, edges: Path, room_type: str, out_nodes: Path, out_edges: Path) -> None:
    """The kept graphs as generated_nodes / generated_edges rows, architecture copied from their rooms."""
    from ..methods.planit.graph_model.tables import grown_rows

    flt = [("room_type", "=", room_type)]
    arch_rows = _architecture_rows(tables.read(nodes, "final_nodes", filters=flt).to_pandas(),
                                   tables.read(edges, "final_edges", filters=flt).to_pandas())
    rows_n, rows_e = [], []
    for i in sorted(kept):
        g, seed = kept[i]
        an, ae = arch_rows[g.arch.room_id]
        nn_, ee = grown_rows(g, vocab, an, ae, f"gen_{room_type}_{i:05d}", room_type, seed)
        rows_n += nn_
        rows_e += ee
    tables.write(out_nodes, "generated_nodes", tables.from_rows("generated_nodes", rows_n))
    tables.write(out_edges, "generated_edges", tables.from_rows("generated_edges", rows_e))


def _architecture_rows(node_df, edge_df) -> dict:
    """Per room: its architecture node rows (in the graph's order) and its kept architecture edges."""
    out = {}
    arch_e = edge_df[edge_df["edge_type"].astype(str).isin(["wall_adjacent", "wall_opposite", "opening"])
                     & (edge_df["status"].astype(str) == "kept")]
    by_room = dict(tuple(arch_e.groupby("room_id", sort=False)))
    for room, g in node_df[node_df["kind"].astype(str) != "object"].groupby("room_id", sort=False):
        out[room] = (g.sort_values("node_id"), by_room.get(room, arch_e.iloc[:0]))
    return out

