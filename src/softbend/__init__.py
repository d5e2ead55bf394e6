"""softbend: design, simulate, learn and control soft pneumatic bending actuators.

The package is organised along the pipeline::

    kinematics -> materials -> design -> analytical / fem -> campaign -> analysis
    -> surrogates -> identification -> transfer -> control -> reports

Every stage takes the actuator it works on as an argument: a description
(:class:`softbend.actuators.Actuator`) of its named design parameters with their
units, ranges and resolutions, the constraints between them and the pressure and
angle columns, optionally with an FEM family that simulates it
(:mod:`softbend.fem.families`). Paper B's fiber-reinforced bending actuator
(``"sfrba"``: l, r, t, b, φ, lc in mm and degrees, pressure in MPa) is one
registered description, the PneuNet (``"pneunet"``) another, and a lab's own
actuator is a third, registered in Python or read off its simulation table.

``import softbend`` is light: heavy dependencies are imported only by the
modules that need them.
"""

from importlib.metadata import PackageNotFoundError, version

from softbend.errors import (
    ConvergenceError,
    DatasetError,
    SchemaError,
    SoftbendError,
)

try:
    __version__ = version("softbend")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0"

__all__ = [
    "ConvergenceError",
    "DatasetError",
    "SchemaError",
    "SoftbendError",
    "__version__",
]
