import os

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from pipeline import tables
from pipeline.errors import PlanitError


def rows():
    return [{"room_id": "r1", "element_id": "wall_0", "kind": "wall", "x0": 0.0, "y0": 0.0, "x1": 1.0, "y1": 0.0,
             "z0": 0.0, "z1": 2.5, "thickness": 0.1, "wall_id": None}]


def test_round_trip_keeps_schema_units_and_metadata(tmp_path):
    path = tables.write(tmp_path / "a.parquet", "architecture", tables.from_rows("architecture", rows()), {"source": "test"})
    back = tables.read(path, "architecture")
    assert back.schema.equals(tables.SCHEMAS["architecture"], check_metadata=False)
    assert back.to_pylist()[0]["x1"] == 1.0
    schema = pq.read_schema(path)
    assert schema.field("x0").metadata[b"unit"] == b"m"
    meta = tables.metadata(path)
    assert meta["pipeline.schema"] == "architecture/v1" and meta["pipeline.source"] == "test"
    assert "Z up" in meta["pipeline.coordinates"]


def test_failed_write_leaves_nothing_behind(tmp_path):
    bad = pa.table({"room_id": ["r1"]})  # lacks every other field
    with pytest.raises(tables.TableError, match="lacks fields"):
        tables.write(tmp_path / "b.parquet", "architecture", bad)
    assert os.listdir(tmp_path) == []


def test_write_replaces_atomically(tmp_path):
    path = tmp_path / "c.parquet"
    tables.write(path, "architecture", tables.from_rows("architecture", rows()))
    two = rows() + [dict(r, element_id="wall_1") for r in rows()]
    tables.write(path, "architecture", tables.from_rows("architecture", two))
    assert tables.read(path).num_rows == 2
    assert sorted(os.listdir(tmp_path)) == ["c.parquet"]


def test_read_errors_name_file_and_field(tmp_path):
    with pytest.raises(tables.TableError, match="no such table file"):
        tables.read(tmp_path / "nope.parquet")
    junk = tmp_path / "junk.parquet"
    junk.write_text("not parquet")
    with pytest.raises(tables.TableError, match="junk.parquet: not a readable Parquet file"):
        tables.read(junk)
    partial = tmp_path / "partial.parquet"
    pq.write_table(pa.table({"room_id": ["r"], "element_id": ["w"]}), partial)
    with pytest.raises(tables.TableError, match=r"partial.parquet: table 'architecture' lacks field\(s\) kind"):
        tables.read(partial, "architecture")


def test_a_written_figure_is_closed_even_when_the_write_fails(tmp_path):
    """The instantiation writes one figure per generated room: each must be released, or hundreds pile up in pyplot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.close("all")
    tables.write_figure(tmp_path / "a.png", plt.subplots()[0])
    assert (tmp_path / "a.png").stat().st_size > 0 and plt.get_fignums() == []
    with pytest.raises(ValueError):
        tables.write_figure(tmp_path / "b.unknown_format", plt.subplots()[0])
    assert plt.get_fignums() == [] and sorted(os.listdir(tmp_path)) == ["a.png"]


def test_an_archive_is_written_whole_and_the_same_entries_give_the_same_bytes(tmp_path):
    def write(path, fail=False):
        with tables.write_archive(path) as archive:
            archive.add("s0.glb", b"glTF" + bytes(100))
            archive.add_json("s0.json", {"status": "placed"})
            if fail:
                raise RuntimeError("scene 1 broke")

    write(tmp_path / "a.zip")
    os.utime(tmp_path / "a.zip", (0, 0))
    write(tmp_path / "b.zip")
    assert (tmp_path / "a.zip").read_bytes() == (tmp_path / "b.zip").read_bytes()  # no clock in the entries
    assert tables.read_archive(tmp_path / "a.zip") == {"s0.glb": b"glTF" + bytes(100), "s0.json": b'{\n  "status": "placed"\n}'}
    with pytest.raises(RuntimeError):
        write(tmp_path / "c.zip", fail=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.zip", "b.zip"]  # nothing half-written left
    (tmp_path / "bad.zip").write_bytes(b"not a zip")
    with pytest.raises(PlanitError, match="bad.zip: not a readable scene archive"):
        tables.read_archive(tmp_path / "bad.zip")
