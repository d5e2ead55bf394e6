import pandas as pd

from softbend.reports.html import Report, write_text_atomic


def test_report_renders_escaped_text_tables_and_relative_figures(tmp_path):
    (tmp_path / "figs").mkdir()
    fig = tmp_path / "figs" / "a.png"
    fig.write_bytes(b"\x89PNG")
    report = Report("Run <1>", subtitle="seed 0")
    section = report.section("Results")
    section.text("R² > 0.99 & fast")
    section.text("run `softbend train --grid paper` for <all>; a lone ` stays")
    section.table(["model", "rmse"], [["svr", 0.123456]])
    section.frame(pd.DataFrame({"a": [1.5], "b": ["x"]}))
    section.figure(fig, "a figure", root=tmp_path)
    path = report.write(tmp_path / "index.html")
    page = path.read_text()
    assert "Run &lt;1&gt;" in page
    assert "R² &gt; 0.99 &amp; fast" in page
    assert "run <code>softbend train --grid paper</code> for &lt;all&gt;; a lone ` stays" in page
    assert "<td>0.1235</td>" in page
    assert 'src="figs/a.png"' in page
    assert page.count("<table>") == 2


def test_atomic_write_leaves_no_temporary_files(tmp_path):
    target = tmp_path / "sub" / "out.txt"
    write_text_atomic(target, "one")
    write_text_atomic(target, "two")
    assert target.read_text() == "two"
    assert [p.name for p in target.parent.iterdir()] == ["out.txt"]


def test_contents_anchors_and_provenance():
    report = Report("Run")
    report.section("Paper A — curling")
    report.section("Paper B: Fig. 4")
    report.section("Paper B: Fig. 4")  # the same title twice gets its own anchor
    report.provenance = {"softbend": "0.1.0", "seed": 3, "model": "x=0.12345678901"}
    page = report.render()
    assert report.anchors() == ["paper-a-curling", "paper-b-fig-4", "paper-b-fig-4-2"]
    for anchor in report.anchors():
        assert f'href="#{anchor}"' in page and f'<section id="{anchor}">' in page
    assert page.index('<nav class="toc">') < page.index('<section id="paper-a-curling">')
    assert '<section id="provenance">' in page and "<dd>0.1.0</dd>" in page
    assert "<dd>x=0.123457</dd>" in page


def test_numbers_are_written_for_people():
    report = Report("Run")
    section = report.section("Materials")
    section.text("fitted NeoHookean(c10_mpa=0.23094937748277466), version 0.1.0, hash 12c9584f")
    section.table(["model", "n"], [["NeoHookean(c10_mpa=0.23094937748277466)", 3]])
    page = report.render()
    assert "0.23094937748277466" not in page
    assert page.count("NeoHookean(c10_mpa=0.230949)") == 2
    assert "version 0.1.0, hash 12c9584f" in page and "<td>3</td>" in page
