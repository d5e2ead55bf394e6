"""The ONNX graphs of the polynomial, MLP and XGBoost surrogates.

Every graph takes the input ``"x"`` of shape [N, 7] (columns
:data:`~softbend.surrogates.features.FEATURES`, in mm, deg and MPa) and returns
``"angle_deg"`` of shape [N] (degrees); :func:`softbend.surrogates.onnx_export.to_onnx`
adds the metadata and checks the model. The families of
:mod:`softbend.surrogates.families` name these builders as their ``onnx``.

- :func:`polynomial_graph` and :func:`mlp_graph`: built node by node in double
  precision (input and output ``tensor(double)``), so they reproduce ``predict``
  to rounding.
- :func:`xgboost_graph`: converted by :func:`onnxmltools.convert_xgboost`, float32.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from softbend._extras import require
from softbend._validation import interval_text, must_be
from softbend.errors import InputError
from softbend.surrogates.features import TARGET

if TYPE_CHECKING:
    import onnx
    from xgboost import XGBRegressor

    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.polynomial import PolynomialRegressor

    _Standardized = PolynomialRegressor | NormalizedMLPRegressor
else:
    onnx = require("onnx", "ONNX export (softbend.surrogates.onnx_export)")
TensorProto, helper, numpy_helper = onnx.TensorProto, onnx.helper, onnx.numpy_helper

__all__ = ["DEFAULT_OPSET", "check_opset", "mlp_graph", "polynomial_graph", "xgboost_graph"]

#: Default opset of the ``ai.onnx`` domain for the polynomial and MLP graphs.
DEFAULT_OPSET = 17

#: Lowest opset the graphs are written for.
_MIN_OPSET = 13

_INPUT = "x"
_OUTPUT = TARGET


def check_opset(opset: object, highest: int) -> int:
    """``opset``, or the default (at most ``highest``) for None; else an
    :class:`~softbend.errors.InputError` (key ``opset``)."""
    if opset is None:
        return min(DEFAULT_OPSET, highest)
    if isinstance(opset, bool) or not isinstance(opset, int) or not _MIN_OPSET <= opset <= highest:
        interval = interval_text(_MIN_OPSET, highest, low_inclusive=True, high_inclusive=True)
        raise InputError(must_be(f"None or an integer in {interval}", opset), key="opset")
    return opset


def _const(name: str, value: ArrayLike, dtype: type = np.float64) -> onnx.TensorProto:
    return numpy_helper.from_array(np.ascontiguousarray(value, dtype=dtype), name)


def _standardize(model: _Standardized) -> tuple[list[onnx.NodeProto], list[onnx.TensorProto]]:
    """Nodes computing z = (x − x_mean_)/x_scale_ into ``"z"``."""
    nodes = [
        helper.make_node("Sub", [_INPUT, "x_mean"], ["x_centred"]),
        helper.make_node("Div", ["x_centred", "x_scale"], ["z"]),
    ]
    return nodes, [_const("x_mean", model.x_mean_), _const("x_scale", model.x_scale_)]


def _rescale(
    model: _Standardized, source: str
) -> tuple[list[onnx.NodeProto], list[onnx.TensorProto]]:
    """Nodes computing angle_deg = y_mean_ + y_scale_ · source."""
    nodes = [
        helper.make_node("Mul", [source, "y_scale"], ["y_scaled"]),
        helper.make_node("Add", ["y_scaled", "y_mean"], [_OUTPUT]),
    ]
    return nodes, [_const("y_scale", model.y_scale_), _const("y_mean", model.y_mean_)]


def _polynomial_body(model: PolynomialRegressor, opset: int) -> tuple[list, list]:
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


def _mlp_body(model: NormalizedMLPRegressor) -> tuple[list, list]:
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


def _double_graph(
    model: _Standardized, name: str, body: tuple[list, list], opset: int
) -> onnx.ModelProto:
    """Standardize, ``body`` (into ``"y_std"``), rescale: the graph ``softbend_<name>``."""
    d = int(model.n_features_in_)
    first, first_consts = _standardize(model)
    body_nodes, body_consts = body
    last, last_consts = _rescale(model, "y_std")
    graph = helper.make_graph(
        first + body_nodes + last,
        f"softbend_{name}",
        [helper.make_tensor_value_info(_INPUT, TensorProto.DOUBLE, ["N", d])],
        [helper.make_tensor_value_info(_OUTPUT, TensorProto.DOUBLE, ["N"])],
        initializer=first_consts + body_consts + last_consts,
    )
    opsets = [helper.make_opsetid("", opset)]
    return helper.make_model(
        graph, opset_imports=opsets, ir_version=helper.find_min_ir_version_for(opsets)
    )


def polynomial_graph(model: PolynomialRegressor, opset: int | None = None) -> onnx.ModelProto:
    """The graph of a fitted ``PolynomialRegressor`` (double precision).

    It raises the standardized inputs z[:, None, :] to the exponent table
    ``powers_`` (a [1, T, 7] double constant; ONNX's ``Pow`` gives 0⁰ = 1), takes
    the product over the features (``ReduceProd``), contracts with ``coef_``
    (``MatMul``) and rescales. Its peak memory is N·T·7 doubles (degree 4: 18 kB
    per sample), so evaluate very large batches in chunks.
    """
    opset = check_opset(opset, onnx.defs.onnx_opset_version())
    return _double_graph(model, "plr", _polynomial_body(model, opset), opset)


def mlp_graph(model: NormalizedMLPRegressor, opset: int | None = None) -> onnx.ModelProto:
    """The graph of a fitted ``NormalizedMLPRegressor``: MatMul/Add/Tanh twice, then linear."""
    opset = check_opset(opset, onnx.defs.onnx_opset_version())
    return _double_graph(model, "mlp", _mlp_body(model), opset)


def xgboost_graph(model: XGBRegressor, opset: int | None = None) -> onnx.ModelProto:
    """The graph of a fitted ``xgboost.XGBRegressor``: a float32 ``TreeEnsembleRegressor``.

    Converted by :func:`onnxmltools.convert_xgboost` (XGBoost evaluates its trees
    in float32 as well), the output reshaped to [N] as ``"angle_deg"``. The opset
    defaults to the highest onnxmltools supports.
    """
    convert_xgboost = require("onnxmltools", "ONNX export of XGBoost").convert_xgboost
    from onnxmltools.convert.common._topology import get_maximum_opset_supported
    from onnxmltools.convert.common.data_types import FloatTensorType

    opset = check_opset(opset, get_maximum_opset_supported())
    if model.get_booster().feature_names is not None:
        # Fitted on a DataFrame: onnxmltools only reads the default names f0, f1, ...
        booster = model.get_booster().copy()
        booster.feature_names = None
        model = copy.copy(model)
        model._Booster = booster
    proto = convert_xgboost(
        model,
        name="softbend_xgb",
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
