"""What ``--plant`` names, parsed once: a registered plant, or a file of one of three kinds.

A control run's plant is given as text: a name of
:data:`~softbend.control.plants.PLANTS` (``surrogate``, ``fem``, ``lab``), or the
path of a saved surrogate (``.json``), of a model of ``softbend identify``
(``.json``: its dynamics play the actuator) or of measurements (``.csv``: their
loading readings, smoothed). :func:`softbend.control.plants.parse_plant` decides
which, once, into a :class:`PlantChoice`; the rest of the control package reads its ``kind`` instead
of looking at the text again.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Literal

from softbend.errors import keyed

if TYPE_CHECKING:
    from softbend.control.identified_plant import IdentifiedPlant

__all__ = ["PlantChoice", "PlantKind"]

#: ``named``: a registered plant; ``surrogate``: a saved surrogate ``.json``;
#: ``identified``: a model of ``softbend identify`` (``.json``); ``measurements``: a ``.csv``.
PlantKind = Literal["named", "surrogate", "identified", "measurements"]


@dataclass(frozen=True)
class PlantChoice:
    """The plant of a control run, as :func:`~softbend.control.plants.parse_plant` read it.

    Attributes
    ----------
    kind : {"named", "surrogate", "identified", "measurements"}
        What the text names (:data:`PlantKind`).
    text : str
        The text as given (the name, or the file's path); what a run's summary records.
    path : Path or None
        The file, for every kind but ``named``.
    """

    kind: PlantKind
    text: str
    path: Path | None = None

    def __str__(self) -> str:
        return self.text

    @property
    def model_file(self) -> Path | None:
        """The file of a saved model that plays the plant (a surrogate or an identified
        model), else None."""
        return self.path if self.kind in ("surrogate", "identified") else None

    @property
    def surrogate_file(self) -> Path | None:
        """The file of a saved surrogate that plays the plant, else None."""
        return self.path if self.kind == "surrogate" else None

    def identified(self) -> IdentifiedPlant | None:
        """The identified model, loaded and checked to play the actuator (once), else None."""
        return self._identified if self.kind == "identified" else None

    @cached_property
    def _identified(self) -> IdentifiedPlant:
        from softbend.control.identified_plant import identified_plant

        with keyed("plant"):
            return identified_plant(self.text)

    def pressure_unit(self) -> str | None:
        """The pressure unit of a plant that is a saved model (its description's, or its
        pressure input's), else None."""
        if self.kind == "identified":
            plant = self.identified()
            return None if plant is None else plant.input_unit
        if self.kind == "surrogate":
            from softbend.surrogates.persistence import load_surrogate

            with keyed("plant"):
                return str(load_surrogate(self.text).actuator.pressure_unit)
        return None
