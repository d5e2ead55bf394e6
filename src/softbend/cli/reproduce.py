"""``softbend reproduce``: the main job, the papers' pipelines end to end."""

from __future__ import annotations


def reproduce() -> None:
    """Run the whole pipeline on built-in defaults and write an HTML report."""
    raise NotImplementedError
