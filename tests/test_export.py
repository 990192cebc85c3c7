"""Rooms in the formats other tools load (``planit export``, rule ``export_rooms``): USD stages reopened with pxr hold
every object with its world transform and attributes; ProcTHOR-style houses validate against the schema, with a
hand-built house as the known answer and iTHOR asset ids round-tripping; 3D-FRONT-style houses read back by the
project's own ingest give the same objects, poses and relation graph; bad input is named by file and field."""
from __future__ import annotations

import json
import math
import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest
import yaml

from pipeline import config, tables
from pipeline.corpus import ithor
from pipeline.corpus.front3d import yaw_from_quaternion
from pipeline.corpus.ingest import ingest_front3d, ingest_ithor, ingest_procedural
from pipeline.errors import InputError
from pipeline.export import export_folder, front3d, procthor, roundtrip, thor
from pipeline.export.rooms import RoomSet, load_set, table_paths
from pipeline.export.shapes import y_up
from pipeline.geometry.meshes import transform
from pipeline.stage import Files
from pipeline.stages import export_rooms

from conftest import ROOT, Room, shared_data

CFG = config.load(ROOT / "config" / "config.yaml")
OPTIONS = {**CFG["export"], "ithor": CFG["ithor"]}
PLANIT = str(Path(sys.executable).parent / "planit")
TABLES = ("rooms", "architecture", "objects", "models")


def write_set(folder: Path, t: dict) -> Path:
    """Canonical tables as a generated set's folder (objects with their scene id, as a method writes them)."""
    folder.mkdir(parents=True, exist_ok=True)
    objects = t["objects"].append_column("scene_id", t["objects"]["room_id"])
    for name, schema, table in (("rooms", "rooms", t["rooms"]), ("architecture", "architecture", t["architecture"]),
                                ("objects", "generated_objects", objects), ("models", "models", t["models"])):
        tables.write(folder / f"{name}.parquet", schema, table)
    return folder


def write_shards(folder: Path, t: dict) -> Path:
    """Canonical tables as a corpus's one shard (``rooms-0.parquet`` ...)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in TABLES:
        tables.write(folder / f"{name}-0.parquet", name, t[name])
    return folder


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> Path:
    """Fifteen procedural rooms (every room type, supported objects, doors and windows, real meshes) laid out as a
    method's generated set."""
    cfg = config.validate({"seed": 5, "procedural": {"rooms": {t: 3 for t in ("bedroom", "living", "office", "bathroom",
                                                                             "kitchen")}, "defect_rate": 0.0}})
    return write_set(tmp_path_factory.mktemp("export") / "generated", ingest_procedural(cfg, 0, 1))


def hand_set(room: Room) -> RoomSet:
    """A hand-built room as a room set: its box meshes, its recorded bounds, its parents."""
    ri = room.room_input()
    bounds = {m: np.stack([v.min(0), v.max(0)]) for m, (v, _) in room.models.items()}
    parents = [o["source_parent_id"] for o in room.objects]
    return RoomSet("hand", [ri], {ri.room_id: parents}, {ri.room_id: "hand"}, dict(room.models), set(), bounds)


def hand_room() -> Room:
    """A 4 x 3 m bedroom: a door in wall_0 from x = 1 to 2, a bed turned 90 degrees, a nightstand with books on it,
    and a wardrobe (no AI2-THOR asset)."""
    room = Room([(0, 0), (4, 0), (4, 3), (0, 3)], height=2.7, room_id="hand_bedroom")
    room.door("door_0", (1.0, 0.0), (2.0, 0.0), "wall_0")
    room.add("bed", "bed", (1.6, 2.0, 0.5), (2.0, 1.8), yaw_deg=90)
    room.add("ns", "nightstand", (0.45, 0.4, 0.55), (3.5, 2.6))
    room.add("books", "books", (0.2, 0.15, 0.05), (3.5, 2.6), z=0.55, parent="ns")
    room.add("wardrobe", "wardrobe", (1.0, 0.6, 2.0), (0.4, 1.5), yaw_deg=-90)
    return room


# ------------------------------------------------------------------------------------------- 3D-FRONT
def assert_round_trip(original: RoomSet, folder: Path) -> int:
    """Every room read back by the ingest has the same objects, poses (1 mm, 0.1 degree) and graph; returns the
    number of edges compared."""
    back = roundtrip.reingest(folder)
    pairs = roundtrip.by_original(back, original)
    assert sorted(pairs) == sorted(r.room_id for r in original.rooms)
    compared = 0
    for room in original.rooms:
        b = pairs[room.room_id]
        assert (b.categories, b.model_ids) == (room.categories, room.model_ids), room.room_id
        offset, turn = roundtrip.pose_errors(room, b)
        assert offset <= 1e-3 and turn <= 0.1, (room.room_id, offset, turn)
        missing, extra = roundtrip.graph_difference(room, b, original, back, CFG)
        assert not missing and not extra, (room.room_id, sorted(missing)[:5], sorted(extra)[:5])
        compared += len(roundtrip._edges(room, original, CFG, {}))
    return compared


def test_a_generated_set_in_3d_front_reads_back_with_the_same_objects_poses_and_graph(generated, tmp_path):
    out, summary = export_folder("front3d", generated, tmp_path / "front3d", OPTIONS)
    rooms = load_set(table_paths(generated), str(generated))
    assert summary["rooms"] == len(rooms.rooms) == 15 and (out / "front3d.yaml").exists()
    assert any(p for ps in rooms.parents.values() for p in ps)  # supported objects are among them
    assert assert_round_trip(rooms, out) > 15 * 10


def test_a_3d_front_child_has_the_ingests_axes_inverted():
    room = hand_room()
    house = front3d.house(room.room_input())
    bed = house["scene"]["room"][0]["children"][0]
    assert house["furniture"][0] | {"uid": "0/model"} == {"uid": "0/model", "jid": "m_bed", "aid": [], "title": "bed",
                                                          "category": "bed", "valid": True}
    assert bed["pos"] == [2.0, 0.0, -1.8] and bed["scale"] == [1.0, 1.0, 1.0]
    assert np.allclose(bed["rot"], [0.0, -math.sin(math.pi / 4), 0.0, math.cos(math.pi / 4)])  # yaw 90 - 180 deg
    yaw, tilt = yaw_from_quaternion(bed["rot"])
    assert math.isclose(yaw + math.pi, math.pi / 2) and tilt == 0.0
    kinds = [m["type"] for m in house["mesh"]]
    assert kinds == ["Floor", "Ceiling", "WallInner", "WallInner", "WallInner", "WallInner", "Door"]
    assert front3d.obj_text(np.array([[1.0, 2.0, 3.0]]) @ front3d.TO_MODEL, np.array([[0, 0, 0]])) == "v -1.0 3.0 2.0\nf 1 1 1\n"


@pytest.mark.realdata
def test_real_3d_front_rooms_with_their_meshes_read_back_exactly(tmp_path):
    data = shared_data("3d-front-meshes")
    section = yaml.safe_load((ROOT / "config" / "front3d.yaml").read_text())["front3d"]
    cfg = config.validate({"source": "front3d", "front3d": {**section, "houses": str(data / "houses"),
                                                            "future": str(data / "3d-future"), "cache_dir": None}})
    corpus = write_shards(tmp_path / "corpus", ingest_front3d(cfg, 0, 1))
    out, summary = export_folder("front3d", corpus, None, OPTIONS)
    assert out == corpus / "export" / "front3d" and summary["rooms"] == 11
    assert assert_round_trip(load_set(table_paths(corpus), str(corpus)), out) > 500


# ------------------------------------------------------------------------------------------- USD
def test_a_usd_stage_holds_every_object_with_its_world_transform_and_attributes(generated, tmp_path):
    from pxr import Usd, UsdGeom

    out, summary = export_folder("usd", generated, tmp_path / "usd", OPTIONS)
    rooms = load_set(table_paths(generated), str(generated))
    assert summary["files"] == [f"{r.room_id}.usdc" for r in rooms.rooms]
    nested = 0
    for room in rooms.rooms:
        stage = Usd.Stage.Open(str(out / f"{room.room_id}.usdc"))
        assert UsdGeom.GetStageUpAxis(stage) == "Y" and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
        prims = {p.GetAttribute("planit:nodeId").Get(): p for p in stage.Traverse() if p.HasAttribute("planit:nodeId")}
        assert sorted(prims) == sorted(room.object_ids)
        cache = UsdGeom.XformCache()
        for k, oid in enumerate(room.object_ids):
            prim = prims[oid]
            assert prim.GetAttribute("planit:category").Get() == room.categories[k]
            assert prim.GetAttribute("planit:modelId").Get() == room.model_ids[k]
            geom = prim.GetChild("geom")
            points = np.array(UsdGeom.Mesh(geom).GetPointsAttr().Get(), float)
            matrix = np.array(cache.GetLocalToWorldTransform(geom))  # row vectors: world = [p, 1] M
            world = np.c_[points, np.ones(len(points))] @ matrix
            p = room.poses[k]
            expected = y_up(transform(rooms.meshes[room.model_ids[k]][0], p[:3], p[3], p[4:]))
            assert np.abs(world[:, :3] - expected).max() < 1e-5, (room.room_id, oid)
            parent = rooms.parents[room.room_id][k]
            if parent is not None:
                assert prim.GetParent().GetAttribute("planit:nodeId").Get() == parent
                nested += 1
        kinds = {p.GetAttribute("planit:kind").Get() for p in stage.Traverse() if p.HasAttribute("planit:kind")}
        assert {"floor", "wall", "door"} <= kinds <= {"floor", "wall", "door", "window"}
    assert nested > 0


def test_a_supported_object_nests_under_its_support_with_its_transform_made_relative(tmp_path):
    from pxr import Usd, UsdGeom

    room = Room([(0, 0), (4, 0), (4, 3), (0, 3)], room_id="hand_office")
    room.add("table", "desk", (1.2, 0.6, 0.75), (2.0, 1.0), yaw_deg=30)
    room.add("lamp", "table_lamp", (0.2, 0.2, 0.4), (2.2, 1.1), yaw_deg=45, z=0.75, parent="table")
    from pipeline.export import usd

    usd.write(hand_set(room), tmp_path, {"usd_extension": "usda"})
    stage = Usd.Stage.Open(str(tmp_path / "hand_office.usda"))
    lamp = UsdGeom.Xformable(stage.GetPrimAtPath("/Room/Objects/table/lamp"))
    ops = {op.GetOpName(): op.Get() for op in lamp.GetOrderedXformOps()}
    # Rz(-30 deg) (0.2, 0.1, 0.75) = (0.2232051, -0.0133975, 0.75), y up: (0.2232051, 0.75, 0.0133975)
    assert np.allclose(ops["xformOp:translate"], (0.22320508, 0.75, 0.01339746)) and math.isclose(ops["xformOp:rotateY"], 15.0)
    assert stage.GetPrimAtPath("/Prototypes").IsAbstract()  # the models' meshes are drawn only where referenced
    assert [str(p.GetPath()) for p in stage.Traverse() if p.GetTypeName() == "Mesh" and "Objects" in str(p.GetPath())] == [
        "/Room/Objects/table/geom", "/Room/Objects/table/lamp/geom"]


# ------------------------------------------------------------------------------------------- ProcTHOR
HAND_HOUSE = {  # hand_room() as a ProcTHOR house, written by hand from the format's fields (assets aside)
    "rooms": [{"id": "room|0", "roomType": "Bedroom", "floorMaterial": {"name": "DarkWoodFloors"}, "children": [],
               "ceilings": [], "floorPolygon": [{"x": 0.0, "y": 0.0, "z": 0.0}, {"x": 4.0, "y": 0.0, "z": 0.0},
                                                {"x": 4.0, "y": 0.0, "z": 3.0}, {"x": 0.0, "y": 0.0, "z": 3.0}]}],
    "walls": [{"id": f"wall|{side}|{w}", "roomId": "room|0", "material": {"name": "PureWhite"},
               "polygon": [{"x": a[0], "y": y, "z": a[1]} for a, y in pts][::1 if side == "0" else -1]}
              for w, pts in (("0.00|0.00|4.00|0.00", [((0.0, 0.0), 0.0), ((4.0, 0.0), 0.0), ((0.0, 0.0), 2.7), ((4.0, 0.0), 2.7)]),
                             ("4.00|0.00|4.00|3.00", [((4.0, 0.0), 0.0), ((4.0, 3.0), 0.0), ((4.0, 0.0), 2.7), ((4.0, 3.0), 2.7)]),
                             ("0.00|3.00|4.00|3.00", [((4.0, 3.0), 0.0), ((0.0, 3.0), 0.0), ((4.0, 3.0), 2.7), ((0.0, 3.0), 2.7)]),
                             ("0.00|0.00|0.00|3.00", [((0.0, 3.0), 0.0), ((0.0, 0.0), 0.0), ((0.0, 3.0), 2.7), ((0.0, 0.0), 2.7)]))
              for side in ("0", "exterior")],
    "doors": [{"id": "door|0|0", "assetId": "Doorway_1", "room0": "room|0", "room1": "room|0",
               "wall0": "wall|0|0.00|0.00|4.00|0.00", "wall1": "wall|exterior|0.00|0.00|4.00|0.00",
               "holePolygon": [{"x": 1.0, "y": 0.0, "z": 0.0}, {"x": 2.0, "y": 2.0, "z": 0.0}],
               "assetPosition": {"x": 1.5, "y": 1.0, "z": 0.0}, "openable": False, "openness": 0}],
    "windows": [],
    "objects": [{"id": "bed", "assetId": "Bed", "position": {"x": 2.0, "y": 0.25, "z": 1.8},
                 "rotation": {"x": 0.0, "y": 270.0, "z": 0.0}, "kinematic": True, "children": []},
                {"id": "ns", "assetId": "SideTable", "position": {"x": 3.5, "y": 0.275, "z": 2.6},
                 "rotation": {"x": 0.0, "y": 0.0, "z": 0.0}, "kinematic": True, "children": [
                     {"id": "books", "assetId": "Book", "position": {"x": 3.5, "y": 0.575, "z": 2.6},
                      "rotation": {"x": 0.0, "y": 0.0, "z": 0.0}, "kinematic": True, "children": []}]}],
    "proceduralParameters": {"ceilingMaterial": {"name": "PureWhite"}, "floorColliderThickness": 1.0, "lights": [],
                             "receptacleHeight": 0.7, "reflections": [], "skyboxId": "Sky1"},
    "metadata": {"schema": "1.0.0", "planit": {"roomId": "hand_bedroom", "roomType": "bedroom"}},
}


def _rounded(value):
    """A JSON value with its numbers rounded to 9 decimals (0.55 + 0.025 is not 0.575 in floating point)."""
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    return round(value, 9) if isinstance(value, float) else value


def _assets(objects: list[dict]) -> list[tuple[str, str]]:
    return [(o["id"], o.pop("assetId")) for o in objects] + [a for o in objects for a in _assets(o["children"])]


def test_a_hand_built_room_exports_as_the_hand_built_house_and_both_validate():
    procthor.check_house(HAND_HOUSE, "HAND_HOUSE")
    house, missing = procthor.house(hand_room().room_input(), [None, None, "ns", None], {})
    procthor.check_house(house, "exported")
    assert missing == ["wardrobe"]
    got, want = _rounded(house), _rounded(HAND_HOUSE)
    assets, types = dict(_assets(got["objects"])), dict(_assets(want["objects"]))
    assert {k: [a for a, _ in thor.asset_sizes()[t]].count(assets[k]) for k, t in types.items()} == dict.fromkeys(types, 1)
    assert got["doors"][0].pop("assetId").startswith("Doorway") and want["doors"][0].pop("assetId")
    assert got == want


def test_broken_houses_are_named_by_file_and_json_path():
    bad = json.loads(json.dumps(HAND_HOUSE))
    bad["objects"][1]["children"][0]["position"]["x"] = "a"
    with pytest.raises(InputError, match=r"^h.json: objects\[1\].children\[0\].position.x: 'a' is not of type 'number'$"):
        procthor.check_house(bad, "h.json")
    bad = json.loads(json.dumps(HAND_HOUSE))
    bad["doors"][0]["wall0"] = "wall|9"
    with pytest.raises(InputError, match=r"^h.json: doors\[0\].wall0: 'wall\|9' names no such entry$"):
        procthor.check_house(bad, "h.json")
    bad["doors"][0]["wall0"] = "wall|0|0.00|0.00|4.00|0.00"
    bad["doors"][0]["holePolygon"][1]["x"] = 4.5
    with pytest.raises(InputError, match=r"doors\[0\].holePolygon: hole .* lies outside its wall \(length 4.000 m"):
        procthor.check_house(bad, "h.json")


def test_a_generated_sets_houses_validate_and_name_the_categories_without_an_asset(generated, tmp_path):
    out, summary = export_folder("procthor", generated, tmp_path / "procthor", OPTIONS)
    known = {a for assets in thor.asset_sizes().values() for a, _ in assets}
    placed = 0
    for name in summary["files"]:
        house = json.loads((out / name).read_text())
        procthor.check_house(house, name)
        stack = list(house["objects"])
        while stack:
            o = stack.pop()
            assert o["assetId"] in known
            stack += o["children"]
            placed += 1
    assert placed + sum(summary["unmapped"].values()) == summary["objects"]
    assert "wardrobe" in summary["unmapped"] and not {"bed", "sofa", "toilet"} & set(summary["unmapped"])
    assert json.loads((out / "export.json").read_text())["unmapped"] == summary["unmapped"]


def test_ithor_rooms_keep_their_asset_ids_and_rotations(tmp_path):
    cfg = config.validate({"source": "ithor", "ithor": {"groups": ["bedrooms"]}})
    corpus = write_shards(tmp_path / "ithor", ingest_ithor(cfg, 0, 1))
    out, summary = export_folder("procthor", corpus, None, {**OPTIONS, "ithor": cfg["ithor"]})
    source, _ = ithor.load(cfg["ithor"])
    checked = 0
    for name in summary["files"]:
        house = json.loads((out / name).read_text())
        room = source["bedrooms"][int(house["metadata"]["planit"]["roomId"].rsplit("_", 1)[1])]
        stack = list(house["objects"])
        while stack:
            o = stack.pop()
            stack += o["children"]
            near = min((s for s in room if s.get("assetId")), key=lambda s: math.dist(_centre(s), _xz(o)))
            if math.dist(_centre(near), _xz(o)) < 1e-3:
                assert o["assetId"] == near["assetId"]
                assert abs((o["rotation"]["y"] - near["rotation"]["y"] + 180) % 360 - 180) < 0.1
                checked += 1
    assert checked >= 0.95 * summary["objects"] and summary["unmapped"] == {}


def _xz(o: dict) -> tuple[float, float]:
    return o["position"]["x"], o["position"]["z"]


def _centre(s: dict) -> tuple[float, float]:
    """Unity (x, z) of the centre of an AI2-THOR object's box: its oriented corners where it has them (as the ingest
    takes them), else its axis-aligned box."""
    corners = ((s.get("objectOrientedBoundingBox") or {}).get("cornerPoints")
               or s["axisAlignedBoundingBox"]["cornerPoints"])
    x, _, z = np.asarray(corners, float).mean(axis=0)
    return float(x), float(z)


# ------------------------------------------------------------------------------------------- the stage, the CLI, bad input
def test_the_rule_writes_an_archive_and_the_default_run_writes_none(generated, tmp_path):
    assert config.validate({})["export"]["formats"] == []
    inp = Files({t: generated / f"{t}.parquet" for t in TABLES})
    got = export_rooms.run(CFG, inp, Files(archive=tmp_path / "usd.zip"), room_type="bedroom", method="planit", format="usd")
    assert got["rooms"] == 15 and got["format"] == "usd"
    names = zipfile.ZipFile(tmp_path / "usd.zip").namelist()
    assert names[0] == "export.json" and len([n for n in names if n.endswith(".usdc")]) == 15


@pytest.mark.slow
def test_the_rule_is_planned_for_a_method_and_format(tmp_path):
    cmd = [str(Path(sys.executable).parent / "snakemake"), "--snakefile", str(ROOT / "Snakefile"), "--directory",
           str(tmp_path), "--configfile", str(ROOT / "config" / "tiny.yaml"), "-n", "-p", "--cores", "1",
           "results/export/bedroom/planit/front3d.zip"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "planit export_rooms --rooms results/generated/bedroom/planit/rooms.parquet" in proc.stdout
    assert "--out-archive results/export/bedroom/planit/front3d.zip --room-type bedroom --method planit --format front3d" in proc.stdout


def test_planit_export_says_where_it_wrote_and_names_bad_input_in_one_line(generated, tmp_path):
    run = lambda *a: subprocess.run([PLANIT, "export", *map(str, a)], capture_output=True, text=True,  # noqa: E731
                                    env={**os.environ, "PYTHONPATH": str(ROOT)})
    ok = run("front3d", generated, "--out", tmp_path / "f")
    assert ok.returncode == 0 and re.fullmatch(rf"wrote 15 rooms \(\d+ objects\) as front3d to {re.escape(str(tmp_path / 'f'))}",
                                               ok.stdout.strip()), ok.stdout
    bad = run("obj", generated)
    assert bad.returncode == 2 and bad.stderr.strip().endswith("error: export format 'obj': unknown (known: usd, procthor, front3d)")
    bad = run("usd", tmp_path)
    assert bad.returncode == 2 and f"error: {tmp_path}: neither a generated set" in bad.stderr


def test_a_missing_table_a_missing_model_and_an_unusable_model_id_are_named(generated, tmp_path):
    t = {n: tables.read(generated / f"{n}.parquet", n if n != "objects" else "objects") for n in TABLES}
    folder = write_set(tmp_path / "set", t)
    (folder / "models.parquet").unlink()
    with pytest.raises(InputError, match=r"models.parquet: not found \(.*needs the tables rooms, architecture"):
        export_folder("usd", folder, None, OPTIONS)
    first = t["models"]["model_id"].to_pylist().index(t["objects"]["model_id"][0].as_py())
    twin = t["models"].slice(first, 1)
    models = pa.concat_tables([t["models"], twin.set_column(0, twin.schema.field(0), pa.array(["../evil"], twin.schema.field(0).type))])
    objects = t["objects"].set_column(3, t["objects"].schema.field(3), pa.array(["../evil" if i == 0 else m for i, m in
                                                               enumerate(t["objects"]["model_id"].to_pylist())]))
    write_set(folder, {**t, "objects": objects})
    with pytest.raises(InputError, match=r"objects.parquet: room \w+, object obj_00: field model_id: model '../evil' "
                                         r"has no mesh in .*models.parquet"):
        export_folder("usd", folder, None, OPTIONS)
    write_set(folder, {**t, "objects": objects, "models": models})
    with pytest.raises(InputError, match=r"models table: field model_id: '../evil' cannot be a 3D-FUTURE folder name"):
        export_folder("front3d", folder, None, OPTIONS)


def test_a_room_whose_walls_do_not_close_is_skipped_and_named(generated, tmp_path):
    t = {n: tables.read(generated / f"{n}.parquet", n) for n in TABLES}
    arch = t["architecture"].to_pandas()
    first = arch["room_id"].iloc[0]
    gone = arch.index[(arch["room_id"] == first) & (arch["element_id"] == "wall_1")]
    folder = write_set(tmp_path / "set", {**t, "architecture": tables.from_rows("architecture", tables.records(arch.drop(gone)))})
    out, summary = export_folder("procthor", folder, None, OPTIONS)
    assert summary["rooms"] == 14 and list(summary["skipped"]) == [first]
    assert "walls do not form a closed loop" in summary["skipped"][first]
    assert json.loads((out / "export.json").read_text())["skipped"] == summary["skipped"]
