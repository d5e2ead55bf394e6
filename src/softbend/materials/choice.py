"""A material named the way a user names it: a preset, or a fit of their own tensile test.

``--material`` on the command line (``softbend fem run``, ``softbend campaign run
--backend fem``) takes either

* a preset name: ``dragon-skin-30`` (paper B's Yeoh constants; see
  :data:`~softbend.materials.presets.PRESETS`), or
* the ``fit.json`` written by ``softbend materials fit``, optionally with the
  model to use after a ``#``: ``mat/fit.json#yeoh``; without it, the file's
  best model (highest R²).

A fit carries no density: the elastomer's density is taken from Dragon Skin 30
(1.08 g/cm³; silicones of this kind lie within a few per cent of it) unless
given, and the material's ``source`` says which.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from softbend.errors import SchemaError
from softbend.materials.presets import (
    DRAGON_SKIN_30,
    G_PER_CM3_TO_T_PER_MM3,
    PRESETS,
    Material,
)
from softbend.registry import UnknownNameError

__all__ = ["material_from_spec", "material_spec_record"]


def material_from_spec(
    spec: str | os.PathLike[str],
    *,
    density_g_per_cm3: float | None = None,
) -> Material:
    """The material ``spec`` names: a preset, or a model of a ``materials fit`` file.

    An error about the name is keyed ``spec`` (a caller that hands its own
    parameter on names it with :func:`softbend.errors.keyed`); an error in the
    file names the file and the entry.

    Parameters
    ----------
    spec : str or path-like
        A preset name, or ``PATH`` / ``PATH#MODEL`` of a ``fit.json``.
    density_g_per_cm3 : float, optional
        Density of a fitted material, g/cm³ (default: Dragon Skin 30's, 1.08);
        ignored for a preset, which has its own.

    Returns
    -------
    Material
        Its ``source`` names the preset's source, or the file, the model and its R².

    Raises
    ------
    UnknownNameError
        ``spec`` is neither a file nor a preset (the message lists the presets).
    SchemaError
        The file is not a valid ``fit.json`` (as :func:`~softbend.materials.fit.load_fit_json`),
        names an unknown model after ``#``, or has no model with a finite R².
    """
    text = os.fspath(spec)
    path_text, _, model_name = text.partition("#")
    path = Path(path_text)
    if not path.is_file():
        try:
            return PRESETS.get(text)
        except UnknownNameError as error:
            raise UnknownNameError(
                f"{error.detail.rstrip('.')}; or a fit.json of 'softbend materials fit'",
                key="spec",
            ) from None
    from softbend.materials.fit import load_fit_json

    fits = load_fit_json(path)  # its errors name the file
    if model_name:
        if model_name not in fits:
            raise SchemaError(
                f"names model {model_name!r} of {path}, which holds {', '.join(fits)}",
                key="spec",
            )
        chosen = fits[model_name]
    else:
        ranked = [f for f in fits.values() if f.r2 == f.r2]
        if not ranked:
            raise SchemaError(f"the fits in {path} have no finite R² to pick one by", key="spec")
        chosen = max(ranked, key=lambda f: f.r2)
    if density_g_per_cm3 is None:
        density = DRAGON_SKIN_30.density_g_per_cm3
        density_note = f"density {density:g} g/cm³ assumed (Dragon Skin 30's)"
    else:
        density = float(density_g_per_cm3)
        density_note = f"density {density:g} g/cm³ given"
    return Material(
        name=f"{_tested_material(path) or path.stem} ({chosen.name})",
        model=chosen.model,
        density_t_per_mm3=density * G_PER_CM3_TO_T_PER_MM3,
        source=(
            f"{path}: {chosen.name} fit to uniaxial tension, R² {chosen.r2:.4f} over "
            f"stretch {chosen.stretch_range[0]:g}-{chosen.stretch_range[1]:g}; {density_note}."
        ),
    )


def material_spec_record(spec: str | os.PathLike[str]) -> dict[str, str]:
    """What ``spec`` names, to record beside the material it gives.

    Parameters
    ----------
    spec : str or path-like
        As :func:`material_from_spec`: a preset name, or ``PATH`` / ``PATH#MODEL``
        of a ``fit.json``.

    Returns
    -------
    dict
        ``{"spec": text}`` for a preset; for a file also ``"file"`` (its path),
        ``"model"`` (the model after ``#``, empty for the best fit) and ``"sha256"``
        (of the file's bytes), so that data made from one fit can be told from
        data made from a refit.
    """
    text = os.fspath(spec)
    path_text, _, model_name = text.partition("#")
    path = Path(path_text)
    if not path.is_file():
        return {"spec": text}
    return {
        "spec": text,
        "file": str(path),
        "model": model_name,
        "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
    }


def _tested_material(path: Path) -> str | None:
    """The material the tensile test of a ``fit.json`` names (its ``Material``), if any."""
    import json

    try:
        test = json.loads(path.read_text(encoding="utf-8")).get("test", {})
    except (OSError, ValueError, AttributeError):
        return None
    name = test.get("material") if isinstance(test, dict) else None
    return name.strip() if isinstance(name, str) and name.strip() else None
