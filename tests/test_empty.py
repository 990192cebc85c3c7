"""Empty shards and room types without rooms are normal: every per-shard stage writes empty tables of the right
schema for a shard with no rooms (a small real corpus split into shards leaves some empty)."""
import pyarrow.parquet as pq

from pipeline import config, tables
from pipeline.stage import Files
from pipeline.stages import extract_graphs, filter_rooms, graph_statistics, refine_graphs, shard_statistics


def _empty(tmp_path, *names):
    out = {}
    for n in names:
        out[n] = tmp_path / f"in_{n}.parquet"
        tables.write(out[n], n, tables.empty(n))
    return out


def _assert_empty(path, schema):
    t = pq.read_table(path)
    assert t.num_rows == 0 and t.schema.remove_metadata().equals(tables.SCHEMAS[schema].remove_metadata()), path


def test_every_per_shard_stage_runs_on_a_shard_with_no_rooms(tmp_path):
    cfg = config.validate({"source": "front3d", "shards": 2})
    inp = _empty(tmp_path, "rooms", "architecture", "objects", "models", "category_counts", "symmetry")
    filter_rooms.run(cfg, Files(rooms=inp["rooms"], architecture=inp["architecture"], objects=inp["objects"],
                                models=inp["models"], counts=inp["category_counts"]),
                     Files(rooms=tmp_path / "kept.parquet", report=tmp_path / "report.parquet"))
    _assert_empty(tmp_path / "kept.parquet", "rooms")
    _assert_empty(tmp_path / "report.parquet", "filter_report")
    summary = extract_graphs.run(cfg, Files(rooms=tmp_path / "kept.parquet", architecture=inp["architecture"],
                                            objects=inp["objects"], models=inp["models"], symmetry=inp["symmetry"]),
                                 Files(nodes=tmp_path / "nodes.parquet", edges=tmp_path / "edges.parquet",
                                       summary=tmp_path / "summary.json"), shard=0)
    assert summary["rooms"] == summary["nodes"] == summary["edges"] == 0
    _assert_empty(tmp_path / "nodes.parquet", "nodes")
    _assert_empty(tmp_path / "edges.parquet", "edges")
    shard_statistics.run(cfg, Files(nodes=tmp_path / "nodes.parquet", edges=tmp_path / "edges.parquet"),
                         Files(counts=tmp_path / "partial.parquet", candidates=tmp_path / "candidates.parquet"))
    _assert_empty(tmp_path / "partial.parquet", "partial_counts")
    stats = {n: tmp_path / f"{n}.parquet" for n in graph_statistics.STAT_TABLES}
    graph_statistics.run(cfg, Files(partial=[tmp_path / "partial.parquet"], nodes=[tmp_path / "nodes.parquet"]),
                         Files(stats))
    out = {n: tmp_path / f"final_{n}.parquet" for n in ("nodes", "edges", "superstructures")}
    refine_graphs.run(cfg, Files(nodes=tmp_path / "nodes.parquet", edges=tmp_path / "edges.parquet",
                                 candidates=tmp_path / "candidates.parquet", **stats),
                      Files(out, summary=tmp_path / "final.json"), shard=0)
    for name, schema in (("nodes", "final_nodes"), ("edges", "final_edges"), ("superstructures", "superstructures")):
        _assert_empty(out[name], schema)


def test_a_room_type_with_too_few_rooms_is_skipped_with_its_reason(tmp_path):
    import pandas as pd

    from pipeline.stages import room_types

    rows = [{"room_id": f"{t}_{k}", "node_id": "n", "room_type": t, "kind": "object"}
            for t, n in (("bedroom", 3), ("office", 2)) for k in range(n)]
    tables.write(tmp_path / "nodes.parquet", "final_nodes", tables.from_rows("final_nodes", rows))
    cfg = config.validate({"graph_model": {"room_types": ["bedroom", "office", "kitchen"]}})
    room_types.run(cfg, Files(nodes=tmp_path / "nodes.parquet"),
                   Files(table=tmp_path / "types.csv", table_html=tmp_path / "types.html"))
    got = pd.read_csv(tmp_path / "types.csv", keep_default_na=False).set_index("room_type")
    assert got.status.to_dict() == {"bedroom": "learned", "office": "skipped", "kitchen": "skipped"}
    assert got.loc["office", "reason"] == "2 room(s); training needs 3"
    assert got.loc["kitchen", "reason"] == "no room of this type passed the filter"
    html = (tmp_path / "types.html").read_text()  # the report's table: the same rows
    assert html.count("<tr>") == 4 and "no room of this type passed the filter" in html
