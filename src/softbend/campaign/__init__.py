"""Design campaigns: sweep many actuator designs and keep the results (SPEC §4.4).

* :mod:`~softbend.campaign.backends` — what computes one sweep (analytical model,
  FEM) behind one protocol and a registry;
* :mod:`~softbend.campaign.store` — the DuckDB database, one transaction per design;
* :mod:`~softbend.campaign.runner` — local processes or a Dask cluster, resume,
  failure recording, progress.

Example::

    from softbend.campaign import run_campaign
    from softbend.design import DesignSpace

    summary = run_campaign("table1.duckdb", DesignSpace.table1(), backend="analytical")

DuckDB and Dask are imported only when a database is opened or a cluster used.
"""

from softbend.campaign.backends import (
    SweepResult,
    available_backends,
    default_pressures_mpa,
    get_backend,
    register_backend,
)
from softbend.campaign.runner import CampaignSummary, run_campaign
from softbend.campaign.store import SCHEMA_VERSION, CampaignStore, load_samples

__all__ = [
    "SCHEMA_VERSION",
    "CampaignStore",
    "CampaignSummary",
    "SweepResult",
    "available_backends",
    "default_pressures_mpa",
    "get_backend",
    "load_samples",
    "register_backend",
    "run_campaign",
]
