"""Write docs/cli-reference.md from the commands' own --help (run by `make docs`)."""

from __future__ import annotations

from pathlib import Path

from softbend._io import write_text_atomic
from softbend.cli.reference import reference_markdown

if __name__ == "__main__":
    target = Path(__file__).resolve().parent / "cli-reference.md"
    write_text_atomic(target, reference_markdown())
    print(f"wrote {target}")
