"""What the output-folder tests share: a snapshot of a folder tree, and a PID no process has."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

__all__ = ["dead_pid", "tree"]


def tree(root: Path) -> dict[str, object]:
    """Every entry under ``root``: relative path → bytes, ``"dir"`` or ``("link", target)``."""
    found: dict[str, object] = {}
    for path in sorted(root.rglob("*")):
        key = path.relative_to(root).as_posix()
        if path.is_symlink():
            found[key] = ("link", os.readlink(path))
        else:
            found[key] = "dir" if path.is_dir() else path.read_bytes()
    return found


def dead_pid() -> int:
    """The PID of a process that has exited."""
    child = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        capture_output=True,
        text=True,
        check=True,
    )
    return int(child.stdout)
