"""The inspector's page: one self-contained HTML file (three.js and its OrbitControls inlined as ``data:`` modules
through an import map, the app and the rooms' JSON inline), so it opens from ``file://`` with no server and nothing
fetched. three.js comes from npm (``pipeline/viewer/package.json``, pinned; ``make setup`` runs ``npm ci``); its MIT
licence travels in each page's comment."""
from __future__ import annotations

import base64
import html
import json
from pathlib import Path

from ..errors import InputError

HERE = Path(__file__).resolve().parent
THREE = HERE / "node_modules" / "three"
MODULES = {"three": "build/three.module.min.js",
           "three/addons/controls/OrbitControls.js": "examples/jsm/controls/OrbitControls.js"}

STYLE = """
body { margin: 0; font: 13px sans-serif; }
#bar { padding: 6px; background: #eee; display: flex; gap: 12px; align-items: center; flex-wrap: wrap; }
#main { display: flex; height: calc(100vh - 44px); }
#view { flex: 1 1 0; width: 0; min-width: 0; height: 100%; display: block; }
#side { flex: none; width: 340px; overflow: auto; padding: 8px; border-left: 1px solid #ccc; }
#side li { margin-bottom: 4px; }
.key span { display: inline-block; width: 12px; height: 12px; margin: 0 4px 0 10px; vertical-align: middle; }
"""

BODY = """<div id="bar"><select id="room"></select>
<label>graph <select id="graph"></select></label>
<label><input type="checkbox" id="pruned"> pruned edges</label>
<label><input type="checkbox" id="groups"> superstructures (hubs yellow, chains blue)</label>
<label>insertion order <input type="range" id="step" min="0" step="1"></label><span id="counts"></span></div>
<div id="main"><canvas id="view"></canvas><div id="side"><h3 id="title"></h3>
<p class="key"><span style="background:#222"></span>support<span style="background:#d62728"></span>adjacent
<span style="background:#ff7f0e"></span>proximal<span style="background:#1f77b4"></span>distant
<span style="background:#aaa"></span>pruned</p>
<p class="key">difference: <span style="background:#2ca02c"></span>kept<span style="background:#d62728"></span>lost
<span style="background:#9467bd"></span>unplanned</p>
<p>Click an object to list its edges.</p><b id="picked"></b><ul id="edges"></ul></div></div>"""


def vendored() -> dict[str, str]:
    """The import map's modules as ``data:`` URLs; an error naming the missing file and the fix without npm's copy."""
    out = {}
    for name, rel in MODULES.items():
        path = THREE / rel
        if not path.exists():
            raise InputError(f"{path}: three.js is not installed for the viewer (run make setup, which runs "
                             f"npm ci --prefix {HERE.relative_to(HERE.parents[1])})")
        out[name] = "data:text/javascript;base64," + base64.b64encode(path.read_bytes()).decode()
    return out


def page(rooms: list[dict], title: str) -> str:
    """The HTML of a viewer over ``rooms`` (:func:`~pipeline.viewer.payload.room_payload` dicts)."""
    if not rooms:
        raise InputError(f"{title}: no room to show")
    version = json.loads((THREE / "package.json").read_text())["version"] if (THREE / "package.json").exists() else "?"
    imports = json.dumps({"imports": vendored()})
    data = json.dumps(rooms, separators=(",", ":")).replace("</", "<\\/")
    app = (HERE / "app.js").read_text()
    return (f"<!doctype html>\n<!-- three.js {version} (MIT licence, (c) 2010-2024 three.js authors), inlined -->\n"
            f"<html><head><meta charset=\"utf-8\"><title>{html.escape(title)}</title><style>{STYLE}</style>"
            f"<script type=\"importmap\">{imports}</script></head><body>{BODY}"
            f"<script type=\"application/json\" id=\"rooms\">{data}</script>"
            f"<script type=\"module\">{app}</script></body></html>\n")
