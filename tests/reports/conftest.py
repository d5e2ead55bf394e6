"""Opening a report in headless Chromium (Debian's ``chromium``) through Playwright."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path
from typing import Any

import pytest

#: Flags for a headless browser on a machine without network or display.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


def chromium_path() -> str:
    """The browser, or skip (fail where SOFTBEND_REQUIRE_BROWSER is set, as in CI)."""
    path = os.environ.get("SOFTBEND_CHROMIUM") or shutil.which("chromium")
    if path is None:
        message = "no chromium on PATH (apt-get install chromium, or set SOFTBEND_CHROMIUM)"
        if os.environ.get("SOFTBEND_REQUIRE_BROWSER"):
            pytest.fail(message)
        pytest.skip(message)
    return path


def open_in_browser(page_path: Path, screenshot: Path | None = None) -> dict[str, Any]:
    """Load an HTML file as a user would and report what the browser saw.

    Returns
    -------
    dict
        ``images`` (src of every <img>), ``broken_images`` (those that did not
        load), ``console_errors`` (console messages of type error and page
        errors, failed requests included), ``section_ids``, ``toc_targets``
        (the #anchors the contents link to) and ``tables`` (count).
    """
    sync_api = pytest.importorskip("playwright.sync_api")
    executable = chromium_path()
    errors: list[str] = []
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 900})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("requestfailed", lambda r: errors.append(f"failed to load {r.url}"))
            page.goto(page_path.resolve().as_uri(), wait_until="load")
            seen = page.evaluate(
                """() => ({
                    images: Array.from(document.images, i => i.getAttribute('src')),
                    broken_images: Array.from(document.images)
                        .filter(i => !(i.complete && i.naturalWidth > 0))
                        .map(i => i.getAttribute('src')),
                    section_ids: Array.from(document.querySelectorAll('section[id]'), s => s.id),
                    toc_targets: Array.from(document.querySelectorAll('nav.toc a'),
                                            a => a.getAttribute('href').slice(1)),
                    tables: document.querySelectorAll('table').length,
                })"""
            )
            if screenshot is not None:
                page.screenshot(path=str(screenshot), full_page=False)
        finally:
            browser.close()
    return {**seen, "console_errors": errors}


def only_section(report: Any) -> tuple[str, str]:
    """The title and HTML of a report's one section (fails if it has another number)."""
    assert len(report.sections) == 1, [s.title for s in report.sections]
    section = report.sections[0]
    return section.title, section.render()


def figures_of(html: str) -> list[str]:
    """The ``src`` of every ``<img>`` in ``html``, in order."""
    return re.findall(r'<img src="([^"]+)"', html)
