"""Tables as self-contained HTML pages (pipeline/html.py): escaping, numbers, marks, sort keys, missing values."""
import re

import numpy as np
import pandas as pd
import pytest

from pipeline.html import Table, cell, page, table_html, write_table_html


def _cells(html: str) -> list[str]:
    return re.findall(r"<td[^>]*>.*?</td>", html)


def test_text_titles_captions_and_notes_are_escaped():
    frame = pd.DataFrame({"a<b": ["<script>alert(1)</script>", 'say "hi" & go']})
    html = table_html(frame, "T & <i>", caption="x < y", notes={"a<b": 'the "a" column'})
    assert "<script>alert" not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert "say &quot;hi&quot; &amp; go" in html and "<title>T &amp; &lt;i&gt;</title>" in html
    assert '<p class="caption">x &lt; y</p>' in html
    assert '<th scope="col" title="the &quot;a&quot; column">a&lt;b</th>' in html


def test_numbers_are_rounded_for_show_and_exact_in_data_value():
    frame = pd.DataFrame({"n": [3, 1200], "x": [0.123456789, 12345.678], "w": [2.0, -0.5]})
    cells = _cells(table_html(frame, "t"))
    assert cells[0] == '<td data-value="3" class="num">3</td>'
    assert cells[1] == '<td data-value="0.123456789" class="num">0.1235</td>'
    assert cells[2] == '<td data-value="2.0" class="num">2</td>'  # a whole float shows as an integer
    assert cells[4] == '<td data-value="12345.678" class="num">12346</td>'
    assert cells[5] == '<td data-value="-0.5" class="num">-0.5</td>'
    assert cell(np.int64(7)) == ("7", "7") and cell(float("inf")) == ("\u221e", "Infinity")


def test_missing_values_are_empty_cells_that_sort_last():
    frame = pd.DataFrame({"x": [np.nan, 1.5], "s": [None, "a"], "t": [pd.NA, ""]})
    cells = _cells(table_html(frame, "t"))
    assert cells[0] == cells[1] == cells[2] == cells[5] == '<td data-value=""></td>'
    assert 'data-value=""' in table_html(pd.DataFrame({"d": [pd.NaT]}), "t")


def test_a_number_with_its_interval_sorts_by_that_number_other_text_as_text():
    frame = pd.DataFrame({"ci": ["0.12 [0.10, 0.15]", "-3e-2 [-4e-2, 1]", "kitchen", "True", "3D-FRONT rooms"]})
    cells = _cells(table_html(frame, "t"))
    assert cells[0] == '<td data-value="0.12" class="num">0.12 [0.10, 0.15]</td>'
    assert cells[1].startswith('<td data-value="-0.03" class="num">')
    assert cells[2] == "<td>kitchen</td>" and cells[3] == "<td>True</td>"  # no data-value: sorted as text
    assert cells[4] == "<td>3D-FRONT rooms</td>"  # led by a digit, but not a number: text


def test_marks_highlight_their_cells_with_a_tooltip_and_a_visible_mark():
    frame = pd.DataFrame({"method": ["a", "b"], "score": [0.5, 0.25]})
    marks = pd.DataFrame("", index=frame.index, columns=frame.columns)
    marks.loc[1, "score"] = "<best>"
    cells = _cells(table_html(frame, "t", marks=marks))
    assert cells[3] == ('<td data-value="0.25" title="&lt;best&gt;" class="num mark">0.25'
                        '<span class="mk">&lt;best&gt;</span></td>')
    assert "mark" not in "".join(cells[:3])
    marks.loc[0, "method"] = np.nan  # NaN: no mark
    assert _cells(table_html(frame, "t", marks=marks))[0] == "<td>a</td>"
    with pytest.raises(ValueError, match="index and columns"):
        table_html(frame, "t", marks=marks.drop(columns="method"))


def test_a_named_index_becomes_the_first_columns_and_keeps_the_marks_aligned():
    frame = pd.DataFrame({"score": [1.0, 2.0]}, index=pd.Index(["planit", "real"], name="method"))
    marks = pd.DataFrame({"score": ["", "*"]}, index=frame.index)
    html = table_html(frame, "t", marks=marks)
    assert re.findall(r"<th scope[^>]*>(.*?)</th>", html) == ["method", "score"]
    assert _cells(html)[2:] == ["<td>real</td>",
                                '<td data-value="2.0" title="*" class="num mark">2<span class="mk">*</span></td>']
    assert "<th" in table_html(pd.DataFrame({"x": [1]}), "t") and ">0<" not in table_html(pd.DataFrame({"x": [1]}), "t")


def test_a_page_holds_several_tables_and_no_network_resource(tmp_path):
    one, two = pd.DataFrame({"a": [1]}), pd.DataFrame({"b": [2]})
    html = page("Comparison", [Table("First", one, "c1"), ("Second", two)], intro="about")
    assert html.count('<table class="sortable">') == 2 and "<h2>First</h2>" in html and "<h2>Second</h2>" in html
    assert html.count("<script>") == 1 and not re.search(r"(src|href)=|https?:|@import", html)
    out = write_table_html(tmp_path / "sub" / "t.html", one, "t")
    assert out.read_text(encoding="utf-8") == table_html(one, "t") and list(out.parent.iterdir()) == [out]


def test_a_header_click_sorts_numbers_by_value_text_as_text_and_empty_cells_last(tmp_path):
    """The page's own script in headless Chromium (no pipeline run)."""
    from webdriver import CHROMEDRIVER, CHROMIUM, Browser

    if not (CHROMIUM and CHROMEDRIVER):
        pytest.skip("Debian's chromium and chromium-driver are not installed")
    frame = pd.DataFrame({"name": ["b", "a10", "a9", "c"], "v": [10.0, np.nan, 9.5, 100.0],
                          "ci": ["2 [1, 3]", "10 [9, 11]", "", "-1 [-2, 0]"]})
    path = write_table_html(tmp_path / "t.html", frame, "t")
    column = "return Array.from(document.querySelectorAll('tbody tr')).map(r => r.cells[%d].textContent)"
    browser = Browser(tmp_path / "profile")
    try:
        browser.open(path.as_uri())
        heads = browser.elements("th")
        browser.click(heads[1])
        assert browser.run(column % 1) == ["9.5", "10", "100", ""]
        browser.click(heads[1])
        assert browser.run(column % 1) == ["100", "10", "9.5", ""]  # reversed; the empty cell stays last
        browser.click(heads[0])
        assert browser.run(column % 0) == ["a9", "a10", "b", "c"]
        browser.click(heads[2])
        assert browser.run(column % 2) == ["-1 [-2, 0]", "2 [1, 3]", "10 [9, 11]", ""]
    finally:
        browser.close()
