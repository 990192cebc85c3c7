"""Real Snakemake runs of the whole workflow on the tiny config (config/tiny.yaml)."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from pipeline import tables
from conftest import ROOT

pytestmark = pytest.mark.slow
BIN = Path(sys.executable).parent


def snakemake(workdir: Path, *args: str, check: bool = True, extra_config: Path | None = None,
              env_extra: dict | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}", **(env_extra or {})}
    configs = [str(ROOT / "config" / "tiny.yaml")] + ([str(extra_config)] if extra_config else [])
    cmd = [str(BIN / "snakemake"), "--snakefile", str(ROOT / "Snakefile"), "--directory", str(workdir),
           "--configfile", *configs, "--cores", "2", *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=900)
    if check and proc.returncode != 0:
        raise AssertionError(f"snakemake failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}")
    return proc


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    work = tmp_path_factory.mktemp("e2e")
    snakemake(work)
    return work


def test_every_table_has_its_schema(run_dir):
    res = run_dir / "results"
    expected = {"ingest/rooms.parquet": "rooms", "ingest/architecture.parquet": "architecture",
                "ingest/objects.parquet": "objects", "ingest/models.parquet": "models",
                "ingest/ground_truth.parquet": "ground_truth", "filter/report.parquet": "filter_report",
                "filter/rooms.parquet": "rooms", "symmetry/symmetry.parquet": "symmetry",
                "graphs/raw/nodes-0.parquet": "nodes", "graphs/raw/nodes-1.parquet": "nodes",
                "graphs/raw/edges-0.parquet": "edges", "graphs/raw/edges-1.parquet": "edges",
                "graphs/stats/relations.parquet": "relations", "graphs/stats/hub_patterns.parquet": "hub_patterns",
                "graphs/stats/cooccurrence.parquet": "cooccurrence", "graphs/stats/category_sizes.parquet": "category_sizes",
                "graphs/final/edges-1.parquet": "final_edges", "graphs/nodes.parquet": "final_nodes",
                "graphs/edges.parquet": "final_edges", "graphs/superstructures.parquet": "superstructures"}
    for rel, name in expected.items():
        schema = pq.read_schema(res / rel)
        assert schema.remove_metadata().equals(tables.SCHEMAS[name].remove_metadata()), rel
        assert tables.metadata(res / rel)["pipeline.schema"] == f"{name}/v1"


def test_contents_are_consistent(run_dir):
    res = run_dir / "results"
    rooms = pq.read_table(res / "ingest/rooms.parquet").to_pandas()
    report = pq.read_table(res / "filter/report.parquet").to_pandas()
    kept = pq.read_table(res / "filter/rooms.parquet").to_pandas()
    assert len(rooms) == 26 and set(report.room_id) == set(rooms.room_id)
    assert (report.status == "rejected").sum() >= 1 and report.loc[report.status == "rejected", "rule"].notna().all()
    assert set(kept.shard) <= {0, 1}
    nodes = pq.read_table(res / "graphs/raw/nodes-0.parquet").to_pandas()
    assert set(nodes.room_id) == set(kept.loc[kept.shard == 0, "room_id"])
    metrics = json.loads((res / "metrics/extraction.json").read_text())
    assert metrics["support_parent_accuracy"] >= 0.98 and metrics["adjacent_recall"] >= 0.95
    sup = json.loads((res / "metrics/superstructures.json").read_text())
    assert sup["hubs_true"] > 0 and sup["hub_recall"] >= 0.8 and sup["chain_recall"] >= 0.8
    edges = pq.read_table(res / "graphs/edges.parquet").to_pandas()
    assert set(edges.status) == {"kept", "pruned"} and edges.rule.notna().all()
    assert (res / "graphs/report/graph_stats.png").stat().st_size > 1000
    for log in ["ingest/ingest.log", "filter_rooms/filter_rooms.log", "extract_graphs/0.log", "symmetry/symmetry.log",
                "graph_statistics/graph_statistics.log", "refine_graphs/1.log"]:
        assert (run_dir / "logs" / log).stat().st_size > 0, log


def test_statistics_do_not_depend_on_the_thread_count(run_dir):
    # A cluster job gets one CPU, a laptop several: DuckDB float means must come out bit-identical.
    from pipeline.graphs.statistics import relation_statistics
    raw = run_dir / "results" / "graphs" / "raw"
    nodes, edges = sorted(raw.glob("nodes-*.parquet")), sorted(raw.glob("edges-*.parquet"))
    one, many = relation_statistics(nodes, edges, threads=1), relation_statistics(nodes, edges, threads=8)
    assert len(one["category_sizes"]) > 10
    for name in one:
        pd.testing.assert_frame_equal(one[name], many[name], check_exact=True, obj=name)


def test_runs_with_different_hash_seeds_write_identical_tables(tmp_path):
    # Python salts str hashes per process, so anything that iterates a set of ids can change results between
    # two runs (or two cluster jobs). 200 rooms hold enough tie-cost connectivity repairs to show it.
    override = tmp_path / "more_rooms.yaml"
    override.write_text("procedural:\n  rooms: {bedroom: 40, living: 40, office: 40, bathroom: 40, kitchen: 40}\n"
                        "refine:\n  hub_min_pattern_count: 3\n")
    for seed in ("1", "2"):
        snakemake(tmp_path / seed, extra_config=override, env_extra={"PYTHONHASHSEED": seed})
    compare = ROOT / "tests" / "slurm" / "compare_runs.py"
    out = subprocess.run([sys.executable, str(compare), str(tmp_path / "1" / "results"), str(tmp_path / "2" / "results")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stdout
    assert "26 tables identical" in out.stdout


def test_second_run_has_nothing_to_do(run_dir):
    out = snakemake(run_dir, "--dry-run")
    assert "Nothing to be done" in out.stdout + out.stderr


def test_changing_a_filter_threshold_reruns_only_downstream(run_dir, tmp_path):
    override = tmp_path / "override.yaml"
    override.write_text("filter:\n  max_height: 3.9\n  min_category_rooms: 1\n")
    out = snakemake(run_dir, "--dry-run", extra_config=override)
    text = out.stdout
    assert "filter_rooms" in text and "extract_graphs" in text and "refine_graphs" in text
    assert "rule ingest:" not in text and "rule symmetry:" not in text


def test_forcerun_refine_reruns_only_refinement_and_after(run_dir):
    out = snakemake(run_dir, "--dry-run", "--forcerun", "refine_graphs")
    text = out.stdout
    assert "refine_graphs" in text and "gather_graphs" in text and "score_superstructures" in text
    for upstream in ("rule ingest:", "rule filter_rooms:", "rule extract_graphs:", "rule graph_statistics:"):
        assert upstream not in text


def test_invalid_config_names_the_key(tmp_path):
    out = snakemake(tmp_path, "--dry-run", "--config", "shards=0", check=False)
    assert out.returncode != 0
    assert "shards" in out.stderr + out.stdout and "minimum" in out.stderr + out.stdout
