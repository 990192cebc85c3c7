"""Tables as self-contained HTML pages: what the Snakemake report shows (it opens an ``.html`` result in an iframe).

The API (kept small and stable; the CSV of a table stays the file for programs, the HTML page is for people):

- ``table_html(frame, title, caption="", marks=None, notes=None) -> str``: a complete page with one table.
- ``page(title, tables, intro="") -> str``: several tables on one page; ``tables`` is a list of :class:`Table`
  (``Table(title, frame, caption="", marks=None, notes=None)``, or plain tuples in that order).
- ``write_table_html(path, frame, title, caption="", marks=None, notes=None) -> Path`` and
  ``write_html(path, text) -> Path``: written atomically (``tables.write_atomic``).

Every page is self-contained (inline CSS and a few lines of inline JavaScript, no network resource) and every text
is HTML-escaped. A click on a column header sorts the rows by that column (a second click reverses): numbers by
the exact value in the cell's ``data-value`` (shown rounded to 4 significant digits, integers whole), a number with
its interval (``"0.12 [0.10, 0.15]"``) by that number, other text alphabetically; empty cells (NaN, None)
sort last. ``marks`` is a frame of the table's index and columns holding a short string per cell (``""`` or NaN for
none): a marked cell is highlighted (CSS class ``mark``), shows its mark after the value and as its tooltip.
``notes`` maps a column name to its explanation: the header's tooltip and a list under the table. An unnamed
``RangeIndex`` is not shown; any other index becomes the first columns.
"""
from __future__ import annotations

import math
import numbers
import re
from html import escape
from itertools import repeat
from pathlib import Path
from typing import NamedTuple

import pandas as pd

from .tables import write_atomic

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
# a number, or a number and its interval ("0.12 [0.1, 0.15]"): sorted by the number; any other text as text
LEADING_NUMBER = re.compile(rf"\s*({NUM})(?:\s*\[\s*{NUM}\s*,\s*{NUM}\s*\])?\s*")

CSS = """
body { font: 14px/1.4 system-ui, -apple-system, "Segoe UI", sans-serif; color: #1e293b; background: #fff; margin: 1em; }
h1 { font-size: 1.3em; margin: 0 0 .4em; } h2 { font-size: 1.1em; margin: 1.4em 0 .3em; }
p.caption { color: #475569; max-width: 60em; margin: 0 0 .6em; }
table.sortable { border-collapse: collapse; margin-bottom: .5em; }
table.sortable th, table.sortable td { padding: .25em .6em; border-bottom: 1px solid #e2e8f0; white-space: nowrap; }
table.sortable th { position: sticky; top: 0; background: #f1f5f9; cursor: pointer; user-select: none;
  text-align: left; }
table.sortable th[title] { text-decoration: underline dotted; }
table.sortable th[aria-sort="ascending"]::after { content: " \\25B2"; }
table.sortable th[aria-sort="descending"]::after { content: " \\25BC"; }
table.sortable td.num { text-align: right; font-variant-numeric: tabular-nums; }
table.sortable tbody tr:hover { background: #f8fafc; }
td.mark { font-weight: bold; background: #fef3c7; }
td.mark span.mk { color: #b45309; margin-left: .15em; }
dl.notes { color: #475569; font-size: .92em; } dl.notes dt { font-weight: bold; float: left; margin-right: .5em; }
"""

# A click on a header sorts its table by that column: numbers (data-value), then text, then empty cells.
SCRIPT = """
document.querySelectorAll("table.sortable th").forEach(function (th) {
  th.addEventListener("click", function () {
    var table = th.closest("table"), body = table.tBodies[0], col = th.cellIndex;
    var dir = th.getAttribute("aria-sort") === "ascending" ? -1 : 1;
    table.querySelectorAll("th").forEach(function (h) { h.removeAttribute("aria-sort"); });
    th.setAttribute("aria-sort", dir > 0 ? "ascending" : "descending");
    function key(row) {
      var c = row.cells[col], v = c.getAttribute("data-value");
      return v === null ? [1, c.textContent.trim()] : v === "" ? [2, ""] : [0, parseFloat(v)];
    }
    var rows = Array.from(body.rows).map(function (r) { return [key(r), r]; });
    rows.sort(function (a, b) {
      var x = a[0], y = b[0];
      if (x[0] !== y[0] || x[0] === 2) return x[0] - y[0];
      return dir * (x[0] === 0 ? x[1] - y[1] : x[1].localeCompare(y[1], undefined, {numeric: true}));
    });
    rows.forEach(function (r) { body.appendChild(r[1]); });
  });
});
"""


class Table(NamedTuple):
    """One table of a page: a heading (none when empty), the frame, a caption under the heading, per-cell marks and
    per-column notes (as in :func:`table_html`)."""
    title: str
    frame: pd.DataFrame
    caption: str = ""
    marks: pd.DataFrame | None = None
    notes: dict[str, str] | None = None


def _missing(value) -> bool:
    """None, NaN, NaT and pd.NA (never a list or other container)."""
    return value is None or (pd.api.types.is_scalar(value) and bool(pd.isna(value)))


def _number_text(value: float) -> str:
    """A float as shown: whole numbers without decimals, large ones rounded to units, others to 4 significant digits."""
    if math.isinf(value):
        return "\u221e" if value > 0 else "-\u221e"
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return f"{value:.0f}" if 1000 <= abs(value) < 1e15 else f"{value:.4g}"


def cell(value) -> tuple[str, str | None]:
    """(text shown, sort key for ``data-value`` or None to sort as text); missing values give ("", "")."""
    if _missing(value):
        return "", ""
    if isinstance(value, (bool, str)) or not isinstance(value, numbers.Real):
        text = str(value)
        if not text.strip():
            return text, ""
        lead = LEADING_NUMBER.fullmatch(text)
        return text, (repr(float(lead.group(1))) if lead else None)
    if isinstance(value, numbers.Integral):
        return str(int(value)), str(int(value))
    value = float(value)
    key = "Infinity" if value == math.inf else "-Infinity" if value == -math.inf else repr(value)
    return _number_text(value), key


def _shown(frame: pd.DataFrame, marks: pd.DataFrame | None) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """The frame (and marks) with a meaningful index moved into the first columns; marks checked against it."""
    if marks is not None and not (marks.index.equals(frame.index) and marks.columns.equals(frame.columns)):
        raise ValueError("marks must have the table's index and columns")
    if isinstance(frame.index, pd.RangeIndex) and frame.index.name is None:
        return frame, marks
    levels = frame.index.nlevels
    frame = frame.reset_index()
    if marks is not None:
        marks = marks.reset_index(drop=True)
        for k in range(levels):
            marks.insert(k, f"\0index{k}", "", allow_duplicates=True)
        marks.columns = frame.columns
    return frame, marks


def _label(column) -> str:
    """A column's header text (a MultiIndex column's levels joined by " / ")."""
    return " / ".join(str(c) for c in column) if isinstance(column, tuple) else str(column)


def _td(value, mark) -> str:
    """One cell: its text, ``data-value`` (a sort key; absent for text) and, when marked, its mark."""
    text, key = cell(value)
    classes, attrs, body = ["num"] if key else [], "" if key is None else f' data-value="{escape(key)}"', escape(text)
    if not _missing(mark) and str(mark).strip():
        classes.append("mark")
        attrs += f' title="{escape(str(mark))}"'
        body += f'<span class="mk">{escape(str(mark))}</span>'
    if classes:
        attrs += f' class="{" ".join(classes)}"'
    return f"<td{attrs}>{body}</td>"


def _table(frame: pd.DataFrame, marks: pd.DataFrame | None, notes: dict[str, str] | None) -> str:
    """The ``<table>`` element (and the notes' list under it)."""
    frame, marks = _shown(frame, marks)
    notes = notes or {}
    heads = []
    for column in frame.columns:
        label = _label(column)
        tip = f' title="{escape(notes[label])}"' if label in notes else ""
        heads.append(f'<th scope="col"{tip}>{escape(label)}</th>')
    values = frame.itertuples(index=False, name=None)  # per column, so an int column stays int
    row_marks = marks.itertuples(index=False, name=None) if marks is not None else repeat((None,) * frame.shape[1])
    rows = ["<tr>" + "".join(_td(v, m) for v, m in zip(vs, ms)) + "</tr>" for vs, ms in zip(values, row_marks)]
    out = (f'<table class="sortable"><thead><tr>{"".join(heads)}</tr></thead>\n<tbody>\n'
           + "\n".join(rows) + "\n</tbody></table>")
    if notes:
        out += '\n<dl class="notes">' + "".join(f"<dt>{escape(k)}</dt><dd>{escape(v)}</dd>"
                                                for k, v in notes.items()) + "</dl>"
    return out


def _caption(text: str) -> str:
    """Paragraphs (split at blank lines) of escaped text; nothing for an empty text."""
    return "".join(f'<p class="caption">{escape(p.strip())}</p>\n' for p in re.split(r"\n\s*\n", text) if p.strip())


def page(title: str, tables: list[Table] | list[tuple], intro: str = "") -> str:
    """A complete, self-contained HTML page: the title, an intro, then each table (its heading, caption, table)."""
    parts = [f"<h1>{escape(title)}</h1>", _caption(intro)]
    for t in tables:
        t = Table(*t)
        if t.title:
            parts.append(f"<h2>{escape(t.title)}</h2>")
        parts += [_caption(t.caption), _table(t.frame, t.marks, t.notes)]
    return ('<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">\n<title>{escape(title)}</title>\n'
            f"<style>{CSS}</style>\n</head>\n<body>\n" + "\n".join(p for p in parts if p)
            + f"\n<script>{SCRIPT}</script>\n</body>\n</html>\n")


def table_html(frame: pd.DataFrame, title: str, caption: str = "", marks: pd.DataFrame | None = None,
               notes: dict[str, str] | None = None) -> str:
    """A complete, self-contained HTML page holding one sortable table (see the module's docstring)."""
    return page(title, [Table("", frame, caption, marks, notes)])


def write_html(path: str | Path, text: str) -> Path:
    """An HTML page (any text) written atomically, UTF-8."""
    return write_atomic(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def write_table_html(path: str | Path, frame: pd.DataFrame, title: str, caption: str = "",
                     marks: pd.DataFrame | None = None, notes: dict[str, str] | None = None) -> Path:
    """:func:`table_html` written atomically to ``path``."""
    return write_html(path, table_html(frame, title, caption, marks, notes))
