"""The annealing methods' energy traces of one room type (the first scene of each) as one figure for the report."""
from __future__ import annotations

import json
from pathlib import Path

from .. import tables
from ..stage import Files


def run(config: dict, inp: Files, out: Files, room_type: str) -> dict:
    from ..methods.solver.trace import first_trace, trace_figure

    traces = {}
    for scenes, summary in zip(inp.generated_scenes, inp.summaries):
        got = first_trace(tables.read(scenes, "scenes").to_pandas())
        if got is not None:
            traces[json.loads(Path(summary).read_text())["variant"]] = got
    tables.write_figure(out.figure, trace_figure(traces, room_type), dpi=110)
    return {"room_type": room_type, "methods": list(traces)}
