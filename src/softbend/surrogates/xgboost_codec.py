"""How an XGBoost surrogate is written to and rebuilt from a saved surrogate file.

Its ``state`` is XGBoost's own JSON model (the ``booster``, restored exactly);
its ``params`` are the estimator's, with XGBoost's default ``missing`` (NaN)
written as ``null`` so that the file is strict JSON. XGBoost also takes extra
keyword parameters that it passes on to the booster; such a key is accepted
unless it could name an attribute of the estimator. XGBoost itself is imported
only when a model is rebuilt.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from softbend._validation import must_be
from softbend.errors import SchemaError
from softbend.surrogates.jsonvalues import decode, encode_params
from softbend.surrogates.protocol import Surrogate
from softbend.surrogates.schema import RuleError, tag_float

if TYPE_CHECKING:
    from xgboost import XGBRegressor

__all__ = ["XGBoostCodec"]


def _params(params: dict[str, Any], cls: type) -> tuple[dict[str, Any], set[str]]:
    """Decoded XGBoost parameters and the names of the standard ones."""
    standard = set(cls().get_params(deep=False))
    unknown = [
        key
        for key in params
        if key not in standard
        and (not key.isidentifier() or key.startswith("_") or hasattr(cls, key))
    ]
    if unknown:
        raise SchemaError(
            f"unknown params key(s) {', '.join(map(repr, unknown))} for the xgb "
            f"surrogate; allowed keys: {', '.join(sorted(standard))} and XGBoost's extra "
            "booster parameters",
            key="params",
        )
    try:
        decoded = {key: decode(value) for key, value in params.items()}
    except (KeyError, TypeError, ValueError, AttributeError, RuleError) as err:
        raise SchemaError(f"cannot be read ({err})", key="params") from None
    if "missing" in decoded:  # null: XGBoost's default NaN (how the codec writes it)
        missing = decoded["missing"]
        if missing is None:
            decoded["missing"] = math.nan
        elif isinstance(missing, bool | np.bool_) or not isinstance(
            missing, int | float | np.integer | np.floating
        ):
            raise SchemaError(
                must_be("a number or null (NaN, XGBoost's default)", params["missing"]),
                key="params.missing",
            )
    return decoded, standard


class XGBoostCodec:
    """The :class:`~softbend.surrogates.families.Codec` of ``xgboost.XGBRegressor``."""

    def is_fitted(self, model: object) -> bool:
        """Whether the regressor holds a trained booster."""
        return bool(cast("XGBRegressor", model).__sklearn_is_fitted__())

    def params(self, model: Surrogate) -> dict[str, Any]:
        """The estimator's parameters, XGBoost's default ``missing`` (NaN) as ``null``."""
        params = encode_params(model)
        if params.get("missing") == tag_float(math.nan):
            params["missing"] = None  # read back as NaN
        return params

    def state(self, model: Surrogate) -> dict[str, Any]:
        """``{"booster": XGBoost's JSON model as text}``."""
        booster = cast("XGBRegressor", model).get_booster()
        return {"booster": bytes(booster.save_raw("json")).decode("utf-8")}

    def restore(
        self, cls: type, params: dict[str, Any], state: dict[str, Any], path: str
    ) -> Surrogate:
        """The regressor of ``params`` (as saved) with the checked ``booster`` loaded.

        Raises
        ------
        softbend.errors.SchemaError
            A parameter XGBoost does not know or refuses, a booster it cannot load or
            one that predicts a non-finite angle (the file ``path``).
        """
        decoded, standard = _params(params, cls)
        try:
            model = cls(**decoded)
            model.load_model(bytearray(state["booster"].encode("utf-8")))
            # load_model fills base_score, booster, ... from the booster; put back the
            # standard parameters as they were set, so that get_params (and a refit) is
            # unchanged.
            for key in standard & decoded.keys():
                setattr(model, key, decoded[key])
            # A parameter XGBoost only reads when predicting (missing, n_jobs, ...) fails
            # here, not in the caller's first prediction.
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                inputs = int(model.get_booster().num_features())  # checked against the actuator
                probe = np.asarray(model.predict(np.zeros((1, inputs))), dtype=np.float64)
        except Exception as err:  # xgboost.core.XGBoostError, a parameter XGBoost refuses, ...
            reason = (str(err).strip().splitlines() or [type(err).__name__])[0]  # no stack trace
            raise SchemaError(f"cannot rebuild the xgb surrogate ({reason})", file=path) from None
        if not np.isfinite(probe).all():
            raise SchemaError(
                f"must predict finite angles; the booster predicts {probe.ravel()[0]} (its "
                "base_score or a leaf value is not a finite number)",
                key="state.booster",
                file=path,
            )
        return cast(Surrogate, model)
