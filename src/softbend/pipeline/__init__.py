"""The sections of ``softbend reproduce``, computed: one module per section.

Each module runs what its section of the report shows (campaigns, training,
sweeps, studies), writes the data a user keeps (CSV, DuckDB, Parquet, models;
never figures) and returns a small frozen dataclass of results with the
section's headline ``summary``. :mod:`softbend.reports` draws those results and
writes the HTML.

- :mod:`~softbend.pipeline.paper_a`: synthetic curling actuator, NARX/GG-SVR
  identification.
- :mod:`~softbend.pipeline.paper_b`: the design-space campaign and the
  surrogates trained on it.
- :mod:`~softbend.pipeline.paper_b_fem`: the Dragon Skin 30 fit and the FEM
  sweep of the Fig. 2 design.
- :mod:`~softbend.pipeline.paper_b_fem_data`: Figs. 4 and 5 on the shipped FEM
  dataset.
- :mod:`~softbend.pipeline.transfer`: transfer learning on the shipped virtual lab.
- :mod:`~softbend.pipeline.control`: closed-loop control on the simulated rig.

Every function takes ``progress(phase, done, total)``, called as work is done.
"""

from __future__ import annotations

from collections.abc import Callable

#: progress(phase, done, total)
Progress = Callable[[str, int, int], None]

__all__ = ["Progress"]
