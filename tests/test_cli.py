"""The planit CLI run as a user runs it: real files, real exit codes."""
import subprocess
import sys
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

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
    out = planit("filter", "--ingest", str(tmp_path / "nowhere"), "--out", str(tmp_path / "f"))
    assert out.returncode == 2 and "rooms.parquet" in out.stderr and "Traceback" not in out.stderr
    assert not (tmp_path / "f").exists() or not any((tmp_path / "f").iterdir())


def test_stage_with_malformed_input_names_the_field(tmp_path):
    ingest = tmp_path / "ingest"
    ingest.mkdir()
    pq.write_table(pa.table({"room_id": ["r1"]}), ingest / "rooms.parquet")
    out = planit("filter", "--ingest", str(ingest), "--out", str(tmp_path / "f"))
    assert out.returncode == 2 and "rooms.parquet" in out.stderr and "source" in out.stderr


def test_invalid_config_file_names_the_key(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text("procedural:\n  defect_rate: 2\n")
    out = planit("ingest", "--config", str(cfg), "--out", str(tmp_path / "i"))
    assert out.returncode == 2 and "procedural.defect_rate" in out.stderr


def test_missing_source_folder_is_a_clear_error(tmp_path):
    out = planit("ingest", "--config-json", '{"source": "front3d", "front3d": {"houses": "/nowhere"}}', "--out", str(tmp_path / "i"))
    assert out.returncode == 2 and "front3d.houses" in out.stderr and "/nowhere" in out.stderr
