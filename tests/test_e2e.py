"""Real Snakemake runs of the whole workflow on the tiny config (config/tiny.yaml)."""
import io
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from pipeline import tables
from pipeline.learning import checkpoint
from pipeline.stage import Files

from conftest import ROOT

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("e2e_run")]
BIN = Path(sys.executable).parent
COMPARE = ROOT / "tests" / "slurm" / "compare_runs.py"


def snakemake(workdir: Path, *args: str, check: bool = True, extra_config: Path | list[Path] | None = None,
              env_extra: dict | None = None) -> subprocess.CompletedProcess:
    """Snakemake as a user without an activated venv runs it: the venv's bin is NOT on PATH. ``extra_config``: one
    config file or several (later ones win) over config/tiny.yaml."""
    path = os.pathsep.join(p for p in os.environ["PATH"].split(os.pathsep) if Path(p) != BIN)
    env = {**os.environ, "PATH": path, **(env_extra or {})}
    extra = [extra_config] if isinstance(extra_config, Path) else list(extra_config or [])
    configs = [str(ROOT / "config" / "tiny.yaml"), *map(str, extra)]
    cmd = [str(BIN / "snakemake"), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(workdir),
           "--configfile", *configs, "--cores", "2", *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    if check and proc.returncode != 0:
        raise AssertionError(f"snakemake failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


# what follows new final graphs: the room_types checkpoint and the run-time table; what is learned from the graphs is
# planned once the checkpoint has run (Snakemake re-evaluates the DAG then)
AFTER_GRAPHS = ("room_types", "runtime")
LEARNED = ("bedroom", "office")  # tiny.yaml's graph_model.room_types: the room types trained, generated and evaluated
TABLE3 = "results/generated/bedroom/table3.csv"  # tiny.yaml leaves Table 3 out of the default target


def planned_jobs(proc: subprocess.CompletedProcess) -> set[str]:
    """Rules a dry run would run (from its 'Job stats' table)."""
    text = proc.stdout + proc.stderr
    block = text[text.index("Job stats:"):] if "Job stats:" in text else ""
    return {m.group(1) for m in re.finditer(r"^(\w+)\s+\d+$", block, re.M)} - {"total", "all"}


@pytest.fixture(scope="session")  # once per worker: xdist interleaves modules, which would rebuild a module fixture
def run_dir(tmp_path_factory):
    work = tmp_path_factory.mktemp("e2e")
    snakemake(work)
    snakemake(work, TABLE3)
    return work


def test_every_table_has_its_schema(run_dir):
    res = run_dir / "results"
    expected = {"ingest/shards/rooms-0.parquet": "rooms", "ingest/shards/architecture-1.parquet": "architecture",
                "ingest/shards/objects-0.parquet": "objects", "ingest/shards/models-1.parquet": "models",
                "ingest/shards/ground_truth-0.parquet": "ground_truth", "ingest/ingest_report.parquet": "ingest_report",
                "ingest/category_counts.parquet": "category_counts", "filter/report.parquet": "filter_report",
                "filter/shards/rooms-1.parquet": "rooms", "graphs/ingested/symmetry.parquet": "symmetry",
                "graphs/ingested/raw/nodes-0.parquet": "nodes", "graphs/ingested/raw/edges-1.parquet": "edges",
                "graphs/ingested/stats/partial-0.parquet": "partial_counts",
                "graphs/ingested/stats/candidates-1.parquet": "superstructures",
                "graphs/ingested/stats/relations.parquet": "relations",
                "graphs/ingested/stats/hub_patterns.parquet": "hub_patterns",
                "graphs/ingested/stats/cooccurrence.parquet": "cooccurrence",
                "graphs/ingested/stats/category_sizes.parquet": "category_sizes",
                "graphs/ingested/final/edges-1.parquet": "final_edges", "graphs/ingested/nodes.parquet": "final_nodes",
                "graphs/ingested/edges.parquet": "final_edges",
                "graphs/ingested/superstructures.parquet": "superstructures"}
    for rel, name in expected.items():
        schema = pq.read_schema(res / rel)
        assert schema.remove_metadata().equals(tables.SCHEMAS[name].remove_metadata()), rel
        assert tables.metadata(res / rel)["pipeline.schema"] == f"{name}/v1"


def test_contents_are_consistent(run_dir):
    res = run_dir / "results"
    rooms = pd.concat([pq.read_table(p).to_pandas() for p in sorted(res.glob("ingest/shards/rooms-*.parquet"))])
    report = pq.read_table(res / "filter/report.parquet").to_pandas()
    assert len(rooms) == 26 and set(report.room_id) == set(rooms.room_id) and rooms.room_id.is_unique
    assert (report.status == "rejected").sum() >= 1 and report.loc[report.status == "rejected", "rule"].notna().all()
    kept = pq.read_table(res / "filter/shards/rooms-0.parquet").to_pandas()
    assert set(kept.shard) == {0} and set(kept.room_id) <= set(rooms.loc[rooms.shard == 0, "room_id"])
    nodes = pq.read_table(res / "graphs/ingested/raw/nodes-0.parquet").to_pandas()
    assert set(nodes.room_id) == set(kept.room_id)
    metrics = json.loads((res / "metrics/ingested/extraction.json").read_text())
    assert metrics["support_parent_accuracy"] >= 0.98 and metrics["adjacent_recall"] >= 0.95
    sup = json.loads((res / "metrics/ingested/superstructures.json").read_text())
    assert sup["hubs_true"] > 0 and sup["hub_recall"] >= 0.8 and sup["chain_recall"] >= 0.8
    edges = pq.read_table(res / "graphs/ingested/edges.parquet").to_pandas()
    assert set(edges.status) == {"kept", "pruned"} and edges.rule.notna().all()
    assert (res / "graphs/ingested/report/graph_stats.png").stat().st_size > 1000
    for log in ["ingest/0.log", "ingest_summary/ingest_summary.log", "filter_rooms/1.log", "extract_graphs/ingested-0.log",
                "symmetry/ingested.log", "graph_statistics/ingested.log", "refine_graphs/ingested-1.log"]:
        assert (run_dir / "logs" / log).stat().st_size > 0, log


def test_statistics_do_not_depend_on_the_thread_count(run_dir):
    # A cluster job gets one CPU, a laptop several: DuckDB float means must come out bit-identical.
    from pipeline.graphs.statistics import gather
    stats = run_dir / "results" / "graphs" / "ingested"
    partial, nodes = sorted(stats.glob("stats/partial-*.parquet")), sorted(stats.glob("raw/nodes-*.parquet"))
    one, many = gather(partial, nodes, 1, threads=1), gather(partial, nodes, 1, threads=8)
    assert len(one["category_sizes"]) > 10
    for name in one:
        pd.testing.assert_frame_equal(one[name], many[name], check_exact=True, obj=name)


def test_second_run_has_nothing_to_do(run_dir):
    out = snakemake(run_dir, "--dry-run")
    assert "Nothing to be done" in out.stdout + out.stderr


def _dry_run_with(run_dir, tmp_path, yaml_text: str, *targets: str) -> set[str]:
    override = tmp_path / "override.yaml"
    override.write_text(yaml_text)
    return planned_jobs(snakemake(run_dir, "--dry-run", *targets, extra_config=override))


def test_a_refinement_threshold_reruns_refinement_and_after_only(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\n  thresholds: {proximal: 0.2}\n")
    assert jobs == {"refine_graphs", "gather_graphs", "score_superstructures", "graph_report", *AFTER_GRAPHS}


def test_a_chain_setting_reruns_the_statistics_map_step(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\n  chain_collinearity: 0.8\n")
    assert {"shard_statistics", "graph_statistics", "refine_graphs"} <= jobs
    assert not jobs & {"ingest", "filter_rooms", "symmetry", "extract_graphs", "score_extraction"}


def test_a_symmetry_table_change_reruns_symmetry_not_ingest(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\n"
                                            "extract:\n  symmetry: {table: {bed: rotational-2}}\n")
    assert "symmetry" in jobs and not jobs & {"ingest", "ingest_summary", "filter_rooms", "filter_report"}


def test_an_extraction_setting_does_not_rerun_symmetry(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\nextract:\n  support: {grid: 4}\n")
    assert "extract_graphs" in jobs and not jobs & {"symmetry", "ingest", "filter_rooms"}


def test_a_filter_threshold_reruns_only_downstream(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\nfilter:\n  max_height: 3.9\n"
                                            "  min_category_rooms: 1\n")
    assert {"filter_rooms", "filter_report", "extract_graphs", "refine_graphs"} <= jobs
    assert not jobs & {"ingest", "ingest_summary", "symmetry"}


def test_forcerun_refine_reruns_only_refinement_and_after(run_dir):
    jobs = planned_jobs(snakemake(run_dir, "--dry-run", "--forcerun", "refine_graphs"))
    assert jobs == {"refine_graphs", "gather_graphs", "score_superstructures", "graph_report", *AFTER_GRAPHS}


def test_a_sampling_setting_resamples_without_retraining(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\n"
                                            "graph_model:\n  sample: {graphs: 20, batch_size: 20, temperature: 0.8}\n")
    assert jobs == {"sample_graphs", "graph_model_metrics", "generate", "evaluate", "gallery_3d", "runtime"}  # placed, scored again


def test_a_search_setting_replaces_without_retraining(run_dir, tmp_path):
    jobs = _dry_run_with(run_dir, tmp_path, "refine:\n  hub_min_pattern_count: 1\ninstantiate:\n  samples: 12\n",
                         "all", TABLE3)
    assert jobs == {"generate", "instantiate", "table3", "evaluate", "gallery_3d", "runtime"}  # the placement networks are kept


def test_graph_models_are_trained_sampled_and_evaluated_per_room_type(run_dir):
    res = run_dir / "results" / "graph_model"
    for room_type in LEARNED:
        folder = res / room_type / "planit"
        training = json.loads((folder / "training.json").read_text())
        assert training["epochs"] >= 1 and training["device"] == "cpu"
        assert (folder / "loss.png").stat().st_size > 1000
        assert pd.read_csv(folder / "history.csv")["validation_nll"].notna().all()
        saved = checkpoint.load(folder / "model.pt", "graph_model").record
        fit, val, held = (set(saved[k]) for k in ("train_ids", "validation_ids", "heldout_ids"))
        assert fit and val and held and not (fit & val) and not ((fit | val) & held)  # the test rooms are never trained on
        assert training["heldout_nll"] == saved["heldout_nll"]["per_graph"] > 0
        for name, table in (("nodes", "generated_nodes"), ("edges", "generated_edges")):
            schema = pq.read_schema(folder / "sampled" / f"{name}.parquet")
            assert schema.remove_metadata().equals(tables.SCHEMAS[table].remove_metadata())
        summary = json.loads((folder / "sampled" / "summary.json").read_text())
        nodes = pd.read_parquet(folder / "sampled" / "nodes.parquet")
        assert nodes.scene_id.nunique() == summary["written"] and summary["written"] + summary["failed_after_budget"] == 20
        metrics = json.loads((folder / "metrics.json").read_text())
        assert {"heldout_nll", "generated_vs_heldout", "floor_real_vs_heldout", "novelty", "uniqueness", "rules",
                "goals"} <= set(metrics)
        assert metrics["heldout_nll"] == saved["heldout_nll"]
        assert (run_dir / "logs" / "train_graph_model" / f"{room_type}-planit.log").stat().st_size > 0


def test_the_string_vae_is_a_second_graph_generator_with_its_own_model_graphs_and_metrics(run_dir):
    """The strings method: its generator's model, graphs and metrics under graph_model/<type>/strings/, scored by
    the same graph metrics; its scenes placed by PlanIT's search from its own graphs, never PlanIT's."""
    for room_type in LEARNED:
        folder = run_dir / "results" / "graph_model" / room_type / "strings"
        saved = checkpoint.load(folder / "model.pt", "strings_vae").record
        assert saved["tokens"][:4] == ["<pad>", "<bos>", "<eos>", "<unk>"] and saved["preset"]["hidden"] == 32
        history = pd.read_csv(folder / "history.csv")
        assert len(history) == 30 and history["beta"].iloc[-1] == 1.0 and np.isfinite(history["validation_elbo"]).all()
        summary = json.loads((folder / "sampled" / "summary.json").read_text())
        assert summary["generator"] == "strings" and summary["written"] + summary["failed_after_budget"] == 10
        assert sum(summary["rejections"].values()) >= summary["failed_after_budget"]
        metrics = json.loads((folder / "metrics.json").read_text())
        assert metrics["valid_before_rejection"] == summary["valid_before_rejection"]
        assert metrics["heldout_nll"]["per_graph"] == saved["heldout_nll"]["per_graph"] > 0
        placed = json.loads((run_dir / "results" / "generated" / room_type / "strings" / "summary.json").read_text())
        assert placed["variant"] == "strings" and placed["scenes"] <= summary["written"]
        scenes = pd.read_parquet(run_dir / "results" / "generated" / room_type / "strings" / "scenes.parquet")
        sampled = pd.read_parquet(folder / "sampled" / "nodes.parquet")
        assert set(scenes["origin_id"]) <= set(sampled["scene_id"])


def test_sampled_graphs_are_placed_into_rooms_every_stage_reads(run_dir, tmp_path):
    from pipeline import config as config_mod
    from pipeline.stages import extract_graphs

    res = run_dir / "results"
    for room_type in LEARNED:
        training = json.loads((res / "placement" / room_type / "cfcn" / "training.json").read_text())
        assert training["steps"] == 20 and training["train_rooms"] >= 1
        assert (res / "placement" / room_type / "cfcn" / "loss.png").stat().st_size > 1000
        folder = res / "generated" / room_type / "planit"
        scenes = pd.read_parquet(folder / "scenes.parquet")
        sampled = pd.read_parquet(res / "graph_model" / room_type / "planit" / "sampled" / "nodes.parquet").scene_id.nunique()
        # failed scenes are recorded, never dropped; a failed sampled graph is replaced by the next (graph_draws)
        assert (scenes.status == "placed").sum() == min(2, sampled) or len(scenes) == min(2 * 3, sampled)
        assert set(scenes.status) <= {"placed", "failed"} and (scenes[scenes.status == "failed"].reason != "").all()
        entries = tables.read_archive(folder / "scenes.zip")  # one file, no folder: a GLB, PNG and JSON per scene
        assert sorted(entries) == sorted(f"{s}.{ext}" for s in scenes.scene_id for ext in ("glb", "json", "png"))
        assert all(data for data in entries.values())
        for scene in scenes.scene_id:
            assert json.loads(entries[f"{scene}.json"])["status"] == scenes.set_index("scene_id").status[scene]
            assert entries[f"{scene}.png"].startswith(b"\x89PNG") and entries[f"{scene}.glb"].startswith(b"glTF")
        objs = pd.read_parquet(folder / "objects.parquet")
        assert (objs.scene_id == objs.room_id).all()
        assert objs.groupby("room_id").size().reindex(scenes.scene_id, fill_value=0).tolist() == scenes.placed_objects.tolist()
    for rel, name in (("planit/objects.parquet", "generated_objects"), ("planit/scenes.parquet", "scenes"),
                      ("planit/rooms.parquet", "rooms"), ("heldout/models.parquet", "models")):
        assert tables.metadata(res / "generated" / "bedroom" / rel)["pipeline.schema"] == f"{name}/v1", rel
    table = pd.read_csv(res / "generated" / "bedroom" / "table3.csv")
    assert table.variant.tolist() == ["heldout", "random_location", "unconditional", "no_pruning", "half_pruning",
                                      "no_ordering", "paper_cfcn", "paper_fcn"]  # Table 3 also in the paper's setting
    assert (res / "placement" / "bedroom" / "fcn" / "model.pt").exists()
    # the generated bedrooms run through the extraction stage unchanged
    gen = res / "generated" / "bedroom" / "planit"
    placed = pd.read_parquet(gen / "scenes.parquet").placed_objects.sum()
    cfg = config_mod.validate({"seed": 7})
    extract_graphs.run(cfg, Files(rooms=gen / "rooms.parquet", architecture=gen / "architecture.parquet", objects=gen / "objects.parquet",
                                  models=gen / "models.parquet", symmetry=res / "graphs/ingested/symmetry.parquet"),
                       Files(nodes=tmp_path / "n.parquet", edges=tmp_path / "e.parquet", summary=tmp_path / "s.json"), shard=0)
    nodes = pd.read_parquet(tmp_path / "n.parquet")
    assert (nodes.kind == "object").sum() == placed


def test_generated_rooms_baselines_and_real_rooms_are_scored_alike(run_dir):
    from pipeline.corpus.procedural_rules import RULES

    res = run_dir / "results"
    sets = {"planit", "planit_prior", "random_sampled", "unconditional_sampled", "strings", "strings_tagged", "grains", "grains_decoded",
            "infinigen", "saog", "retrieval", "real_heldout"}
    for room_type in LEARNED:
        m = json.loads((res / "eval" / room_type / "metrics.json").read_text())
        assert set(m["sets"]) == sets
        real, gen = m["sets"]["real_heldout"], m["sets"]["planit"]
        assert real["category_kl"] == 0.0 and real["count_distance"] == 0.0 and "sca" not in real
        if gen["scenes"] >= 2:  # the classifier needs a generated room on each side of its split
            assert 50.0 <= gen["sca"]["low"] <= gen["sca"]["accuracy"] <= gen["sca"]["high"] <= 100.0
        if m["sets"]["retrieval"]["scenes"]:
            assert m["sets"]["retrieval"]["nn_similarity"] == 1.0  # the memorisation floor
        assert set(m["power"]["scores"]) == {"jitter_0.1", "jitter_0.3", "shuffle", "turns", "placement", "real_vs_real"}
        assert m["goals"].get("sca_at_most_60") in (None, True, False, "inconclusive")
        if not m["power"]["passed"]:  # the tiny run's 20-step classifier: its SCA must not read as a pass
            assert m["goals"].get("sca_at_most_60") in (None, "inconclusive")
        for check in m["checks"]:  # every functional check is a figure of every set, with its interval
            assert all(check in s and len(s["intervals"][check]) == 2 for s in m["sets"].values())
        diff = m["differences"]["vs_real_heldout"]["planit"]
        assert diff["walkable_share"]["low"] <= diff["walkable_share"]["high"]
        assert isinstance(diff["walkable_share"]["excludes_zero"], bool)
        assert "category_kl" not in diff  # a distance to the real rooms: beside its floor, not a difference
        assert set(m["floors"]) == {"category_kl", "count_distance"} and m["goals"]
        assert all(set(s["rules"]) == set(RULES) for s in m["sets"].values())  # the generator's rules, re-extracted
        rows = pd.read_parquet(res / "eval" / room_type / "scenes.parquet")
        assert tables.metadata(res / "eval" / room_type / "scenes.parquet")["pipeline.schema"] == "eval_scenes/v1"
        assert rows.groupby("set").size().to_dict() == {k: v["scenes"] for k, v in m["sets"].items() if v["scenes"]}
        assert rows.walkable_share.between(0, 1).all() and rows.nn_similarity.between(0, 1).all()
        assert ((rows.failed_checks.str.len() == 0) == (rows.functional_all == 1.0)).all()  # a failing room names why
        assert {c for cs in rows.failed_checks for c in cs} <= {c[3:] for c in m["checks"]} | {"contents_excess",
                                                                                               "contents_missing"}


def test_the_annealing_methods_learn_readable_programs_and_their_rooms_are_scored(run_dir):
    """infinigen and saog: a program per learned room type (derived from the training split, parsed back), rooms with
    a record of their annealing (no hard violation left in a placed scene), a row in the evaluation with the time per
    scene, and the energy trace figure."""
    from pipeline.methods.infinigen.program import load_program
    from pipeline.methods.saog.layout import load_grammar

    res = run_dir / "results"
    for room_type in LEARNED:
        program = load_program(res / "programs" / room_type / "infinigen.yaml")
        split = pd.read_parquet(res / "splits" / f"{room_type}.parquet")
        train = set(split.loc[split["split"].isin(["fit", "validation"]), "room_id"])
        objs = pd.concat([pd.read_parquet(p) for p in sorted((res / "ingest" / "shards").glob("objects-*.parquet"))])
        assert program.room_type == room_type and set(program.objects) <= set(objs[objs["room_id"].isin(train)]["category"])
        grammar = load_grammar(res / "programs" / room_type / "saog.yaml", room_type)
        assert all(w >= 0 for w in grammar["weights"].values()) and grammar["categories"]
        for method in ("infinigen", "saog"):
            scenes = pd.read_parquet(res / "generated" / room_type / method / "scenes.parquet")
            assert len(scenes) == 2 and scenes["energy"].notna().all() and scenes["energy_trace"].notna().all()
            assert (scenes["seconds"] > 0).all()
            m = json.loads((res / "eval" / room_type / "metrics.json").read_text())["sets"][method]
            assert m["attempted"] == 2 and (m["scenes"] == 0 or m["seconds_per_scene"] > 0)
        assert (res / "eval" / room_type / "energy_trace.png").stat().st_size > 10_000


def test_grains_trains_per_room_type_and_its_rooms_are_scored_with_the_cooccurrence_similarity(run_dir):
    """GRAINS: a recursive VAE per learned room type (its checkpoint, history and curve), rooms decoded from its prior
    in the held-out architectures, and every set of the evaluation with GRAINS's co-occurrence similarity."""
    from pipeline.learning import checkpoint
    from pipeline.methods.grains.hierarchy import from_dict, tree_depth

    res = run_dir / "results"
    for room_type in LEARNED:
        folder = res / "placement" / room_type / "grains"
        saved = checkpoint.load(folder / "model.pt", "grains_vae")
        assert saved.record["labels"] and tree_depth(from_dict(saved.record["example_tree"])) >= 2
        assert len(pd.read_csv(folder / "history.csv")) >= 1 and (folder / "loss.png").stat().st_size > 5_000
        scenes = pd.read_parquet(res / "generated" / room_type / "grains" / "scenes.parquet")
        held = pd.read_parquet(res / "splits" / f"{room_type}.parquet").query("split == 'heldout'")["room_id"]
        assert len(scenes) == 2 and set(scenes["source_room_id"]) <= set(held)
        sets = json.loads((res / "eval" / room_type / "metrics.json").read_text())["sets"]
        assert all(0.0 <= s["cooccurrence_similarity"] <= 1.0 for s in sets.values() if s["scenes"])


def test_grains_decoded_furnishes_the_same_trees_in_the_rooms_they_decode(run_dir):
    """GRAINS's faithful mode: the same decoded trees as grains (the same categories scene by scene, with what grains's
    repair left out, recorded in its scenes' drops), each in its own room: a rectangle centred on the origin with four
    walls and no doors or windows, written as the scene's own architecture (no source room), which the evaluation
    reads like any other."""
    res = run_dir / "results"
    for room_type in LEARNED:
        gen = res / "generated" / room_type
        cats = {m: {r.removeprefix(f"{m}_"): c for r, c in pd.read_parquet(gen / m / "objects.parquet")
                    .groupby("room_id")["category"].apply(list).items()} for m in ("grains", "grains_decoded")}
        repaired = pd.read_parquet(gen / "grains" / "scenes.parquet")
        left_out = {r.scene_id.removeprefix("grains_"): [d["category"] for d in json.loads(r.drops)]
                    for r in repaired.itertuples() if r.drops}
        assert all(d["cause"] in ("overlap", "support_dropped") for r in repaired.drops.dropna() for d in json.loads(r))
        assert {r: sorted(c + left_out.get(r, [])) for r, c in cats["grains"].items()} == {
            r: sorted(c) for r, c in cats["grains_decoded"].items()} and cats["grains"]
        rooms = pd.read_parquet(gen / "grains_decoded" / "rooms.parquet")
        arch = pd.read_parquet(gen / "grains_decoded" / "architecture.parquet")
        scenes = pd.read_parquet(gen / "grains_decoded" / "scenes.parquet")
        assert scenes["source_room_id"].isna().all()
        assert (arch.groupby("room_id")["kind"].apply(list) == pd.Series([["wall"] * 4] * len(rooms),
                                                                          index=sorted(rooms["room_id"]))).all()
        for r in rooms.itertuples():
            x, y = np.asarray(r.floor_x), np.asarray(r.floor_y)
            assert len(x) == 4 and np.allclose(x.sum(), 0) and np.allclose(y.sum(), 0) and r.floor_area > 0
            assert np.isclose(r.floor_area, np.ptp(x) * np.ptp(y)) and r.height > 0
        sets = json.loads((res / "eval" / room_type / "metrics.json").read_text())["sets"]
        assert sets["grains_decoded"]["scenes"] == len(rooms)


def test_a_users_own_program_runs_with_planit_generate(run_dir, tmp_path):
    """``planit generate --method infinigen --program FILE``: an edited program (the derived one with no bed) is what
    the rooms hold; a program with an error is refused in one line naming its file and line."""
    res = run_dir / "results"
    text = (res / "programs/bedroom/infinigen.yaml").read_text()
    mine_text, edits = re.subn(r"^(  bed: \{count: )\[\d+, \d+\]", r"\1[0, 0]", text, flags=re.M)
    assert edits == 1
    mine = tmp_path / "mine.yaml"
    mine.write_text(mine_text)
    shards = lambda t: [a for p in sorted((res / ("filter" if t == "rooms" else "ingest") / "shards").glob(f"{t}-*.parquet"))
                        for a in (f"--{t}", str(p))]
    out = {t: tmp_path / f"{t}.parquet" for t in ("rooms", "architecture", "objects", "models", "scenes")}
    cmd = [sys.executable, "-m", "pipeline", "generate", *shards("rooms"), *shards("architecture"), *shards("objects"),
           *shards("models"), "--split", str(res / "splits/bedroom.parquet"),
           "--symmetry", str(res / "graphs/ingested/symmetry.parquet"),
           "--category-sizes", str(res / "graphs/ingested/stats/category_sizes.parquet"), "--program", str(mine),
           *[a for t, p in out.items() for a in (f"--out-{t}", str(p))], "--out-summary", str(tmp_path / "s.json"),
           "--out-archive", str(tmp_path / "s.zip"), "--room-type", "bedroom", "--method", "infinigen", "--count", "2",
           "--config", str(ROOT / "config" / "tiny.yaml")]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    got = subprocess.run(cmd, cwd=run_dir, capture_output=True, text=True, env=env)
    assert got.returncode == 0, got.stderr[-2000:]
    objs = pd.read_parquet(out["objects"])
    assert len(objs) and "bed" not in set(objs["category"])
    mine.write_text("room_type: bedroom\nobjects:\n  bed: {count: [2, 1], stage: large}\n")
    bad = subprocess.run(cmd, cwd=run_dir, capture_output=True, text=True, env=env)
    assert bad.returncode != 0 and f"{mine}:3: objects.bed.count" in bad.stderr and "Traceback" not in bad.stderr


def test_the_run_time_table_holds_every_benchmarked_job(run_dir):
    from pipeline.stages.runtime import TOTAL, WALL

    table = pd.read_csv(run_dir / "results" / "runtime.csv").set_index("rule")
    built = (run_dir / "results" / "runtime.csv").stat().st_mtime  # Table 3's jobs ran later, in a second run
    jobs = [p for p in (run_dir / "benchmarks").glob("*/*.tsv") if p.stat().st_mtime <= built]
    rules = {p.parent.name for p in jobs}
    per_rule = table.iloc[2:][~table.index[2:].str.contains("/")]
    assert rules == set(per_rule.index) and {"ingest", "train_placement", "generate", "evaluate"} <= rules
    assert table.loc[TOTAL, "jobs"] == len(jobs) and table.loc[TOTAL, "jobs"] == per_rule.jobs.sum()
    assert table.loc["generate/planit", "budget_seconds"] > 0  # each method's generation beside its budget
    wall, total = table.loc[WALL, "job_seconds"], table.loc[TOTAL, "job_seconds"]
    assert 0 < wall and total / 2 - 1 <= wall  # two cores: the span is at least half the job time


def _report(run_dir) -> Path:
    out = run_dir / "results" / "report.html"
    if not out.exists():
        snakemake(run_dir, "--report", str(out), "all", TABLE3)
    return out


def test_the_report_gathers_counts_tables_curves_evaluation_and_gallery(run_dir):
    import base64

    html = _report(run_dir).read_text()
    for item in ("results/filter/rule_counts.html", "results/graphs/ingested/room_types.html",
                 "results/graphs/ingested/report/table1.html", "results/graphs/ingested/report/pruning.html",
                 "results/graph_model/bedroom/planit/loss.png", "results/placement/bedroom/cfcn/loss.png",
                 "results/generated/bedroom/table3.html", "results/eval/bedroom/metrics.html",
                 "results/eval/bedroom/power.png", "results/runtime.html"):
        assert f'"{item}": {{' in html, item
    for item in ("results/filter/rule_counts.tsv", "results/graphs/ingested/report/table1.csv",
                 "results/generated/bedroom/table3.csv", "results/eval/bedroom/metrics.csv",
                 "results/runtime.csv"):  # the tables' CSV files are for programs
        assert f'"{item}": {{' not in html, item
    gallery = run_dir / "results" / "eval" / "bedroom" / "gallery.png"  # embedded whole, as a PNG
    entry = html[html.index('"results/eval/bedroom/gallery.png": {'):]
    data = re.search(r'"data_uri": "data:image/png;[^"]*?base64,([A-Za-z0-9+/=]+)"', entry).group(1)
    assert base64.b64decode(data) == gallery.read_bytes()


def test_the_gallery_tiles_generated_rooms_above_real_ones(run_dir):
    """Two rows of figures: the first method's scenes (their archive's PNGs), then held-out real rooms."""
    from matplotlib.image import imread

    from pipeline.evaluation.gallery import tile

    res = run_dir / "results"
    image = imread(res / "eval" / "bedroom" / "gallery.png")
    entries = tables.read_archive(res / "generated" / "bedroom" / "planit" / "scenes.zip")
    scenes = pd.read_parquet(res / "generated" / "bedroom" / "planit" / "scenes.parquet")
    first = imread(io.BytesIO(entries[f"{scenes[scenes.status == 'placed'].scene_id.iloc[0]}.png"]), format="png")
    assert image.shape[0] == 2 * first.shape[0] and image.shape[1] >= first.shape[1]
    assert np.allclose(image[:first.shape[0], :first.shape[1], :3], first[..., :3], atol=1 / 255)
    assert not np.allclose(image[first.shape[0]:, :first.shape[1], :3], 1)  # a real room drawn below
    grid = tile([[entries[n] for n in sorted(entries) if n.endswith(".png")][:1], []])
    assert grid.shape[:2] == (2 * first.shape[0], first.shape[1]) and (grid[first.shape[0]:] == 1).all()


def test_the_report_renders_in_headless_chromium_and_its_gallery_images_load(run_dir, tmp_path):
    from webdriver import CHROMEDRIVER, CHROMIUM, Browser

    if not (CHROMIUM and CHROMEDRIVER):
        pytest.skip("Debian's chromium and chromium-driver are not installed (make test installs them where it can)")
    report = _report(run_dir)
    browser = Browser(tmp_path / "profile")
    try:
        browser.open(report.as_uri())
        browser.click_text("6. Gallery")
        browser.click_text("bedroom")
        browser.click_text("gallery")  # two figures per room type (the PNG and the 3D page) are a toggle
        images = ("return Array.from(document.images).filter(i => i.src.startsWith('data:image/png'))"
                  ".map(i => [i.src.split(';')[2], i.complete, i.naturalWidth])")
        before = browser.run(images)
        browser.click(browser.elements("tbody tr a[iconname='eye']")[0])
        shown = browser.wait_for(lambda: [i for i in browser.run(images) if i not in before and i[1]], timeout=20)
        shot = browser.screenshot(tmp_path / "gallery.png")
    finally:
        browser.close()
    assert [s[0].removeprefix("filename=") for s in shown] == ["gallery.png"]
    assert all(complete and width >= 400 for _, complete, width in shown)  # decoded, at the figures' size
    assert shot.stat().st_size > 10_000


def _browser(tmp_path):
    """Headless Chromium through chromedriver (the test skips where Debian's packages are missing)."""
    from webdriver import CHROMEDRIVER, CHROMIUM, Browser

    if not (CHROMIUM and CHROMEDRIVER):
        pytest.skip("Debian's chromium and chromium-driver are not installed (make test installs them where it can)")
    return Browser(tmp_path / "profile")


def _show_in_frame(browser, report, menu: list[str], eye) -> None:
    """Open the report, click through the ``menu`` texts, click the eye button ``eye()`` returns, and switch into
    the iframe that Snakemake shows an HTML result in (a data: URL)."""
    browser.open(report.as_uri())
    for text in menu:
        browser.click_text(text)
    browser.click(eye())
    frame = browser.wait_for(lambda: browser.elements("iframe"), timeout=20)
    assert frame, "no iframe shows the page"
    browser.frame(frame[0])


def test_the_report_shows_its_tables_as_html_that_sorts_on_a_header_click(run_dir, tmp_path):
    """Table 1 opened from the report's menu: Snakemake shows an HTML result in an iframe (a data: URL); its cells
    hold the CSV's numbers, and a click on a header sorts the rows."""
    csv = pd.read_csv(run_dir / "results/graphs/ingested/report/table1.csv")
    rows = ("return Array.from(document.querySelectorAll('table.sortable tbody tr'))"
            ".map(r => Array.from(r.cells).map(c => [c.textContent, c.getAttribute('data-value')]))")
    browser = _browser(tmp_path)
    try:
        _show_in_frame(browser, _report(run_dir), ["2. Graphs"],
                       lambda: browser.find("//tr[td[normalize-space(text())='Table 1']]//a[@iconname='eye']"))
        shown = browser.wait_for(lambda: browser.run(rows), timeout=20)
        heads = browser.run("return Array.from(document.querySelectorAll('th')).map(h => h.textContent)")
        browser.click(browser.elements("th")[heads.index("nodes")])
        ascending = browser.run(rows)
        browser.click(browser.elements("th")[heads.index("nodes")])
        descending = browser.run(rows)
        browser.frame(None)
        shot = browser.screenshot(tmp_path / "table1.png")
    finally:
        browser.close()
    assert heads == list(csv.columns) and len(shown) == len(csv)
    bedroom = dict(zip(heads, shown[list(csv.room_type).index("bedroom")]))
    expected = csv.set_index("room_type")
    rooms = str(expected.at["bedroom", "rooms"])  # a known number, from the CSV (an integer column)
    assert bedroom["rooms"] == [rooms, rooms]
    text, value = bedroom["edges_per_node_final"]
    assert float(value) == expected.at["bedroom", "edges_per_node_final"]  # exact, as the CSV holds it
    assert text == f"{float(value):.4g}"  # shown to 4 significant digits
    column = heads.index("nodes")
    assert [float(r[column][1]) for r in ascending] == sorted(csv.nodes)  # by value, not as text
    assert [float(r[column][1]) for r in descending] == sorted(csv.nodes, reverse=True)
    nodes = dict(zip(csv.room_type, csv.nodes))
    assert all(float(r[column][1]) == nodes[r[0][0]] for r in ascending + descending)  # whole rows moved
    assert shot.stat().st_size > 10_000


def test_the_report_shows_every_method_beside_the_real_rooms_with_intervals(run_dir, tmp_path):
    """The evaluation's page opened from the report's menu: its first table holds metrics.json's figures with their
    bootstrap intervals, one row per method and one for the real rooms."""
    metrics = json.loads((run_dir / "results/eval/bedroom/metrics.json").read_text())
    rows = ("return Array.from(document.querySelector('table.sortable').querySelectorAll('tbody tr'))"
            ".map(r => Array.from(r.cells).map(c => c.textContent))")
    browser = _browser(tmp_path)
    try:  # three figures of a room type are a table (Snakemake's layout): the eye in the "metrics" row opens the page
        _show_in_frame(browser, _report(run_dir), ["5. Evaluation", "bedroom"],
                       lambda: browser.find("//tr[td[normalize-space()='metrics']]//a[@iconname='eye']"))
        shown = browser.wait_for(lambda: browser.run(rows), timeout=20)
        heads = browser.run("return Array.from(document.querySelector('table.sortable').querySelectorAll('th'))"
                            ".map(h => h.textContent)")
    finally:
        browser.close()
    table = {r[0]: dict(zip(heads, r)) for r in shown}
    assert list(table) == list(metrics["sets"])  # every method and the real rooms
    walk = metrics["sets"]["planit"]["walkable_share"]
    low, high = metrics["sets"]["planit"]["intervals"]["walkable_share"]
    assert table["planit"]["walkable_share"].startswith(f"{walk:.4g} [{low:.4g}, {high:.4g}]")  # a known number


def test_the_reports_3d_gallery_draws_generated_and_real_rooms_in_chromium(run_dir, tmp_path):
    """The 3D gallery opened from the report (an iframe on a data: URL, no server): three.js draws the first room,
    the room list holds each method's first placed scenes and the held-out real rooms, and a generated room offers
    its planned graph, the extracted one and their difference."""
    browser = _browser(tmp_path)
    try:
        _show_in_frame(browser, _report(run_dir), ["6. Gallery", "bedroom", "3D gallery"],
                       lambda: browser.elements("tbody tr a[iconname='eye']")[0])
        state = browser.wait_for(lambda: browser.run("return window.viewer && window.viewer.state.drawn && "
                                                     "window.viewer.state.frames > 2 ? window.viewer.state : null"), 60)
        titles = browser.run("return [...document.querySelectorAll('#room option')].map(o => o.textContent)")
        graphs = browser.run("return [...document.querySelectorAll('#graph option')].map(o => o.textContent)")
    finally:
        browser.close()
    assert state and state["objects"] > 0 and state["edges"] > 0
    assert sum("held-out real" in t for t in titles) >= 1 and sum("planit" in t for t in titles) >= 1
    assert graphs == ["difference", "planned", "extracted"]


def test_planit_view_writes_a_page_for_a_generated_scene_and_a_real_room(run_dir):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    run = lambda *a: subprocess.run([sys.executable, "-m", "pipeline", "view", *a], cwd=run_dir, capture_output=True,
                                    text=True, env=env)
    got = run("results/generated/bedroom/planit", "--scene", "0")
    scenes = pd.read_parquet(run_dir / "results/generated/bedroom/planit/scenes.parquet")
    first = scenes.loc[scenes["status"].isin(["placed", "partial"]), "scene_id"].iloc[0]
    assert got.returncode == 0 and f"wrote results/view/{first}.html" in got.stdout
    assert (run_dir / f"results/view/{first}.html").stat().st_size > 100_000
    room = pd.read_parquet(run_dir / "results/graphs/ingested/nodes.parquet")["room_id"].iloc[0]
    got = run("--room", room, "--out", "results/view/real.html")
    assert got.returncode == 0 and "1 graph(s)" in got.stdout and (run_dir / "results/view/real.html").exists()
    bad = run("--room", "no_such_room")
    assert bad.returncode == 2 and "no room 'no_such_room'" in bad.stderr
    bad = run("results/generated/bedroom/planit", "--scene", "999")
    assert bad.returncode == 2 and "scenes.parquet: no placed scene '999'" in bad.stderr


def test_writing_commands_say_where_they_wrote_and_scene_ids_are_never_shared(run_dir, tmp_path):
    """``planit sample_graphs`` run by hand prints the files it wrote; across the run, no two methods' scenes and no
    generated scene and corpus room share an id, and each scene names the graph it grew from."""
    res = run_dir / "results"
    out = {t: tmp_path / f"{t}.parquet" for t in ("nodes", "edges")}
    got = subprocess.run([sys.executable, "-m", "pipeline", "sample_graphs", "--model", str(res / "graph_model/bedroom/planit/model.pt"),
                          "--nodes", str(res / "graphs/ingested/nodes.parquet"), "--edges", str(res / "graphs/ingested/edges.parquet"),
                          "--out-nodes", str(out["nodes"]), "--out-edges", str(out["edges"]), "--out-summary",
                          str(tmp_path / "s.json"), "--room-type", "bedroom", "--generator", "planit"],
                         cwd=run_dir, capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert got.returncode == 0, got.stderr
    assert f"wrote {out['nodes']} {out['edges']} {tmp_path / 's.json'}" in got.stdout
    ids, corpus = {}, set(pd.read_parquet(res / "graphs/ingested/nodes.parquet")["room_id"])
    for folder in sorted((res / "generated" / "bedroom").iterdir()):
        if (folder / "scenes.parquet").exists():
            scenes = pd.read_parquet(folder / "scenes.parquet")
            assert scenes["scene_id"].str.startswith(folder.name + "_").all() and scenes["origin_id"].notna().all()
            ids[folder.name] = set(scenes["scene_id"])
    assert len(ids) >= 6 and sum(map(len, ids.values())) == len(set().union(*ids.values()))
    assert not set().union(*ids.values()) & corpus
    planit = pd.read_parquet(res / "generated/bedroom/planit/scenes.parquet")
    sampled = set(pd.read_parquet(res / "graph_model/bedroom/planit/sampled/nodes.parquet")["scene_id"])
    assert set(planit["origin_id"]) <= sampled


def test_invalid_config_names_the_key_in_one_line(tmp_path):
    out = snakemake(tmp_path, "--dry-run", "--config", "shards=0", check=False)
    text = out.stderr + out.stdout
    assert out.returncode != 0
    assert "config: invalid config at key 'shards': 0 is less than the minimum of 1" in text
    assert "draft-07" not in text and "$schema" not in text  # no schema dump, no validator warning


def test_lint_passes():
    out = subprocess.run([str(BIN / "snakemake"), "--snakefile", str(ROOT / "Snakefile"), "--lint", "--configfile",
                          str(ROOT / "config" / "tiny.yaml")], capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert out.returncode == 0 and "good condition" in out.stdout + out.stderr, out.stdout[-2000:]


def test_any_corpus_of_canonical_tables_runs_through_the_same_rules(run_dir, tmp_path):
    # a corpus is any folder of canonical tables per shard: here a copy of the ingested rooms the filter kept
    res = run_dir / "results"
    folder = tmp_path / "copy_tables"
    folder.mkdir()
    for k in (0, 1):
        shutil.copy(res / f"filter/shards/rooms-{k}.parquet", folder / f"rooms-{k}.parquet")
        for t in ("architecture", "objects", "models", "ground_truth"):
            shutil.copy(res / f"ingest/shards/{t}-{k}.parquet", folder / f"{t}-{k}.parquet")
    override = tmp_path / "corpus.yaml"
    override.write_text(f"corpora: {{copy: {folder}}}\n")
    targets = ["results/graphs/copy/edges.parquet", "results/metrics/copy/extraction.json",
               "results/metrics/copy/superstructures.json", "results/graphs/copy/report/table1.csv"]
    snakemake(run_dir, *targets, extra_config=override)
    for name in ("nodes", "edges", "superstructures"):
        a = pq.read_table(res / f"graphs/ingested/{name}.parquet")
        b = pq.read_table(res / f"graphs/copy/{name}.parquet")
        assert a.equals(b), name
    for name in ("extraction", "superstructures"):
        assert (json.loads((res / f"metrics/copy/{name}.json").read_text())
                == json.loads((res / f"metrics/ingested/{name}.json").read_text()))


def test_a_method_registered_from_outside_runs_through_generation_evaluation_and_report(run_dir, tmp_path):
    """tests/toy_method.py (uniform random rooms, no training) registers itself through the interface alone: a config
    naming it (generation.plugins, generation.methods) carries it through the generate rule, the evaluation and the
    report; no file of the pipeline changes."""
    work = tmp_path / "run"
    shutil.copytree(run_dir, work, symlinks=True)
    extra = tmp_path / "toy.yaml"
    extra.write_text("generation: {methods: [planit, toy, retrieval], plugins: [toy_method]}\n")
    env = {"PYTHONPATH": str(ROOT / "tests")}
    jobs = planned_jobs(snakemake(work, "--dry-run", extra_config=extra, env_extra=env))
    assert jobs == {"generate", "evaluate", "gallery_3d", "runtime"}, jobs  # nothing learned again: toy trains nothing
    snakemake(work, extra_config=extra, env_extra=env)
    res = work / "results"
    for room_type in LEARNED:
        scenes = pd.read_parquet(res / "generated" / room_type / "toy" / "scenes.parquet")
        objects = pd.read_parquet(res / "generated" / room_type / "toy" / "objects.parquet")
        assert len(scenes) and (scenes.status == "placed").all() and set(objects.room_id) <= set(scenes.scene_id)
        m = json.loads((res / "eval" / room_type / "metrics.json").read_text())
        assert set(m["sets"]) == {"planit", "toy", "retrieval", "real_heldout"}
        assert set(m["sets"]["toy"]) == set(m["sets"]["planit"])  # every metric, by the same code
        assert "toy" in set(pd.read_csv(res / "eval" / room_type / "metrics.csv")["set"])
    report = work / "results" / "report.html"
    snakemake(work, "--report", str(report), extra_config=extra, env_extra=env)
    assert '"results/eval/bedroom/metrics.html": {' in report.read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text("generation: {methods: [planit, nosuch]}\n")
    out = snakemake(work, "--dry-run", extra_config=bad, check=False)
    assert out.returncode != 0 and "generation method 'nosuch' is not registered" in out.stdout + out.stderr
