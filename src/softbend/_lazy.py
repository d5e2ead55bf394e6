"""Lazy package exports: a package names its public objects, their modules load on first use.

A subpackage's ``__init__`` maps each exported name to the module defining it
and delegates its module-level ``__getattr__`` here, so ``import softbend.x``
stays light (no SciPy, PyTorch or NGSolve until a name that needs them is used)::

    from softbend._lazy import export as _export  # private: a submodule may be "export"

    _EXPORTS = {"run_campaign": "runner", "CampaignStore": "store"}
    __all__ = sorted(_EXPORTS)

    def __getattr__(name: str) -> Any:
        return _export(__name__, _EXPORTS, name)
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import Any

__all__ = ["export"]


def export(package: str, exports: Mapping[str, str], name: str) -> Any:
    """The object ``name`` exported by ``package``, imported from its module.

    Parameters
    ----------
    package : str
        The package's ``__name__`` (``"softbend.campaign"``).
    exports : mapping of str to str
        Exported name → module: a submodule's name relative to ``package``
        (``"runner"``) or a full module path (``"softbend.analysis.ols"``).
    name : str
        The attribute asked for.

    Raises
    ------
    AttributeError
        For a name ``package`` does not export (as for any missing attribute).
    """
    module = exports.get(name)
    if module is None:
        raise AttributeError(f"module {package!r} has no attribute {name!r}")
    path = module if module.startswith("softbend.") else f"{package}.{module}"
    return getattr(importlib.import_module(path), name)
