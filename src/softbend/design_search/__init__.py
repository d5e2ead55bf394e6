"""Design to a specification: search the design space on a surrogate, verify with the FEM.

:class:`Specification` says what the actuator must do (bend θ* at p*, reach θ*
below a pressure, bend as far as possible, follow a curve), the parameters'
ranges and the mould's step, and what to minimise; :func:`find_designs` scores
every design of the grid on a saved surrogate and ranks those that meet it;
:func:`verify_candidates` sweeps the best with the FEM (the campaign machinery)
and sets the FEM's angle beside the surrogate's.

The parameters are those of the model's actuator
(:class:`~softbend.design_search.space.SearchSpace`): paper B's six by their
short names, or another description's own (``Specification(...,
actuator=saved.actuator)``). Every actuator is verified by the FEM family its
description names (``fem_family``: paper B's ``sfrba``, the PneuNet's
``pneunet``); a sweep that stops before the pressure checked (walls touching)
is reported with the FEM's stop reason, not as an angle.

The specification's data classes are :mod:`.spec`'s, its reading from
command-line text :mod:`.spec_text`'s and from a TOML file :mod:`.spec_toml`'s;
the grid a search scores is :mod:`.grid`'s and its answer :mod:`.result`'s.
"""

from __future__ import annotations

from typing import Any

from softbend._lazy import export as _export

#: Public name -> the module that defines it.
_EXPORTS: dict[str, str] = {
    "Candidate": "result",
    "SearchResult": "result",
    "find_designs": "search",
    "Objective": "spec",
    "ParameterRange": "spec",
    "SearchSpace": "space",
    "Specification": "spec",
    "Target": "spec",
    "load_specifications": "spec_toml",
    "space_of": "space",
    "verify_candidates": "verify",
    "verify_family": "verify",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str) -> Any:
    return _export(__name__, _EXPORTS, name)


def __dir__() -> list[str]:
    return list(__all__)
