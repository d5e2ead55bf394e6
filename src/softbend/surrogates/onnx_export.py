"""Export fitted surrogates to ONNX, and run an exported model with onnxruntime.

Every exported graph takes the input ``"x"`` of shape [N, 7] (columns
:data:`~softbend.surrogates.features.FEATURES`, in mm, deg and MPa) and returns
``"angle_deg"`` of shape [N] (degrees).

- **polynomial** and **mlp**: built node by node in double precision (input and
  output ``tensor(double)``), so they reproduce ``predict`` to rounding. The
  polynomial raises the standardized inputs z[:, None, :] to the exponent table
  ``powers_`` (a [1, T, 7] double constant; ONNX's ``Pow`` gives 0⁰ = 1), takes
  the product over the features (``ReduceProd``), contracts with ``coef_``
  (``MatMul``) and rescales. Its peak memory is N·T·7 doubles (degree 4: 18 kB
  per sample), so evaluate very large batches in chunks. The MLP is
  MatMul/Add/Tanh, twice, then a linear output.
- **xgboost**: converted by :func:`onnxmltools.convert_xgboost` to a
  ``TreeEnsembleRegressor`` with a float32 input (XGBoost evaluates its trees in
  float32 as well) and the output reshaped to [N] as ``"angle_deg"`` (float32).

Each model carries metadata properties ``features`` and ``units`` (JSON),
``kind`` and ``target``, and passes :func:`onnx.checker.check_model`.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from softbend import __version__
from softbend._extras import require
from softbend._io import write_bytes_atomic
from softbend.surrogates.features import FEATURES, TARGET, UNITS, check_features
from softbend.surrogates.persistence import COMPOSITE_KINDS, check_fitted_surrogate

onnx = require("onnx", "ONNX export (softbend.surrogates.onnx_export)")
TensorProto, helper, numpy_helper = onnx.TensorProto, onnx.helper, onnx.numpy_helper

__all__ = ["DEFAULT_OPSET", "onnx_predict", "save_onnx", "to_onnx"]

#: Default opset of the ``ai.onnx`` domain for the polynomial and MLP graphs.
DEFAULT_OPSET = 17

#: Lowest opset the graphs are written for.
_MIN_OPSET = 13

_INPUT = "x"
_OUTPUT = TARGET


def _check_opset(opset: Any, highest: int, owner: str) -> int:
    if opset is None:
        return min(DEFAULT_OPSET, highest)
    if isinstance(opset, bool) or not isinstance(opset, int) or not _MIN_OPSET <= opset <= highest:
        raise ValueError(
            f"The 'opset' of {owner} must be None or an integer in [{_MIN_OPSET}, {highest}]. "
            f"Got {opset!r} instead."
        )
    return opset


def _const(name: str, value: ArrayLike, dtype: type = np.float64) -> onnx.TensorProto:
    return numpy_helper.from_array(np.ascontiguousarray(value, dtype=dtype), name)


def _standardize(model: Any) -> tuple[list[onnx.NodeProto], list[onnx.TensorProto]]:
    """Nodes computing z = (x − x_mean_)/x_scale_ into ``"z"``."""
    nodes = [
        helper.make_node("Sub", [_INPUT, "x_mean"], ["x_centred"]),
        helper.make_node("Div", ["x_centred", "x_scale"], ["z"]),
    ]
    return nodes, [_const("x_mean", model.x_mean_), _const("x_scale", model.x_scale_)]


def _rescale(model: Any, source: str) -> tuple[list[onnx.NodeProto], list[onnx.TensorProto]]:
    """Nodes computing angle_deg = y_mean_ + y_scale_ · source."""
    nodes = [
        helper.make_node("Mul", [source, "y_scale"], ["y_scaled"]),
        helper.make_node("Add", ["y_scaled", "y_mean"], [_OUTPUT]),
    ]
    return nodes, [_const("y_scale", model.y_scale_), _const("y_mean", model.y_mean_)]


def _polynomial_body(model: Any, opset: int) -> tuple[list, list]:
    powers = np.asarray(model.powers_, dtype=np.float64)
    nodes = [
        helper.make_node("Unsqueeze", ["z", "axis_1"], ["z_rows"]),  # [N, 1, d]
        helper.make_node("Pow", ["z_rows", "powers"], ["factors"]),  # [N, T, d]
    ]
    if opset >= 18:
        nodes.append(
            helper.make_node("ReduceProd", ["factors", "axis_last"], ["terms"], keepdims=0)
        )
    else:
        nodes.append(helper.make_node("ReduceProd", ["factors"], ["terms"], axes=[-1], keepdims=0))
    nodes.append(helper.make_node("MatMul", ["terms", "coef"], ["y_std"]))  # [N]
    constants = [
        _const("axis_1", [1], np.int64),
        _const("powers", powers[None, :, :]),
        _const("coef", model.coef_),
    ]
    if opset >= 18:
        constants.append(_const("axis_last", [-1], np.int64))
    return nodes, constants


def _mlp_body(model: Any) -> tuple[list, list]:
    coefs = [np.asarray(w, dtype=np.float64) for w in model.coefs_]
    intercepts = [np.asarray(b, dtype=np.float64).ravel() for b in model.intercepts_]
    nodes, constants, source = [], [], "z"
    for layer, (weight, bias) in enumerate(zip(coefs[:-1], intercepts[:-1], strict=True)):
        nodes += [
            helper.make_node("MatMul", [source, f"W{layer}"], [f"h{layer}_lin"]),
            helper.make_node("Add", [f"h{layer}_lin", f"b{layer}"], [f"h{layer}_pre"]),
            helper.make_node("Tanh", [f"h{layer}_pre"], [f"h{layer}"]),
        ]
        constants += [_const(f"W{layer}", weight), _const(f"b{layer}", bias)]
        source = f"h{layer}"
    # Linear output: a [h, 1] weight as a vector gives [N] directly.
    nodes += [
        helper.make_node("MatMul", [source, "W_out"], ["out_lin"]),
        helper.make_node("Add", ["out_lin", "b_out"], ["y_std"]),
    ]
    constants += [_const("W_out", coefs[-1][:, 0]), _const("b_out", intercepts[-1][:1])]
    return nodes, constants


def _double_graph(model: Any, kind: str, opset: int) -> onnx.ModelProto:
    d = int(model.n_features_in_)
    first, first_consts = _standardize(model)
    if kind == "polynomial":
        body, body_consts = _polynomial_body(model, opset)
    else:
        body, body_consts = _mlp_body(model)
    last, last_consts = _rescale(model, "y_std")
    graph = helper.make_graph(
        first + body + last,
        f"softbend_{kind}",
        [helper.make_tensor_value_info(_INPUT, TensorProto.DOUBLE, ["N", d])],
        [helper.make_tensor_value_info(_OUTPUT, TensorProto.DOUBLE, ["N"])],
        initializer=first_consts + body_consts + last_consts,
    )
    opsets = [helper.make_opsetid("", opset)]
    return helper.make_model(
        graph, opset_imports=opsets, ir_version=helper.find_min_ir_version_for(opsets)
    )


def _xgboost_graph(model: Any, opset: int | None) -> onnx.ModelProto:
    convert_xgboost = require("onnxmltools", "ONNX export of XGBoost").convert_xgboost
    from onnxmltools.convert.common._topology import get_maximum_opset_supported
    from onnxmltools.convert.common.data_types import FloatTensorType

    opset = _check_opset(opset, get_maximum_opset_supported(), "to_onnx (xgboost)")
    if model.get_booster().feature_names is not None:
        # Fitted on a DataFrame: onnxmltools only reads the default names f0, f1, ...
        booster = model.get_booster().copy()
        booster.feature_names = None
        model = copy.copy(model)
        model._Booster = booster
    proto = convert_xgboost(
        model,
        name="softbend_xgboost",
        initial_types=[(_INPUT, FloatTensorType([None, int(model.n_features_in_)]))],
        target_opset=opset,
    )
    graph = proto.graph
    (output,) = graph.output
    source = output.name
    graph.initializer.append(_const("flat_shape", [-1], np.int64))
    graph.node.append(helper.make_node("Reshape", [source, "flat_shape"], [_OUTPUT]))
    graph.output.remove(output)
    graph.output.append(helper.make_tensor_value_info(_OUTPUT, TensorProto.FLOAT, ["N"]))
    if not any(op.domain in ("", "ai.onnx") for op in proto.opset_import):
        proto.opset_import.append(helper.make_opsetid("", opset))
    return proto


def to_onnx(model: Any, *, opset: int | None = None) -> onnx.ModelProto:
    """Export a fitted surrogate as an ONNX model.

    Parameters
    ----------
    model : estimator
        A fitted ``PolynomialRegressor``, ``NormalizedMLPRegressor`` or
        ``xgboost.XGBRegressor`` on the 7 inputs :data:`FEATURES` (mm, deg, MPa).
    opset : int, optional
        Opset of the ``ai.onnx`` domain. Default :data:`DEFAULT_OPSET` (17) for the
        polynomial and MLP (allowed 13 up to what the installed ``onnx`` knows);
        for XGBoost the highest that onnxmltools supports (allowed 13 up to that).

    Returns
    -------
    onnx.ModelProto
        Input ``"x"`` [N, 7] (double; float32 for XGBoost), output ``"angle_deg"``
        [N] in degrees (double; float32 for XGBoost); checked by
        :func:`onnx.checker.check_model`.

    Raises
    ------
    ValueError
        Unknown model type, a model on other than 7 features, a bad ``opset``.
    sklearn.exceptions.NotFittedError
        If the model is not fitted.
    """
    kind = check_fitted_surrogate(model, "to_onnx")
    if kind in COMPOSITE_KINDS:
        raise ValueError(
            f"The 'model' of to_onnx must be a polynomial, MLP or XGBoost surrogate. Got a "
            f"{kind} surrogate ({type(model).__name__}), which has no ONNX export; export "
            "its base instead."
        )
    if kind == "xgboost":
        proto = _xgboost_graph(model, opset)
    else:
        proto = _double_graph(
            model, kind, _check_opset(opset, onnx.defs.onnx_opset_version(), "to_onnx")
        )
    proto.producer_name = "softbend"
    proto.producer_version = __version__
    proto.doc_string = f"softbend {kind} surrogate: {', '.join(FEATURES)} -> {TARGET} (deg)."
    props = {
        "features": json.dumps(list(FEATURES)),
        "units": json.dumps({name: UNITS[name] for name in (*FEATURES, TARGET)}),
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
    raise ValueError(
        "The 'model' of onnx_predict must be an onnx.ModelProto, bytes or a path. "
        f"Got {type(model).__name__} instead."
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
    X : array_like, shape (n, 7) or (7,)
        Inputs, columns :data:`FEATURES` (mm, deg, MPa), finite; cast to the
        model's input type (double, or float32 for XGBoost).

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
    X = check_features(X, "onnx_predict")
    session = onnxruntime.InferenceSession(_as_bytes(model), providers=["CPUExecutionProvider"])
    (source,) = session.get_inputs()
    dtype = _NUMPY_OF_ONNX.get(source.type)
    if dtype is None:
        raise ValueError(
            "The 'model' of onnx_predict must take a double or float tensor. "
            f"Got an input of type {source.type} instead."
        )
    (result,) = session.run([session.get_outputs()[0].name], {source.name: X.astype(dtype)})
    return np.asarray(result, dtype=np.float64).reshape(X.shape[0])


def save_onnx(model: Any, path: str | os.PathLike[str], *, opset: int | None = None) -> Path:
    """Export a fitted surrogate with :func:`to_onnx` and write it to ``path`` atomically.

    Parameters
    ----------
    model : estimator
        A fitted polynomial, MLP or XGBoost surrogate on the 7 inputs.
    path : str or Path
        File to write (conventionally ``.onnx``); parent folders are created.
    opset : int, optional
        As in :func:`to_onnx`.

    Returns
    -------
    Path
        The written file.
    """
    return write_bytes_atomic(path, to_onnx(model, opset=opset).SerializeToString())
