"""Design campaigns: sweep many actuator designs and keep the results (SPEC §4.4).

* :mod:`~softbend.campaign.backends` — what computes one sweep (analytical model,
  FEM) behind one protocol and a registry;
* :mod:`~softbend.campaign.schema` — the tables of a campaign database, their
  version and the checks of an existing file;
* :mod:`~softbend.campaign.store` — the DuckDB database, one transaction per design;
* :mod:`~softbend.campaign.runner` — :func:`run_campaign`: plans a run
  (:mod:`~softbend.campaign.planning`: resume, the designs left, the executor) and
  runs it (:mod:`~softbend.campaign.executors`: serial, local processes or a Dask
  cluster, failure recording, progress).

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
