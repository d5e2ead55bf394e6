import pandas as pd

from softbend.reports.html import Report, write_text_atomic


def test_report_renders_escaped_text_tables_and_relative_figures(tmp_path):
    (tmp_path / "figs").mkdir()
    fig = tmp_path / "figs" / "a.png"
    fig.write_bytes(b"\x89PNG")
    report = Report("Run <1>", subtitle="seed 0")
    section = report.section("Results")
    section.text("R² > 0.99 & fast")
    section.table(["model", "rmse"], [["svr", 0.123456]])
    section.frame(pd.DataFrame({"a": [1.5], "b": ["x"]}))
    section.figure(fig, "a figure", root=tmp_path)
    path = report.write(tmp_path / "index.html")
    page = path.read_text()
    assert "Run &lt;1&gt;" in page
    assert "R² &gt; 0.99 &amp; fast" in page
    assert "<td>0.1235</td>" in page
    assert 'src="figs/a.png"' in page
    assert page.count("<table>") == 2


def test_atomic_write_leaves_no_temporary_files(tmp_path):
    target = tmp_path / "sub" / "out.txt"
    write_text_atomic(target, "one")
    write_text_atomic(target, "two")
    assert target.read_text() == "two"
    assert [p.name for p in target.parent.iterdir()] == ["out.txt"]
