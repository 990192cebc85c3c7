"""The room inspector (issue 32): payloads built from hand-built rooms and real extraction, the self-contained page
opened in headless Chromium (WebGL on SwiftShader) where the viewer's own state and DOM are read, a real 3D-FRONT
room with its meshes, ``planit view`` on a run's tables with its one-line errors, and ``--serve``."""
from __future__ import annotations

import io
import re
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from pipeline.placement.layout import walls_of
from pipeline.viewer import payload
from pipeline.viewer.page import THREE, page

from conftest import ROOT, Room, shared_data

pytestmark = pytest.mark.skipif(not (THREE / "package.json").exists(),
                                reason="three.js is not installed (make setup runs npm ci for the viewer)")


def bedroom() -> Room:
    r = Room([(0, 0), (4, 0), (4, 3.5), (0, 3.5)], room_id="hand_bedroom")
    r.add("bed", "bed", (1.6, 2.0, 0.5), (2.0, 1.0)).add("ns_l", "nightstand", (0.5, 0.4, 0.55), (0.95, 0.2))
    r.add("ns_r", "nightstand", (0.5, 0.4, 0.55), (3.05, 0.2)).add("wardrobe", "wardrobe", (1.0, 0.6, 2.0), (3.4, 3.1), 180)
    r.add("lamp", "table_lamp", (0.2, 0.2, 0.4), (0.95, 0.2), z=0.55, parent="ns_l")
    return r.door("door_0", (0.2, 3.5), (1.0, 3.5), "wall_2")


def graph_rows(r: Room) -> list[dict]:
    """The room's raw graph from the project's extraction, as the viewer's edges (every edge kept)."""
    found = r.extract()
    return [{**e, "status": "kept"} for e in payload.edge_rows(pd.DataFrame(found.edges))
            if e["edge_type"] in ("support", "spatial")]


def test_a_payload_holds_every_object_wall_opening_and_edge_of_the_room():
    r = bedroom()
    room = r.room_input()
    edges = graph_rows(r)
    data = payload.room_payload("t", room, walls_of(room), r.models.get, {"raw": edges}, {"bed": "hub"})
    assert [o["id"] for o in data["objects"]] == room.object_ids and len(data["walls"]) == 4
    assert data["openings"] == [{"id": "door_0", "kind": "door", "a": [0.2, 3.5], "b": [1.0, 3.5], "z0": 0.0, "z1": 2.0,
                                 "wall": "wall_2"}]
    bed = data["objects"][0]
    v = np.frombuffer(__import__("base64").b64decode(bed["mesh"]["v"]), np.float32).reshape(-1, 3)
    assert v.min(0) == pytest.approx([1.2, 0.0, 0.0], abs=1e-6) and v.max(0) == pytest.approx([2.8, 2.0, 0.5], abs=1e-6)
    assert bed["role"] == "hub" and data["objects"][1]["role"] is None
    assert any(e["edge_type"] == "support" and (e["source"], e["target"]) == ("ns_l", "lamp") for e in edges)


def test_the_difference_of_a_plan_and_an_extracted_graph_names_kept_lost_and_unplanned_edges():
    plan = [{"source": "wall_0", "target": "bed", "edge_type": "spatial", "direction": "front", "distance": "adjacent"},
            {"source": "bed", "target": "ns", "edge_type": "spatial", "direction": "left", "distance": "adjacent"},
            {"source": "bed", "target": "gone", "edge_type": "spatial", "direction": "left", "distance": "adjacent"}]
    found = [plan[0], {**plan[1], "distance": "proximal"}, {"source": "ns", "target": "lamp", "edge_type": "support",
                                                           "direction": None, "distance": None}]
    got = {(e["source"], e["target"], e["distance"]): e["status"] for e in payload.difference(plan, found, {"wall_0", "bed", "ns", "lamp"})}
    assert got == {("wall_0", "bed", "adjacent"): "kept", ("bed", "ns", "adjacent"): "lost",
                   ("bed", "ns", "proximal"): "unplanned", ("ns", "lamp", None): "unplanned"}


def _browser(tmp_path):
    from webdriver import CHROMEDRIVER, CHROMIUM, Browser

    if not (CHROMIUM and CHROMEDRIVER):
        pytest.skip("Debian's chromium and chromium-driver are not installed (make test installs them where it can)")
    return Browser(tmp_path / "profile")


def _drawn(browser, timeout: float = 30.0) -> dict:
    """The viewer's state once it has drawn its room and rendered a few frames."""
    state = browser.wait_for(lambda: browser.run("return window.viewer && window.viewer.state.drawn && "
                                                 "window.viewer.state.frames > 2 ? window.viewer.state : null"), timeout)
    assert state, "the viewer did not draw"
    return state


def _canvas_pixels(browser, tmp_path) -> np.ndarray:
    """The canvas's pixels from a screenshot of the page: (H, W, 3) floats."""
    from matplotlib.image import imread

    shot = browser.screenshot(tmp_path / "shot.png")
    image = imread(io.BytesIO(shot.read_bytes()))[..., :3]
    x, y, w, h = (int(v) for v in browser.run("const r = document.getElementById('view').getBoundingClientRect();"
                                             "return [r.left, r.top, r.width, r.height]"))
    return image[y:y + h, x:x + w]


def test_the_page_draws_the_room_in_chromium_and_lists_an_objects_edges(tmp_path):
    """A hand-built bedroom and its extracted graph: the canvas is not blank, the viewer holds one mesh per object
    and one arrow per edge, clicking the bed through the viewer lists exactly its edges, and the insertion slider
    hides the later objects with their edges."""
    r = bedroom()
    room = r.room_input()
    edges = graph_rows(r)
    html = tmp_path / "room.html"
    html.write_text(page([payload.room_payload("hand bedroom", room, walls_of(room), r.models.get, {"raw": edges})], "t"))
    browser = _browser(tmp_path)
    try:
        browser.open(html.as_uri())
        state = _drawn(browser)
        pixels = _canvas_pixels(browser, tmp_path)
        listed = browser.run("return window.viewer.select('bed')")
        shown = [li for li in browser.run("return [...document.querySelectorAll('#edges li')].map(l => l.textContent)")]
        browser.run("window.viewer.setStep(1)")
        first = browser.run("return window.viewer.state")
    finally:
        browser.close()
    assert state["objects"] == 5 and state["edges"] == len(edges)
    assert pixels.std() > 0.05 and len(np.unique((pixels * 255).astype(int).reshape(-1, 3), axis=0)) > 50  # not blank
    bed_edges = [e for e in edges if "bed" in (e["source"], e["target"])]
    assert len(listed) == len(shown) == len(bed_edges) > 0 and all("bed" in t for t in shown)
    assert first["objects"] == 1 and first["edges"] == sum(e["source"] not in room.object_ids[1:] and
                                                          e["target"] not in room.object_ids[1:] for e in edges)


def test_a_real_3d_front_room_with_its_meshes_draws_with_every_object(tmp_path):
    from pipeline.viewer.sources import corpus_room

    from test_sources import ingest_outputs, run_ingest

    sample = shared_data("3d-front-meshes")
    run_ingest("front3d", {"houses": str(sample / "houses"), "future": str(sample / "3d-future"),
                           "cache_dir": str(tmp_path / "cache")}, tmp_path)
    outs = ingest_outputs(tmp_path / "ingest")
    objs = pd.read_parquet(outs["objects"]).merge(pd.read_parquet(outs["models"])[["model_id", "mesh_kind"]], on="model_id")
    meshed = objs[objs["mesh_kind"] == "mesh"]
    room_id = meshed["room_id"].value_counts().index[0]  # the room with the most real furniture meshes
    shards = {t: [outs[t]] for t in ("rooms", "architecture", "objects", "models")}
    data = corpus_room(shards, None, room_id, "ingest")
    with_mesh = sum(o["mesh"] is not None for o in data["objects"])
    html = tmp_path / "front.html"
    html.write_text(page([data], room_id))
    browser = _browser(tmp_path)
    try:
        browser.open(html.as_uri())
        state = _drawn(browser, 60)
        pixels = _canvas_pixels(browser, tmp_path)
    finally:
        browser.close()
    assert with_mesh == (meshed["room_id"] == room_id).sum() >= 8 and data["openings"]  # real meshes, doors, windows
    assert state["objects"] == len(data["objects"]) == (objs["room_id"] == room_id).sum()
    assert pixels.std() > 0.05


def _planit(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pipeline", *args], cwd=cwd, capture_output=True, text=True,
                          env={"PYTHONPATH": str(ROOT), "PATH": str(Path(sys.executable).parent) + ":/usr/bin:/bin"})


def _error(got: subprocess.CompletedProcess) -> str:
    """The one ``error:`` line of a failed command (exit code 2)."""
    lines = [line for line in got.stderr.splitlines() if line.startswith("error:")]
    assert got.returncode == 2 and len(lines) == 1, got.stderr
    return lines[0]


def test_bad_input_gives_one_line_naming_it(tmp_path):
    (tmp_path / "results" / "ingest" / "shards").mkdir(parents=True)
    assert "results/ingest/shards: no ingested rooms" in _error(_planit("view", "--room", "nope", cwd=tmp_path))
    empty = tmp_path / "results/generated/bedroom/planit"
    empty.mkdir(parents=True)
    assert "planit/rooms.parquet: not found" in _error(_planit("view", str(empty), cwd=tmp_path))
    assert "--room" in _error(_planit("view", cwd=tmp_path))


def test_serve_listens_on_localhost_and_stops_cleanly(tmp_path):
    r = bedroom()
    room = r.room_input()
    html = tmp_path / "room.html"
    html.write_text(page([payload.room_payload("t", room, walls_of(room), r.models.get, {})], "t"))
    proc = subprocess.Popen([sys.executable, "-c", "import sys; from pathlib import Path; "
                             "from pipeline.viewer.serve import serve; serve(Path(sys.argv[1]), port=0)", str(html)],
                            cwd=ROOT, stdout=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        url = re.search(r"http://\S+", line).group()
        assert url.startswith("http://127.0.0.1:")
        body = urllib.request.urlopen(url, timeout=10).read().decode()
        assert "importmap" in body and "hand_bedroom" in body
    finally:
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=60)  # a bound, not a timing: a loaded CI machine is slow to exit
    assert proc.returncode == 0 and "stopped" in out


def test_a_run_of_pages_is_self_contained():
    """Nothing in a page is fetched: no src or href to another file, three.js inlined as data: modules."""
    r = bedroom()
    room = r.room_input()
    html = page([payload.room_payload("t", room, walls_of(room), r.models.get, {})], "t")
    assert not re.search(r"""(src|href)=["'](?!data:)""", html)
    assert '"three":"data:text/javascript;base64,' in html.replace(" ", "")
