"""A small HTML report: sections of text, tables and figures in one page.

The page references its figures by relative path, so the output folder can be
moved or zipped as a whole. Writing is atomic (temporary file, then rename).
"""

from __future__ import annotations

import html
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from softbend._io import write_text_atomic

__all__ = ["Report", "Section", "write_text_atomic"]

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
"""


def _format_cell(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return html.escape(str(value))


@dataclass
class Section:
    """One ``<h2>`` section of a report."""

    title: str
    parts: list[str] = field(default_factory=list)

    def text(self, paragraph: str, *, note: bool = False) -> Section:
        """Add a paragraph (escaped). ``note=True`` draws it as a highlighted box."""
        css = ' class="note"' if note else ""
        self.parts.append(f"<p{css}>{html.escape(paragraph)}</p>")
        return self

    def table(self, columns: list[str], rows: list[list[Any]], *, caption: str = "") -> Section:
        """Add a table; floats are shown with four significant digits."""
        head = "".join(f"<th>{html.escape(c)}</th>" for c in columns)
        body = "".join(
            "<tr>" + "".join(f"<td>{_format_cell(v)}</td>" for v in row) + "</tr>" for row in rows
        )
        cap = f"<caption>{html.escape(caption)}</caption>" if caption else ""
        self.parts.append(
            f"<table>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
        )
        return self

    def frame(self, df: Any, *, caption: str = "", index: bool = False) -> Section:
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

    def render(self) -> str:
        """The section as HTML."""
        return f"<section><h2>{html.escape(self.title)}</h2>{''.join(self.parts)}</section>"


@dataclass
class Report:
    """An HTML report made of sections."""

    title: str
    subtitle: str = ""
    sections: list[Section] = field(default_factory=list)

    def section(self, title: str) -> Section:
        """Append and return a new section."""
        section = Section(title)
        self.sections.append(section)
        return section

    def render(self) -> str:
        """The whole page as HTML."""
        sub = f'<p class="meta">{html.escape(self.subtitle)}</p>' if self.subtitle else ""
        body = "".join(s.render() for s in self.sections)
        return (
            "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head>"
            f"<body><h1>{html.escape(self.title)}</h1>{sub}{body}</body></html>\n"
        )

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the page atomically and return its path."""
        return write_text_atomic(Path(path), self.render())
