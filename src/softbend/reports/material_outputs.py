"""The files of ``softbend materials fit``: the fitted curves' figure and ``fit.json``."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from softbend.materials.fit import FitResult
    from softbend.materials.tensile import TensileTest

__all__ = ["FIT_JSON", "FIT_PNG", "write_fit"]

#: The figure of the data and the fitted curves.
FIT_PNG = "fit.png"
#: The fits, their test and the best model (:func:`softbend.materials.fit.fit_file_payload`).
FIT_JSON = "fit.json"


def write_fit(
    test: TensileTest,
    results: Mapping[str, FitResult],
    max_stretch: float | None,
    folder: Path,
) -> dict[str, Any]:
    """Write :data:`FIT_PNG` and :data:`FIT_JSON` of fits of one test into ``folder``.

    Both files are written through temporary files beside them and replaced together:
    both new, or both as they were.

    Parameters
    ----------
    test : TensileTest
        The tensile test fitted.
    results : mapping of str to FitResult
        The fits, by model name (:func:`softbend.materials.fit.fit_models`).
    max_stretch : float, optional
        The largest stretch fitted, as given (None: all points).
    folder : Path
        The folder written into; it must exist or be creatable.

    Returns
    -------
    dict
        The content of ``fit.json``, with ``files`` naming both files.
    """
    from softbend._io import atomic_files, json_text
    from softbend.materials.fit import fit_file_payload
    from softbend.reports.material_figures import fit_figure

    figure = folder / FIT_PNG
    payload = fit_file_payload(test, results, max_stretch)
    payload["files"] = {"figure": str(figure), "json": str(folder / FIT_JSON)}
    with atomic_files(figure, folder / FIT_JSON) as (png, summary):
        fit_figure(test, results, png)
        summary.write_text(json_text(payload) + "\n", encoding="utf-8")
    return payload
