"""``softbend analyze``: preliminary analysis of a campaign (paper B Fig. 4)."""

from __future__ import annotations


def analyze() -> None:
    """Correlations and standardized regression of a campaign database."""
    raise NotImplementedError
