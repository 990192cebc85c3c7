"""The planit CLI run as a user runs it: real files, real exit codes."""
import os
import subprocess
import sys
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from pipeline import tables

PLANIT = str(Path(sys.executable).parent / "planit")


def planit(*args, cwd=None):
    return subprocess.run([PLANIT, *args], capture_output=True, text=True, cwd=cwd, timeout=300)


def test_stats_prints_schema_rows_and_summary(tmp_path):
    rows = [{"room_id": "r", "element_id": f"wall_{k}", "kind": "wall", "x0": float(k), "y0": 0.0, "x1": k + 1.0,
             "y1": 0.0, "z0": 0.0, "z1": 2.5, "thickness": 0.1, "wall_id": None} for k in range(3)]
    path = tables.write(tmp_path / "arch.parquet", "architecture", tables.from_rows("architecture", rows))
    out = planit("stats", str(path))
    assert out.returncode == 0, out.stderr
    assert "rows: 3" in out.stdout and "architecture/v1" in out.stdout
    assert "x1" in out.stdout and " m " in out.stdout  # the unit column


def test_stats_on_bad_input_names_the_file(tmp_path):
    junk = tmp_path / "junk.parquet"
    junk.write_text("nope")
    out = planit("stats", str(junk))
    assert out.returncode == 2 and "junk.parquet" in out.stderr and "Traceback" not in out.stderr


def test_stage_with_missing_input_fails_cleanly(tmp_path):
    f = tmp_path / "f"
    out = planit("filter_rooms", "--rooms", str(tmp_path / "nowhere/rooms-0.parquet"), "--architecture", "a", "--objects", "o",
                 "--models", "m", "--counts", "c", "--out-rooms", str(f / "rooms.parquet"), "--out-report", str(f / "report.parquet"))
    assert out.returncode == 2 and "nowhere/rooms-0.parquet" in out.stderr and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) <= 2  # the log line and the error line
    assert not f.exists() or not any(f.iterdir())


def test_stage_with_malformed_input_names_the_field(tmp_path):
    pq.write_table(pa.table({"room_id": ["r1"]}), tmp_path / "rooms.parquet")
    out = planit("filter_rooms", "--rooms", str(tmp_path / "rooms.parquet"), "--architecture", "a", "--objects", "o", "--models", "m",
                 "--counts", "c", "--out-rooms", str(tmp_path / "k.parquet"), "--out-report", str(tmp_path / "r.parquet"))
    assert out.returncode == 2 and "rooms.parquet" in out.stderr and "source" in out.stderr


def test_corrupt_intermediate_table_is_one_line_naming_it(tmp_path):
    junk = tmp_path / "partial-0.parquet"
    junk.write_bytes(b"PAR1 not really")
    outs = [f"--out-{n}" for n in ("cooccurrence", "relations", "hub-patterns", "category-sizes")]
    args = [a for o in outs for a in (o, str(tmp_path / f"{o}.parquet"))]
    out = planit("graph_statistics", "--partial", str(junk), "--nodes", str(junk), *args)
    assert out.returncode == 2 and "partial-0.parquet" in out.stderr and "Traceback" not in out.stderr


def test_invalid_config_file_names_the_key_in_one_line(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("procedural:\n  defect_rate: 2\n")
    o = tmp_path / "i"
    out = planit("ingest", "--shard", "0", "--config", str(cfg), *[a for n in ("rooms", "architecture", "objects", "models",
                 "ground-truth", "ingest-report", "drops") for a in (f"--out-{n}", str(o / f"{n}.parquet"))])
    assert out.returncode == 2 and "procedural.defect_rate" in out.stderr
    assert [line for line in out.stderr.splitlines() if line.startswith("error:")] == [
        f"error: {cfg}: invalid config at key 'procedural.defect_rate': 2 is greater than the maximum of 1"]


def test_missing_source_folder_is_a_clear_error(tmp_path):
    o = tmp_path / "i"
    out = planit("ingest", "--shard", "0", "--config-json", '{"source": "front3d", "front3d": {"houses": "/nowhere"}}',
                 *[a for n in ("rooms", "architecture", "objects", "models", "ground-truth", "ingest-report", "drops")
                   for a in (f"--out-{n}", str(o / f"{n}.parquet"))])
    assert out.returncode == 2 and "front3d" in out.stderr and "/nowhere" in out.stderr and "Traceback" not in out.stderr


def test_only_domain_errors_are_turned_into_one_line():
    from typer import Exit

    from pipeline import cli
    from pipeline.tables import TableError

    with pytest.raises(Exit):
        cli._guard(lambda: (_ for _ in ()).throw(TableError("x.parquet: bad")))
    with pytest.raises(ZeroDivisionError):  # a bug keeps its traceback
        cli._guard(lambda: 1 / 0)
    with pytest.raises(KeyError):
        cli._guard(lambda: {}["missing"])


def test_strict_keys_expose_a_rule_that_forgets_a_key(tmp_path):
    # the rules run stages with PLANIT_STRICT_KEYS=1: a stage reading a key its rule did not pass fails loudly
    o = tmp_path / "i"
    args = [a for n in ("rooms", "architecture", "objects", "models", "ground-truth", "ingest-report", "drops")
            for a in (f"--out-{n}", str(o / f"{n}.parquet"))]
    env = {**os.environ, "PLANIT_STRICT_KEYS": "1"}
    out = subprocess.run([PLANIT, "ingest", "--shard", "0", "--config-json", '{"source": "procedural"}', *args],
                         capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 1 and "KeyError" in out.stderr
