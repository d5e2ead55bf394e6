"""Write docs/validation.md from a run's summary.json (run by `make docs` after `make run`).

Usage: python docs/gen_validation.py [SUMMARY_JSON]   (default results/reproduce/summary.json)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from softbend._io import write_text_atomic
from softbend.reports.summary_section import validation_markdown

if __name__ == "__main__":
    root = Path(__file__).resolve().parents[1]
    source = Path(sys.argv[1]) if len(sys.argv) > 1 else root / "results/reproduce/summary.json"
    if not source.is_file():
        sys.exit(f"{source} is missing: `make run` writes it.")
    target = root / "docs" / "validation.md"
    write_text_atomic(target, validation_markdown(json.loads(source.read_text(encoding="utf-8"))))
    print(f"wrote {target} from {source}")
