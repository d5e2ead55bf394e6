"""Export fitted surrogates to ONNX, and run an exported model with onnxruntime.

Every exported graph takes the input ``"x"`` of shape [N, 7] (columns
:data:`~softbend.surrogates.features.FEATURES`, in mm, deg and MPa) and returns
``"angle_deg"`` of shape [N] (degrees).

A family's export is its ``onnx`` (:class:`~softbend.surrogates.families.Family`);
paper B's three are in :mod:`softbend.surrogates.onnx_graphs`:

- ``plr`` and ``mlp``: built node by node in double precision (input and output
  ``tensor(double)``), so they reproduce ``predict`` to rounding;
- ``xgb``: converted by :func:`onnxmltools.convert_xgboost` to a
  ``TreeEnsembleRegressor`` with a float32 input (XGBoost evaluates its trees in
  float32 as well) and the output reshaped to [N] as ``"angle_deg"`` (float32).

Each model carries metadata properties ``features`` and ``units`` (JSON),
``kind`` (the family's name) and ``target``, and passes
:func:`onnx.checker.check_model`.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from softbend import __version__
from softbend._extras import require
from softbend._io import write_bytes_atomic
from softbend.errors import InputError
from softbend.surrogates.families import FAMILIES
from softbend.surrogates.features import FEATURES, TARGET, check_features
from softbend.surrogates.onnx_graphs import DEFAULT_OPSET, helper, onnx
from softbend.surrogates.persistence import COMPOSITE_KINDS, check_fitted_surrogate, model_units
from softbend.surrogates.protocol import Surrogate

if TYPE_CHECKING:
    from softbend.actuators import Actuator

__all__ = ["DEFAULT_OPSET", "onnx_predict", "save_onnx", "to_onnx"]


def to_onnx(
    model: Surrogate, *, opset: int | None = None, actuator: Actuator | None = None
) -> onnx.ModelProto:
    """Export a fitted surrogate as an ONNX model.

    Parameters
    ----------
    model : estimator
        A fitted surrogate of a family with an ONNX export (``PolynomialRegressor``,
        ``NormalizedMLPRegressor``, ``xgboost.XGBRegressor``) on the inputs of ``actuator``.
    opset : int, optional
        Opset of the ``ai.onnx`` domain. Default :data:`DEFAULT_OPSET` (17) for the
        polynomial and MLP (allowed 13 up to what the installed ``onnx`` knows);
        for XGBoost the highest that onnxmltools supports (allowed 13 up to that).
    actuator : Actuator, optional
        The actuator the model is of: its inputs and units are recorded in the
        model's properties (default paper B's, :data:`softbend.actuators.SFRBA`:
        the 7 inputs :data:`FEATURES` in mm, deg, MPa).

    Returns
    -------
    onnx.ModelProto
        Input ``"x"`` [N, d], d the actuator's inputs (double; float32 for XGBoost),
        output ``"angle_deg"`` [N] in degrees (double; float32 for XGBoost); checked
        by :func:`onnx.checker.check_model`.

    Raises
    ------
    ValueError
        Unknown model type, a composite surrogate or a family without an ONNX
        export, a model on other inputs than the actuator's, a bad ``opset``.
    sklearn.exceptions.NotFittedError
        If the model is not fitted.
    """
    if actuator is None:
        from softbend.actuators import SFRBA

        actuator = SFRBA
    kind = check_fitted_surrogate(model, actuator.features)
    export = None if kind in COMPOSITE_KINDS else FAMILIES.get(kind).onnx
    if export is None:
        exporting = [name for name, family in FAMILIES.items() if family.onnx is not None]
        hint = "; export its base instead" if kind in COMPOSITE_KINDS else ""
        raise InputError(
            f"must be a surrogate of a family with an ONNX export ({', '.join(exporting)}); "
            f"got a {kind} surrogate ({type(model).__name__}), which has no ONNX export{hint}",
            key="model",
        )
    proto = export(model, opset)
    proto.producer_name = "softbend"
    proto.producer_version = __version__
    inputs = ", ".join(actuator.features)
    proto.doc_string = f"softbend {kind} surrogate: {inputs} -> {TARGET} (deg)."
    props = {
        "features": json.dumps(list(actuator.features)),
        "units": json.dumps(model_units(actuator)),
        "kind": kind,
        "target": TARGET,
    }
    helper.set_model_props(proto, props)
    onnx.checker.check_model(proto, full_check=True)
    return proto


def _as_bytes(model: onnx.ModelProto | bytes | str | os.PathLike[str]) -> bytes:
    if isinstance(model, onnx.ModelProto):
        return model.SerializeToString()
    if isinstance(model, bytes | bytearray | memoryview):
        return bytes(model)
    if isinstance(model, str | os.PathLike):
        path = Path(model)
        if not path.is_file():
            raise FileNotFoundError(f"No ONNX model at {path}.")
        return path.read_bytes()
    raise InputError(
        f"must be an onnx.ModelProto, bytes or a path; got {type(model).__name__}", key="model"
    )


_NUMPY_OF_ONNX = {"tensor(double)": np.float64, "tensor(float)": np.float32}


def onnx_predict(
    model: onnx.ModelProto | bytes | str | os.PathLike[str], X: ArrayLike
) -> np.ndarray:
    """Predict bending angles with an exported surrogate through onnxruntime (CPU).

    A new inference session is built on every call; keep an
    :class:`onnxruntime.InferenceSession` yourself to evaluate many small batches.

    Parameters
    ----------
    model : onnx.ModelProto, bytes, str or Path
        A model from :func:`to_onnx`, its serialized bytes, or a ``.onnx`` file.
    X : array_like, shape (n, d) or (d,)
        Inputs, the columns the model's ``features`` property names (:data:`FEATURES`,
        mm, deg, MPa, when it names none), finite; cast to the model's input type
        (double, or float32 for XGBoost).

    Returns
    -------
    ndarray of float64, shape (n,)
        Bending angles, degrees.

    Raises
    ------
    ValueError
        ``X`` of the wrong shape or not finite, or a ``model`` of another type.
    """
    onnxruntime = require("onnxruntime", "ONNX prediction (onnx_predict)")
    session = onnxruntime.InferenceSession(_as_bytes(model), providers=["CPUExecutionProvider"])
    recorded = session.get_modelmeta().custom_metadata_map.get("features")
    X = check_features(X, FEATURES if recorded is None else tuple(json.loads(recorded)))
    (source,) = session.get_inputs()
    dtype = _NUMPY_OF_ONNX.get(source.type)
    if dtype is None:
        raise InputError(
            f"must take a double or float tensor; got an input of type {source.type}", key="model"
        )
    (result,) = session.run([session.get_outputs()[0].name], {source.name: X.astype(dtype)})
    return np.asarray(result, dtype=np.float64).reshape(X.shape[0])


def save_onnx(
    model: Surrogate,
    path: str | os.PathLike[str],
    *,
    opset: int | None = None,
    actuator: Actuator | None = None,
) -> Path:
    """Export a fitted surrogate with :func:`to_onnx` and write it to ``path`` atomically.

    Parameters
    ----------
    model : estimator
        A fitted polynomial, MLP or XGBoost surrogate on the inputs of ``actuator``.
    path : str or Path
        File to write (conventionally ``.onnx``); parent folders are created.
    opset, actuator : optional
        As in :func:`to_onnx`.

    Returns
    -------
    Path
        The written file.
    """
    proto = to_onnx(model, opset=opset, actuator=actuator)
    return write_bytes_atomic(path, proto.SerializeToString())
