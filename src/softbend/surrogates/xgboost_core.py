"""Prediction of a saved XGBoost surrogate with NumPy alone (no XGBoost, no scikit-learn).

A saved XGBoost surrogate keeps XGBoost's own JSON model (the ``booster``,
:mod:`softbend.surrogates.xgboost_codec`). For the plain regression that softbend
trains (one target, a ``gbtree`` of numerical splits, an identity link such as
``reg:squarederror``, no early-stopping cut) the prediction is the base score
plus one leaf of every tree, each tree walked from its root (``x < split`` goes
left, a missing value the default way), in float32 as XGBoost computes it:
:meth:`BoosterTrees.predict` gives XGBoost's numbers. Any other booster
(:func:`booster_trees` returns None) is left to XGBoost.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["BoosterTrees", "booster_trees"]

#: Objectives whose prediction is the raw sum of the trees (identity link).
IDENTITY_OBJECTIVES = frozenset({"reg:squarederror", "reg:absoluteerror", "reg:pseudohubererror"})


@dataclass(frozen=True)
class BoosterTrees:
    """The trees of a booster as flat arrays (all trees' nodes one after the other).

    Attributes
    ----------
    base_score : numpy.float32
        The starting prediction, degrees.
    roots : ndarray of int64
        Index of each tree's root node.
    left, right : ndarray of int64
        Children of each node (global indices; -1 at a leaf).
    feature : ndarray of int64
        Input column split on.
    threshold : ndarray of float32
        Split value (a leaf's value at a leaf), in the input's unit (degrees at a leaf).
    default_left : ndarray of bool
        Where a missing (NaN) input goes.
    depth : int
        Largest number of splits from a root to a leaf.
    n_features_in_ : int
        Number of inputs.
    """

    base_score: np.float32
    roots: np.ndarray
    left: np.ndarray
    right: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    default_left: np.ndarray
    depth: int
    n_features_in_: int

    def predict(self, rows: np.ndarray) -> np.ndarray:
        """Angles (deg, float64 of XGBoost's float32) of float rows of the inputs."""
        X = np.asarray(rows, dtype=np.float32)
        n = X.shape[0]
        out = np.full(n, self.base_score, dtype=np.float32)
        index = np.arange(n)
        for root in self.roots:
            node = np.full(n, root, dtype=np.int64)
            for _ in range(self.depth):
                inner = self.left[node] >= 0
                if not inner.any():
                    break
                value = X[index, self.feature[node]]
                go_left = np.where(
                    np.isnan(value), self.default_left[node], value < self.threshold[node]
                )
                node = np.where(inner, np.where(go_left, self.left[node], self.right[node]), node)
            out += self.threshold[node]
        return out.astype(np.float64)


def _base_score(text: object) -> float | None:
    if not isinstance(text, str):
        return None
    try:
        value = float(text.strip().strip("[]"))
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _tree_depth(left: np.ndarray, right: np.ndarray) -> int:
    """Depth of one tree whose children always follow their parent (else -1)."""
    depth = np.zeros(left.size, dtype=np.int64)
    for i in range(left.size):
        for child in (left[i], right[i]):
            if child < 0:
                continue
            if child <= i or child >= left.size:
                return -1
            depth[child] = depth[i] + 1
    return int(depth.max(initial=0))


def booster_trees(booster: str, params: dict[str, Any], n_features: int) -> BoosterTrees | None:
    """The trees of XGBoost's JSON model ``booster``, or None where XGBoost must predict.

    None for anything but one target, a ``gbtree`` of numerical splits and an
    identity-link objective without an early-stopping cut, a ``missing`` other
    than NaN, or a model whose arrays do not fit together (XGBoost then checks it
    and names what is wrong).
    """
    missing = params.get("missing")
    if missing is not None and not (isinstance(missing, float) and math.isnan(missing)):
        return None
    try:
        learner = json.loads(booster)["learner"]
        if learner.get("attributes", {}).get("best_iteration") is not None:
            return None
        if learner["objective"]["name"] not in IDENTITY_OBJECTIVES:
            return None
        model_param = learner["learner_model_param"]
        if str(model_param.get("num_target", "1")) != "1":
            return None
        if str(model_param.get("num_class", "0")) != "0":
            return None
        base = _base_score(model_param["base_score"])
        gbtree = learner["gradient_booster"]
        if gbtree["name"] != "gbtree" or base is None:
            return None
        trees = gbtree["model"]["trees"]
        roots, lefts, rights, features, thresholds, defaults = [], [], [], [], [], []
        offset, depth = 0, 0
        for tree in trees:
            left = np.asarray(tree["left_children"], dtype=np.int64)
            right = np.asarray(tree["right_children"], dtype=np.int64)
            feature = np.asarray(tree["split_indices"], dtype=np.int64)
            threshold = np.asarray(tree["split_conditions"], dtype=np.float32)
            default = np.asarray(tree["default_left"], dtype=bool)
            split_type = np.asarray(tree.get("split_type", []), dtype=np.int64)
            sizes = {a.size for a in (left, right, feature, threshold, default)}
            if (
                len(sizes) != 1
                or left.size == 0
                or np.any(split_type != 0)
                or np.any((left < 0) != (right < 0))
                or np.any(feature[left >= 0] < 0)
                or np.any(feature[left >= 0] >= n_features)
                or not np.all(np.isfinite(threshold))
            ):
                return None
            tree_depth = _tree_depth(left, right)
            if tree_depth < 0:
                return None
            depth = max(depth, tree_depth)
            roots.append(offset)
            lefts.append(np.where(left >= 0, left + offset, -1))
            rights.append(np.where(right >= 0, right + offset, -1))
            features.append(np.where(left >= 0, feature, 0))
            thresholds.append(threshold)
            defaults.append(default)
            offset += left.size
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
    if not trees:
        return None
    return BoosterTrees(
        base_score=np.float32(base),
        roots=np.asarray(roots, dtype=np.int64),
        left=np.concatenate(lefts),
        right=np.concatenate(rights),
        feature=np.concatenate(features),
        threshold=np.concatenate(thresholds),
        default_left=np.concatenate(defaults),
        depth=depth,
        n_features_in_=n_features,
    )
