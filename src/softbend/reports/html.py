"""A small HTML report: sections of text, tables and figures in one page.

The page opens with a table of contents (every section has an anchor) and ends
with the run's provenance. Numbers are written for people: floats in tables to
four significant digits, and long decimals inside text or object reprs (such as
``NeoHookean(c10_mpa=0.23094937748277466)``) to six. The page references its
figures by relative path, so the output folder can be moved or zipped as a
whole. Writing is atomic (temporary file, then rename).
"""

from __future__ import annotations

import html
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from softbend._io import write_text_atomic

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["Link", "Report", "Section", "human_numbers", "slug", "write_text_atomic"]

_CSS = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em;
       color: #222; line-height: 1.45; }
h1 { border-bottom: 2px solid #444; padding-bottom: .2em; }
h2 { margin-top: 2em; border-bottom: 1px solid #bbb; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: .25em .6em; text-align: right; }
th { background: #f0f0f0; }
td:first-child, th:first-child { text-align: left; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
.note { background: #fff8e0; border-left: 4px solid #e0b000; padding: .5em 1em; }
.meta { color: #666; font-size: 0.85em; }
nav.toc { background: #f7f7f7; border: 1px solid #ddd; padding: .5em 1.5em; }
nav.toc ol { margin: .3em 0; }
dl.provenance { display: grid; grid-template-columns: max-content auto; gap: .2em 1em; }
dl.provenance dt { color: #555; }
dl.provenance dd { margin: 0; font-family: ui-monospace, monospace; font-size: 0.9em; }
"""

#: A decimal with more digits than a person reads (7 or more after the point).
_LONG_DECIMAL = re.compile(r"(?<![\w.])-?\d+\.\d{7,}(?:[eE][-+]?\d+)?(?![\w.])")

#: Inline code in a paragraph: a command or a name between backticks, as in Markdown.
_INLINE_CODE = re.compile(r"`([^`]+)`")


def human_numbers(text: str) -> str:
    """Rewrite long decimals in ``text`` with six significant digits.

    ``"NeoHookean(c10_mpa=0.23094937748277466)"`` becomes
    ``"NeoHookean(c10_mpa=0.230949)"``; short numbers, integers, versions and
    hashes are left alone.
    """
    return _LONG_DECIMAL.sub(lambda m: f"{float(m.group(0)):.6g}", text)


def slug(title: str) -> str:
    """An anchor for a section title: lower case, words joined by hyphens."""
    words = re.findall(r"[0-9a-z]+", title.lower())
    return "-".join(words) or "section"


@dataclass(frozen=True)
class Link:
    """A table cell that links to an anchor or a file of the report."""

    text: str
    href: str


def _format_cell(value: object) -> str:
    if isinstance(value, Link):
        return f'<a href="{html.escape(value.href)}">{html.escape(value.text)}</a>'
    if isinstance(value, bool):
        return html.escape(str(value))
    if isinstance(value, float):
        return f"{value:.4g}"
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:  # NumPy scalars
        return _format_cell(value.item())
    return html.escape(human_numbers(str(value)))


@dataclass
class Section:
    """One ``<h2>`` section of a report."""

    title: str
    parts: list[str] = field(default_factory=list)

    def text(self, paragraph: str, *, note: bool = False) -> Section:
        """Add a paragraph (escaped; `backticks` mark code). ``note=True`` draws it as a box."""
        css = ' class="note"' if note else ""
        body = _INLINE_CODE.sub(r"<code>\1</code>", html.escape(human_numbers(paragraph)))
        self.parts.append(f"<p{css}>{body}</p>")
        return self

    def table(self, columns: list[str], rows: list[list[Any]], *, caption: str = "") -> Section:
        """Add a table; floats are shown with four significant digits."""
        head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
        body = "".join(
            "<tr>" + "".join(f"<td>{_format_cell(v)}</td>" for v in row) + "</tr>" for row in rows
        )
        cap = f"<caption>{html.escape(human_numbers(caption))}</caption>" if caption else ""
        self.parts.append(
            f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
        )
        return self

    def frame(self, df: pd.DataFrame, *, caption: str = "", index: bool = False) -> Section:
        """Add a pandas DataFrame as a table."""
        frame = df.reset_index() if index else df
        return self.table(
            [str(c) for c in frame.columns], frame.to_numpy().tolist(), caption=caption
        )

    def figure(self, path: str | os.PathLike[str], caption: str, *, root: Path) -> Section:
        """Add a figure; ``path`` is stored relative to the report folder ``root``."""
        rel = os.path.relpath(Path(path), root)
        self.parts.append(
            f'<figure><img src="{html.escape(Path(rel).as_posix())}" alt="{html.escape(caption)}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>"
        )
        return self

    def render(self, anchor: str = "") -> str:
        """The section as HTML, with ``id=anchor`` when given."""
        ident = f' id="{html.escape(anchor)}"' if anchor else ""
        title = html.escape(self.title)
        return f"<section{ident}><h2>{title}</h2>{''.join(self.parts)}</section>"


@dataclass
class Report:
    """An HTML report made of sections, with a table of contents and provenance.

    Attributes
    ----------
    title, subtitle : str
        Heading of the page and a line under it.
    sections : list of Section
        In order of appearance.
    provenance : dict
        ``{label: value}`` shown at the end of the page (version, command, seed,
        machine, times); set it before :meth:`write`.
    """

    title: str
    subtitle: str = ""
    sections: list[Section] = field(default_factory=list)
    provenance: dict[str, Any] = field(default_factory=dict)

    def section(self, title: str) -> Section:
        """Append and return a new section."""
        section = Section(title)
        self.sections.append(section)
        return section

    def anchors(self) -> list[str]:
        """One unique anchor per section, from its title."""
        seen: dict[str, int] = {}
        out = []
        for section in self.sections:
            base = slug(section.title)
            seen[base] = seen.get(base, 0) + 1
            out.append(base if seen[base] == 1 else f"{base}-{seen[base]}")
        return out

    def render(self) -> str:
        """The whole page as HTML."""
        sub = f'<p class="meta">{html.escape(self.subtitle)}</p>' if self.subtitle else ""
        anchors = self.anchors()
        toc = ""
        if self.sections:
            items = "".join(
                f'<li><a href="#{a}">{html.escape(s.title)}</a></li>'
                for s, a in zip(self.sections, anchors, strict=True)
            )
            toc = f'<nav class="toc"><strong>Contents</strong><ol>{items}</ol></nav>'
        body = "".join(s.render(a) for s, a in zip(self.sections, anchors, strict=True))
        footer = ""
        if self.provenance:
            rows = "".join(
                f"<dt>{html.escape(str(k))}</dt><dd>{html.escape(human_numbers(str(v)))}</dd>"
                for k, v in self.provenance.items()
            )
            footer = (
                '<section id="provenance"><h2>Provenance of this report</h2>'
                f'<dl class="provenance">{rows}</dl></section>'
            )
        return (
            "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head>"
            f"<body><h1>{html.escape(self.title)}</h1>{sub}{toc}{body}{footer}</body></html>\n"
        )

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the page atomically and return its path."""
        return write_text_atomic(Path(path), self.render())
