"""Design campaigns: sweep many actuator designs and keep the results (paper B §3.3).

A campaign sweeps the designs of one actuator (its description, and the FEM family or
other backend that computes it) over pressures; paper B's Table 1 campaign over its
fiber-reinforced actuator is one example, a PneuNet space (``--family pneunet``) another.

* :mod:`~softbend.campaign.backends` — what computes one sweep (analytical model,
  FEM, a saved surrogate) behind one protocol and a registry (:data:`BACKENDS`);
* :mod:`~softbend.campaign.schema` — the tables of a campaign database, their
  version and the checks of an existing file;
* :mod:`~softbend.campaign.store` — the DuckDB database, one transaction per design;
* :mod:`~softbend.campaign.settings` — the backend's settings a database records
  (mesh, FEM options, material) and checks on resume;
* :mod:`~softbend.campaign.spaces` — the design spaces of every FEM actuator
  family named by text (paper B's Table 1 among them);
* :mod:`~softbend.campaign.footprint` — shards, and the memory and disk a
  campaign needs;
* :mod:`~softbend.campaign.family_schema` — campaigns over any FEM actuator family
  (``--family``): its FEM sweep as a backend and what its database records;
* :mod:`~softbend.campaign.runner` — :func:`run_campaign`: plans a run
  (:mod:`~softbend.campaign.planning`: resume, the designs left, the executor) and
  runs it (:mod:`~softbend.campaign.executors`: serial, local processes or a Dask
  cluster, failure recording, progress).

Example::

    from softbend.campaign import run_campaign
    from softbend.design import DesignSpace

    summary = run_campaign("table1.duckdb", DesignSpace.table1(), backend="analytical")

DuckDB and Dask are imported only when a database is opened or a cluster used;
names are imported on first use.
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

_EXPORTS = {
    "BACKENDS": "backends",
    "INTERNAL_BACKENDS": "backends",
    "SweepResult": "backends",
    "available_backends": "backends",
    "backend_for_run": "backends",
    "default_pressures_mpa": "backends",
    "get_backend": "backends",
    "public_backends": "backends",
    "register_backend": "backends",
    "CampaignSummary": "runner",
    "count_designs_to_run": "runner",
    "parse_scheduler_address": "runner",
    "run_campaign": "runner",
    "FamilyBackend": "family_schema",
    "campaign_actuator": "store",
    "family_backend": "family_schema",
    "FamilySpace": "spaces",
    "parse_family_space": "spaces",
    "SPACE_FORMS": "spaces",
    "SpaceSpec": "spaces",
    "campaign_space": "spaces",
    "campaign_footprint": "footprint",
    "check_footprint": "footprint",
    "parse_shard": "footprint",
    "parse_space": "spaces",
    "SettingsMismatchError": "settings",
    "UncheckedSettingsWarning": "settings",
    "backend_settings": "settings",
    "SCHEMA_VERSION": "store",
    "CampaignStore": "store",
    "load_designs": "store",
    "load_samples": "store",
    "merge_campaigns": "store",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
