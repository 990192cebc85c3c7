"""Broken 3D-FRONT input: every house parses in its own error boundary, no table holds a non-finite number or a
duplicate id, and every dropped house, room, object and model is named in the drops table."""
import copy
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from pipeline import config, tables
from pipeline.corpus.ingest import OUTPUTS as INGEST_OUTPUTS
from pipeline.errors import InputError
from pipeline.stage import Files
from pipeline.stages import ingest, ingest_summary

from conftest import shared_data

FIX = Path(__file__).parent / "fixtures" / "front3d"
BASE = json.loads((FIX / "houses" / "tinyhouse.json").read_text())
PLANIT = str(Path(sys.executable).parent / "planit")


def run(tmp: Path, houses: dict[str, object], future: Path = FIX / "future", **section) -> dict[str, pd.DataFrame]:
    """Ingest the given house JSONs (file stem -> content; a string is written as is) as one shard."""
    folder = tmp / "houses"
    folder.mkdir(parents=True, exist_ok=True)
    for stem, house in houses.items():
        (folder / f"{stem}.json").write_text(house if isinstance(house, str) else json.dumps(house))
    cfg = config.validate({"source": "front3d", "shards": 1,
                           "front3d": {"houses": str(folder), "future": str(future), "cache_dir": None, **section}})
    outs = {n: tmp / "out" / f"{n}.parquet" for n in INGEST_OUTPUTS}
    ingest.run(cfg, Files(), Files(outs), shard=0)
    return {n: pd.read_parquet(p) for n, p in outs.items()}


def drops_of(t, level=None) -> pd.DataFrame:
    d = t["drops"]
    return d if level is None else d[d.level == level]


def test_furniture_that_is_not_a_list_of_objects_is_dropped_by_path_and_the_run_goes_on(tmp_path):
    bad = copy.deepcopy(BASE)
    bad["furniture"] = ["x", 1]
    t = run(tmp_path, {"bad": bad, "good": BASE})
    assert t["rooms"].room_id.tolist() == ["good_MasterBedroom-1"]
    d = drops_of(t, "object")
    rows = d[d.file.str.endswith("bad.json")][["field", "reason"]].values.tolist()
    assert rows == [["furniture[0]", "furniture entry without a string uid"],
                    ["furniture[1]", "furniture entry without a string uid"]]
    room = drops_of(t, "room")
    assert ("bad_MasterBedroom-1", "no furniture") in set(zip(room.room_id, room.reason))


def test_a_house_whose_structure_is_wrong_is_skipped_with_the_json_path(tmp_path):
    bad = copy.deepcopy(BASE)
    bad["scene"]["room"] = {"not": "a list"}
    t = run(tmp_path, {"bad": bad, "junk": "{ nope", "good": BASE})
    houses = drops_of(t, "house").set_index("file")
    assert houses.loc[str(tmp_path / "houses/bad.json"), "field"] == "scene.room"
    assert houses.loc[str(tmp_path / "houses/bad.json"), "reason"] == "scene.room: expected list, got dict"
    assert "not readable JSON" in houses.loc[str(tmp_path / "houses/junk.json"), "reason"]
    assert len(t["rooms"]) == 1


def test_same_house_uid_in_two_files_and_repeated_ids_stay_unique(tmp_path):
    twin = copy.deepcopy(BASE)
    twin["furniture"].append(dict(twin["furniture"][0]))  # a repeated furniture uid: the first is kept
    twin["scene"]["room"].append(copy.deepcopy(twin["scene"]["room"][0]))  # a repeated room instanceid: renamed
    del twin["scene"]["room"][0]["instanceid"]  # no instanceid: room<index>
    t = run(tmp_path, {"a": BASE, "b": twin})
    ids = t["rooms"].room_id.tolist()
    assert sorted(ids) == ["a_MasterBedroom-1", "b_MasterBedroom-1", "b_room0"] and len(set(ids)) == len(ids)
    assert not t["objects"].duplicated(["room_id", "object_id"]).any()
    dup = drops_of(t, "object")
    assert dup[dup.reason.str.startswith("duplicate furniture uid")].field.tolist() == ["furniture[4].uid"]
    out = tmp_path / "out"
    summary = tmp_path / "summary"
    ingest_summary.run({}, Files(rooms=[out / "rooms.parquet"], objects=[out / "objects.parquet"],
                                 models=[out / "models.parquet"], reports=[out / "ingest_report.parquet"],
                                 drops=[out / "drops.parquet"]),
                       Files(counts=summary / "c.parquet", report=summary / "r.parquet", drops=summary / "d.parquet"))
    rep = pd.read_parquet(summary / "r.parquet")
    twins = rep[rep.status == "duplicate uid"]
    assert twins.item.tolist() == [BASE["uid"]] and twins["count"].tolist() == [2] and "a.json" in twins.reason.iloc[0]


@pytest.mark.parametrize("field, value, reason", [
    ("pos", [float("nan"), 0, 0], "not finite"),
    ("rot", [0, float("inf"), 0, 1], "not finite"),
    ("rot", [0, 0, 0, 0], "zero quaternion"),
    ("scale", [float("inf"), 1, 1], "not finite"),
    ("scale", [1e6, 1, 1], "outside [0.05, 20.0]"),
    ("scale", [0, 1, 1], "outside [0.05, 20.0]"),
    ("pos", [1, 2], "expected a list of 3 numbers"),
    ("scale", ["a", 1, 1], "expected a list of 3 numbers"),
])
def test_non_finite_zero_or_absurd_transforms_are_dropped_with_the_object_and_field(tmp_path, field, value, reason):
    bad = copy.deepcopy(BASE)
    bad["scene"]["room"][0]["children"][5][field] = value  # f-ns, the nightstand
    t = run(tmp_path, {"h": bad})
    d = drops_of(t, "object").set_index("item_id")
    assert d.loc["f-ns", "field"] == f"scene.room[0].children[5].{field}" and reason in d.loc["f-ns", "reason"]
    assert d.loc["f-ns", "room_id"] == "h_MasterBedroom-1" and d.loc["f-ns", "house_id"] == BASE["uid"]
    objs = t["objects"]
    assert len(objs) == 1 and np.isfinite(objs.select_dtypes("number").to_numpy()).all()


def test_every_drop_of_the_fixture_house_is_named(tmp_path):
    t = run(tmp_path, {"tiny": BASE})
    rows = set(map(tuple, drops_of(t)[["level", "room_id", "item_id", "field", "reason"]].fillna("").values.tolist()))
    assert ("object", "tiny_MasterBedroom-1", "f-ghost", "furniture[2].jid", "no mesh and no box for its model") in rows
    assert ("object", "tiny_MasterBedroom-1", "f-invalid", "furniture[3].valid", "not in 3D-FUTURE (valid: false)") in rows
    assert ("room", "tiny_Kitchen-2", "", "scene.room[1]", "no Floor mesh") in rows
    assert ("room", "tiny_Balcony-3", "", "scene.room[2]", "room type 'Balcony' not mapped") in rows


def test_entries_without_a_valid_flag_are_kept_when_their_model_exists(tmp_path):
    house = copy.deepcopy(BASE)
    del house["furniture"][1]["valid"]  # the nightstand: Models.csv has its box
    house["furniture"].append({"uid": "f-door", "jid": "jid-ns", "title": "door/single swing door"})
    house["scene"]["room"][0]["children"].append({"ref": "f-door", "pos": [1, 0, -1], "rot": [0, 0, 0, 1], "scale": [1, 1, 1]})
    t = run(tmp_path, {"h": house})
    assert sorted(t["objects"].category) == ["king-size bed", "nightstand"]
    rep = t["ingest_report"]
    assert rep[rep.reason == "no valid flag, but its model has a mesh or box"]["count"].sum() == 1
    assert drops_of(t, "object").set_index("item_id").loc["f-door", "reason"].startswith("door or window")


def test_ceiling_and_wall_attached_lights_are_not_floor_objects(tmp_path):
    house = copy.deepcopy(BASE)
    house["furniture"][1]["title"] = "lighting/single spotlight - ceiling-attached"
    t = run(tmp_path, {"h": house})
    d = drops_of(t, "object").set_index("item_id")
    assert "not a floor object ('ceiling'" in d.loc["f-ns", "reason"] and d.loc["f-ns", "field"] == "furniture[1].title"


def test_others_yields_to_the_furniture_title(tmp_path):
    future = tmp_path / "future"
    future.mkdir()
    (future / "Models.csv").write_text((FIX / "future/Models.csv").read_text())
    (future / "ModelCategoryMapping.csv").write_text("model_id,category,super-category\njid-ns,Others,Others\n")
    house = copy.deepcopy(BASE)
    house["furniture"][1]["title"] = "plants/plants - on top of others"
    t = run(tmp_path, {"h": house}, future=future)
    assert t["objects"].category.tolist() == ["plants/plants"]


def test_mesh_problems_are_reported_by_kind_per_model(tmp_path):
    future = tmp_path / "future"
    for jid, content in (("jid-bed", b"\x00\xffgarbage\x13" * 50), ("jid-ns", b"")):
        (future / jid).mkdir(parents=True)
        (future / jid / "raw_model.obj").write_bytes(content)
    (future / "Models.csv").write_text((FIX / "future/Models.csv").read_text())
    (future / "ModelCategoryMapping.csv").write_text((FIX / "future/ModelCategoryMapping.csv").read_text())
    house = copy.deepcopy(BASE)
    house["scene"]["room"][0]["children"].append(dict(house["scene"]["room"][0]["children"][5], pos=[2.5, 0, -0.2]))
    t = run(tmp_path, {"h": house}, future=future)
    models = drops_of(t, "model").set_index("item_id")
    assert set(models.index) == {"jid-bed", "jid-ns"}  # once per model, though the nightstand is placed twice
    assert models.loc["jid-ns", "status"] == "fallback" and models.loc["jid-ns", "reason"] in ("mesh empty", "mesh unreadable")
    assert models.loc["jid-bed", "reason"] in ("mesh unreadable", "mesh empty", "mesh bad indices")
    assert models.loc["jid-bed", "status"] == "fallback"  # Models.csv has both boxes: the objects stay, as boxes
    assert len(t["objects"]) == 3 and set(t["models"].mesh_kind) == {"box_fallback"}
    assert drops_of(t, "model").file.str.endswith("raw_model.obj").all()


def test_centimetre_meshes_are_reported_as_rescaled(tmp_path):
    t = run(tmp_path, {"h": BASE})  # the fixture bed's OBJ is in centimetres
    d = drops_of(t, "model").set_index("item_id")
    assert d.loc["jid-bed", "reason"] == "mesh rescaled from cm" and d.loc["jid-bed", "status"] == "kept"


def test_no_room_at_all_is_a_clear_error_at_ingest(tmp_path):
    t = tmp_path / "i"
    cfg = config.validate({"source": "front3d", "shards": 1, "front3d": {"houses": str(tmp_path), "future": str(FIX / "future")}})
    outs = {n: t / f"{n}.parquet" for n in INGEST_OUTPUTS}
    ingest.run(cfg, Files(), Files(outs), shard=0)  # an empty shard is fine ...
    with pytest.raises(InputError, match="no room was ingested"):  # ... an empty corpus is not
        ingest_summary.run({}, Files(rooms=[outs["rooms"]], objects=[outs["objects"]], models=[outs["models"]],
                                     reports=[outs["ingest_report"]], drops=[outs["drops"]]),
                           Files(counts=t / "c.parquet", report=t / "r.parquet", drops=t / "d.parquet"))


def test_tables_refuse_non_finite_numbers_and_duplicate_ids(tmp_path):
    row = {"room_id": "r", "element_id": "wall_0", "kind": "wall", "x0": 0.0, "y0": 0.0, "x1": float("inf"), "y1": 0.0,
           "z0": 0.0, "z1": 2.5, "thickness": 0.1}
    with pytest.raises(tables.TableError, match="x1.*not finite"):
        tables.write(tmp_path / "a.parquet", "architecture", tables.from_rows("architecture", [row]))
    ok = dict(row, x1=1.0)
    with pytest.raises(tables.TableError, match="duplicate.*room_id, element_id"):
        tables.write(tmp_path / "a.parquet", "architecture", tables.from_rows("architecture", [ok, ok]))
    assert not (tmp_path / "a.parquet").exists()


def test_corrupt_intermediate_table_names_the_file_and_its_rule(tmp_path):
    junk = tmp_path / "edges-0.parquet"
    junk.write_bytes(b"PAR1 garbage")
    out = subprocess.run([PLANIT, "shard_statistics", "--nodes", str(junk), "--edges", str(junk), "--out-counts",
                          str(tmp_path / "c.parquet"), "--out-candidates", str(tmp_path / "k.parquet")],
                         capture_output=True, text=True, timeout=120)
    errors = [line for line in out.stderr.splitlines() if line.startswith("error:")]
    assert out.returncode == 2 and len(errors) == 1 and "Traceback" not in out.stderr
    assert "edges-0.parquet" in errors[0] and "extract_graphs" in errors[0]


# ----------------------------------------------------------------------------------------------- fuzzing
BAD_VALUES = [float("nan"), float("inf"), -float("inf"), 0, 1e9, -1, "x", None, [], {}, True, [1, 2]]


def _paths(node, prefix=()):
    """Every JSON path of a document (the root excluded)."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield prefix + (k,)
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield prefix + (i,)
            yield from _paths(v, prefix + (i,))


PATHS = list(_paths(BASE))


def _mutate(house, path, action, value):
    parent = house
    for p in path[:-1]:
        parent = parent[p]
    key = path[-1]
    if action == "replace":
        parent[key] = value
    elif action == "delete":
        del parent[key]
    elif action == "duplicate" and isinstance(parent, list):
        parent.append(copy.deepcopy(parent[key]))


@st.composite
def broken_houses(draw):
    house = copy.deepcopy(BASE)
    for _ in range(draw(st.integers(1, 4))):
        live = list(_paths(house))
        path = draw(st.sampled_from(live or PATHS))
        action = draw(st.sampled_from(["replace", "replace", "delete", "duplicate"]))
        try:
            _mutate(house, path, action, draw(st.sampled_from(BAD_VALUES)))
        except (KeyError, IndexError, TypeError):
            pass
    return house


@settings(suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(house=broken_houses())
def test_fuzzed_houses_never_crash_and_every_drop_is_accounted(tmp_path_factory, house):
    tmp = tmp_path_factory.mktemp("fuzz")
    t = run(tmp, {"h": house, "twin": house})
    for name in ("rooms", "architecture", "objects", "models"):  # nulls allowed, NaN and inf never
        table = pq.read_table(tmp / "out" / f"{name}.parquet")
        for col in table.columns:
            values = pc.list_flatten(col) if pa.types.is_list(col.type) else col
            if pa.types.is_floating(values.type) and len(values):
                assert pc.all(pc.is_finite(values.drop_null())).as_py() in (True, None), name
    assert t["rooms"].room_id.is_unique and not t["objects"].duplicated(["room_id", "object_id"]).any()
    houses_dropped = set(drops_of(t, "house").file)
    for stem in ("h", "twin"):
        if str(tmp / "houses" / f"{stem}.json") in houses_dropped:
            continue
        read = set(t["rooms"].room_id[t["rooms"].room_id.str.startswith(f"{stem}_")])
        skipped = set(drops_of(t, "room").room_id.dropna()) & {r for r in _expected_rooms(house, stem)}
        assert read | skipped == set(_expected_rooms(house, stem)) and not read & skipped
        for rid in read:  # every placed furniture child is an object or a drop
            placed = t["objects"].room_id.eq(rid).sum() + drops_of(t, "object").room_id.eq(rid).sum()
            assert placed == _placed_children(house, rid.split("_", 1)[1]), rid


def _expected_rooms(house, stem) -> list[str]:
    rooms = house["scene"]["room"]
    out, seen = [], {}
    for i, r in enumerate(rooms):
        if not isinstance(r, dict):
            continue
        name = r.get("instanceid") if isinstance(r.get("instanceid"), str) and r.get("instanceid") else f"room{i}"
        seen[name] = seen.get(name, 0) + 1
        out.append(f"{stem}_{name if seen[name] == 1 else f'{name}-{seen[name]}'}")
    return out


def _placed_children(house, name) -> int:
    furniture = {}
    for f in house["furniture"]:
        if isinstance(f, dict) and isinstance(f.get("uid"), str):
            furniture.setdefault(f["uid"], f)
    seen = {}
    for i, r in enumerate(house["scene"]["room"]):
        if not isinstance(r, dict):
            continue
        n = r.get("instanceid") if isinstance(r.get("instanceid"), str) and r.get("instanceid") else f"room{i}"
        seen[n] = seen.get(n, 0) + 1
        if (n if seen[n] == 1 else f"{n}-{seen[n]}") == name:
            kids = r.get("children") if isinstance(r.get("children"), list) else []
            return sum(isinstance(c, dict) and isinstance(c.get("ref"), str) and c["ref"] in furniture for c in kids)
    raise AssertionError(name)


@pytest.mark.realdata
def test_real_sample_houses_ingest_with_every_drop_named(tmp_path):
    sample = shared_data("3d-front-sample")
    cfg = config.validate({"source": "front3d", "shards": 1, "front3d": {
        "houses": str(sample / "houses"), "future": str(sample / "3d-future"), "cache_dir": str(tmp_path / "c")}})
    outs = {n: tmp_path / f"{n}.parquet" for n in INGEST_OUTPUTS}
    ingest.run(cfg, Files(), Files(outs), shard=0)
    rooms, objs = pd.read_parquet(outs["rooms"]), pd.read_parquet(outs["objects"])
    drops = pd.read_parquet(outs["drops"])
    assert rooms.room_id.is_unique and not drops.empty and drops.file.notna().all() and drops.reason.notna().all()
    untitled = {f.get("jid") for h in (sample / "houses").glob("*.json") for f in json.loads(h.read_text())["furniture"]
                if not f.get("title")}
    assert set(objs.model_id[objs.category == "others"]) <= untitled  # 'others' yields to the title where there is one
    assert not objs.category.str.contains("ceiling|pendant|spotlight").any()
    assert drops[drops.level == "object"].item_id.notna().all()
    assert math.isfinite(objs.select_dtypes("number").to_numpy().sum())
