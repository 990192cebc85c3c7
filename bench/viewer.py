"""The room inspector's speed (issue 32's goals): a real 3D-FRONT room with its furniture meshes, from the ingested
tables to the first frame in headless Chromium (page build in Python, then the browser's navigation to its first
rendered frame), and the frame rate of a 40-object room (the same room's objects repeated across a larger floor).

    .venv/bin/python bench/viewer.py            # needs ../shared/data/3d-front-meshes, chromium and chromedriver
    .venv/bin/python bench/viewer.py shot PAGE.html OUT.png [OBJECT_ID]   # a screenshot of a page (the README's)

WebGL runs on SwiftShader (the CPU): a machine with a GPU draws faster. Writes nothing but a temporary folder."""
from __future__ import annotations

import copy
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]

import pandas as pd  # noqa: E402

from pipeline.viewer.page import page  # noqa: E402
from pipeline.viewer.sources import corpus_room  # noqa: E402

from conftest import shared_data  # noqa: E402
from test_sources import ingest_outputs, run_ingest  # noqa: E402
from webdriver import Browser  # noqa: E402


def spread(data: dict, count: int) -> dict:
    """The room's payload with its objects repeated (shifted by whole room widths along x) up to ``count``."""
    out = copy.deepcopy(data)
    xs = [p[0] for p in data["outline"]]
    width = max(xs) - min(xs) + 0.5
    k = 0
    while len(out["objects"]) < count:
        o = copy.deepcopy(data["objects"][k % len(data["objects"])])
        o["id"], o["mesh"] = f"{o['id']}_copy{k}", None  # boxes: the shifted mesh would need new vertices
        o["box"][0] += width * (1 + k // len(data["objects"]))
        out["objects"].append(o)
        k += 1
    return out


def browse(browser: Browser, html: Path, seconds: float) -> dict:
    """First-frame time (ms after navigation began) and frames per second over ``seconds``."""
    browser.open(html.as_uri())
    state = browser.wait_for(lambda: browser.run("return window.viewer && window.viewer.state.frames > 2 ? "
                                                 "window.viewer.state : null"), 120)
    start, t0 = browser.run("return window.viewer.state.frames"), time.perf_counter()
    time.sleep(seconds)
    frames, t1 = browser.run("return window.viewer.state.frames"), time.perf_counter()
    return {"objects": state["objects"], "edges": state["edges"], "first_frame_ms": round(state["first_frame_ms"]),
            "fps": round((frames - start) / (t1 - t0), 1)}


def main() -> None:
    tmp = Path(tempfile.mkdtemp())
    sample = shared_data("3d-front-meshes")
    run_ingest("front3d", {"houses": str(sample / "houses"), "future": str(sample / "3d-future"),
                           "cache_dir": str(tmp / "cache")}, tmp)
    outs = ingest_outputs(tmp / "ingest")
    objs = pd.read_parquet(outs["objects"]).merge(pd.read_parquet(outs["models"])[["model_id", "mesh_kind"]], on="model_id")
    room_id = objs[objs["mesh_kind"] == "mesh"]["room_id"].value_counts().index[0]
    shards = {t: [outs[t]] for t in ("rooms", "architecture", "objects", "models")}
    t0 = time.perf_counter()
    data = corpus_room(shards, None, room_id, "ingest")
    real = tmp / "real.html"
    real.write_text(page([data], room_id))
    build = time.perf_counter() - t0
    big = tmp / "forty.html"
    big.write_text(page([spread(data, 40)], "40 objects"))
    browser = Browser(tmp / "profile")
    try:
        one = browse(browser, real, 5)
        forty = browse(browser, big, 5)
    finally:
        browser.close()
    meshed = sum(o["mesh"] is not None for o in data["objects"])
    print(f"machine: {platform.processor() or platform.machine()}, headless Chromium, WebGL on SwiftShader")
    print(f"3D-FRONT room {room_id}: {len(data['objects'])} objects ({meshed} with real meshes), page "
          f"{real.stat().st_size / 2**20:.1f} MB")
    print(f"  page built in {build:.2f} s; first frame {one['first_frame_ms']} ms after navigation; "
          f"open total {build + one['first_frame_ms'] / 1000:.2f} s; {one['fps']} frames/s")
    print(f"40-object room: first frame {forty['first_frame_ms']} ms, {forty['fps']} frames/s")


def shot(html: Path, out: Path, select: str | None = None) -> None:
    """A screenshot of a viewer page after it has drawn (with ``select``'s edges listed)."""
    tmp = Path(tempfile.mkdtemp())
    browser = Browser(tmp / "profile")
    try:
        browser.open(html.resolve().as_uri())
        browser.wait_for(lambda: browser.run("return window.viewer && window.viewer.state.frames > 2"), 120)
        if select:
            browser.run(f"window.viewer.select({select!r})")
            time.sleep(0.5)
        browser.screenshot(out)
    finally:
        browser.close()
    print(f"wrote {out}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["shot"]:
        shot(Path(sys.argv[2]), Path(sys.argv[3]), sys.argv[4] if len(sys.argv) > 4 else None)
    else:
        main()
