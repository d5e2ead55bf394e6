"""softbend: design, simulate, learn and control soft pneumatic bending actuators.

The package is organised along the pipeline::

    kinematics -> materials -> design -> analytical / fem -> campaign -> analysis
    -> surrogates -> identification -> transfer -> control -> reports

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
