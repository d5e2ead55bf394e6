"""Surrogate families: one registry from a family's name to all softbend needs of it.

A *family* is a kind of regressor of the bending angle with its own
hyperparameters: paper B's polynomial regression (``plr``), XGBoost (``xgb``)
and normalized MLP (``mlp``). Its name is the same everywhere: the
``--models`` option of ``softbend train``, the ``model`` column of the results
tables, the ``models/<name>.json`` file and its ``kind``, the report. Each is a
:class:`Family` in :data:`FAMILIES`, which holds

- its ``title`` (for tables and figures);
- its ``grids``: the configurations the search tries, per grid name
  (:data:`GRID_NAMES`, and optionally ``small``: :data:`OPTIONAL_GRIDS`);
- ``make``: a factory of an unfitted estimator from a configuration and the
  search's :class:`FitSettings` (seed, threads, device, epochs);
- ``storage``: how :func:`~softbend.surrogates.persistence.save_surrogate`
  writes a fitted one and :func:`~softbend.surrogates.persistence.load_surrogate`
  rebuilds it (a :class:`Storage`: the estimator's class, the
  :class:`~softbend.surrogates.schema.Schema` every saved value is checked
  against, older names of the kind, an optional :class:`Codec`);
- ``onnx``: its ONNX export, if it has one.

Adding a family is one module plus one ``register`` call, from inside softbend
or outside it::

    from sklearn.linear_model import LinearRegression
    from softbend.surrogates.families import FAMILIES, Family

    FAMILIES.register("linear", Family(
        name="linear", title="linear regression",
        grids={"quick": ({},), "paper": ({"fit_intercept": True}, {"fit_intercept": False})},
        make=lambda params, settings: LinearRegression(**params),
    ))

after which ``softbend train --models linear`` searches, refits and reports it
(and saves it, given a ``storage``). An unknown name anywhere is one
:class:`~softbend.registry.UnknownNameError` line listing the known families.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Protocol, cast

from softbend._extras import require
from softbend._validation import check_choice, must_be
from softbend.errors import InputError, keyed
from softbend.references import SURROGATE_TRAINING
from softbend.registry import Registry
from softbend.surrogates.protocol import Surrogate
from softbend.surrogates.schema import (
    MLP_SCHEMA,
    POLYNOMIAL_SCHEMA,
    TABLE_SCHEMA,
    XGBOOST_SCHEMA,
    Schema,
)
from softbend.surrogates.xgboost_codec import XGBoostCodec

if TYPE_CHECKING:
    from xgboost import XGBRegressor

    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.polynomial import PolynomialRegressor

__all__ = [
    "FAMILIES",
    "GRID_NAMES",
    "MODEL_NAMES",
    "MODEL_TITLES",
    "OPTIONAL_GRIDS",
    "PLR_SMALL_ALPHAS",
    "PLR_SMALL_DEGREES",
    "SMALL_DATA_MLP_GRID",
    "XGB_TREES",
    "Codec",
    "Family",
    "FitSettings",
    "Storage",
    "family_names",
    "legacy_kinds",
]

#: Grid names: ``quick`` (what ``softbend reproduce`` trains in its time budget) and
#: ``paper`` (paper B's grids, §4.1).
GRID_NAMES: tuple[str, ...] = ("quick", "paper")

#: Grids a family may give or leave out: ``small``, for tables of fewer than 100 designs
#: (:data:`softbend.surrogates.search.SMALL_DATA_DESIGNS`); a family without one searches
#: its ``quick`` grid there.
OPTIONAL_GRIDS: tuple[str, ...] = ("small",)

#: Paper B's three families, in the order of its tables (the default of the search).
MODEL_NAMES: tuple[str, ...] = ("plr", "xgb", "mlp")

#: Trees per XGBoost model (paper B does not give the number).
XGB_TREES = 300


@dataclass(frozen=True)
class FitSettings:
    """The search's settings a family's factory may use.

    Attributes
    ----------
    seed : int
        Seed of the estimator's random streams.
    n_jobs : int or None
        Threads (None: the library's default, all cores).
    device : {"auto", "cpu", "cuda"}
        Where a PyTorch model trains.
    epochs : int
        Training epochs of a network.
    """

    seed: int = 0
    n_jobs: int | None = None
    device: str = "auto"
    epochs: int = 200


class Codec(Protocol):
    """How a family whose fitted state is not plain attributes is saved and rebuilt.

    Without a codec, a family's ``params`` are its estimator's ``get_params`` and
    its ``state`` the fitted attributes (names ending in ``_``), each set back on
    a new estimator after its schema's rule accepted it.
    """

    def is_fitted(self, model: object) -> bool:
        """Whether ``model`` (an instance of the family's class) is fitted (and can be saved)."""
        ...

    def params(self, model: Surrogate) -> dict[str, Any]:
        """The parameters to write, as strict JSON."""
        ...

    def state(self, model: Surrogate) -> dict[str, Any]:
        """The fitted state to write, as strict JSON (checked on load by the schema)."""
        ...

    def restore(
        self, cls: type, params: dict[str, Any], state: dict[str, Any], path: str
    ) -> Surrogate:
        """The fitted estimator of ``params`` (as read) and ``state`` (checked), or a
        :class:`~softbend.errors.SchemaError` keyed by the field at fault
        (``params.missing``); the loader names the file ``path``."""
        ...


@dataclass(frozen=True)
class Storage:
    """How a family's fitted estimator is saved to and rebuilt from a surrogate file.

    Attributes
    ----------
    module, class_name : str
        The estimator's class (only this exact class is saved as the family). It
        is found without importing ``module`` (a model exists only once its class
        was imported); rebuilding imports it.
    schema : Schema
        The rule of every ``params`` and ``state`` value a file may hold.
    required_state : tuple of str
        The fitted attributes prediction needs: a file without one is refused, a
        model without one is not fitted.
    legacy_kinds : tuple of str
        Names the family's ``kind`` had in files of older schema versions, read
        as this family (a schema migration).
    extra : str, optional
        The optional dependency (a key of :data:`softbend._extras.EXTRAS`) that
        rebuilding needs, named in the error when it is missing.
    codec : Codec, optional
        Own saving and rebuilding (XGBoost's booster); default: attributes.
    """

    module: str
    class_name: str
    schema: Schema
    required_state: tuple[str, ...]
    legacy_kinds: tuple[str, ...] = ()
    extra: str | None = None
    codec: Codec | None = None

    def holds(self, model: object) -> bool:
        """Whether ``model`` is an instance of exactly this class (no import)."""
        cls = getattr(sys.modules.get(self.module), self.class_name, None)
        return cls is not None and type(model) is cls

    def estimator_class(self, purpose: str) -> type:
        """The estimator's class, imported (``purpose`` names it if an extra is missing)."""
        if self.extra is not None:
            require(self.extra, purpose)
        return getattr(importlib.import_module(self.module), self.class_name)


@dataclass(frozen=True)
class Family:
    """A surrogate family: what the search, the persistence, the CLI and the report use.

    Attributes
    ----------
    name : str
        The name it is registered under in :data:`FAMILIES` (``"plr"``), as on the
        command line and in files.
    title : str
        Long name for tables and figures (``"polynomial regression"``).
    grids : mapping
        ``{grid name: configurations}`` for every name of :data:`GRID_NAMES`; a
        configuration is a dict of the factory's parameters.
    make : callable
        ``make(params, settings) -> estimator``: a new, unfitted scikit-learn style
        regressor (``fit(X, y)``, ``predict(X)`` on the columns of
        :data:`~softbend.surrogates.features.FEATURES`, mm, deg and MPa, to degrees)
        of the configuration ``params`` and the :class:`FitSettings`.
    storage : Storage, optional
        How a fitted one is saved; None: it is searched and reported, not saved.
    onnx : callable, optional
        ``onnx(model, opset) -> onnx.ModelProto`` with input ``"x"`` [N, 7] and
        output ``"angle_deg"`` [N]; None: no ONNX export.
    """

    name: str
    title: str
    grids: Mapping[str, Sequence[Mapping[str, Any]]]
    make: Callable[[dict[str, Any], FitSettings], Any]
    storage: Storage | None = None
    onnx: Callable[[Any, int | None], Any] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        family = f"of the surrogate family {self.name!r}"
        if not isinstance(self.title, str) or not self.title.strip():
            raise InputError(must_be(f"a non-empty string {family}", self.title), key="title")
        if not callable(self.make):
            raise InputError(
                f"must be callable (params, settings) {family}; got {self.make!r}", key="make"
            )
        grids = dict(self.grids) if isinstance(self.grids, Mapping) else {}
        unknown = [g for g in grids if g not in (*GRID_NAMES, *OPTIONAL_GRIDS)]
        if unknown:
            raise InputError(
                f"must name only the grids {', '.join(GRID_NAMES + OPTIONAL_GRIDS)} {family}; "
                f"got {', '.join(map(repr, unknown))}",
                key="grids",
            )
        for grid_name in (*GRID_NAMES, *(g for g in OPTIONAL_GRIDS if g in grids)):
            configs = grids.get(grid_name)
            if not isinstance(configs, Sequence) or isinstance(configs, str) or not configs:
                raise InputError(
                    f"must give one or more configurations {family} for each grid "
                    f"{', '.join(GRID_NAMES)}; got {grid_name!r}: {configs!r}",
                    key="grids",
                )
            if not all(isinstance(c, Mapping) for c in configs):
                raise InputError(
                    f"must hold dicts of parameters {family}; got {configs!r} for {grid_name!r}",
                    key="grids",
                )
        object.__setattr__(self, "grids", {k: tuple(dict(c) for c in v) for k, v in grids.items()})

    def configs(self, grid_name: str) -> list[dict[str, Any]]:
        """New copies of the configurations of the grid ``grid_name`` (``quick``, ``paper``,
        ``small``: the family's own, else its ``quick`` grid)."""
        check_choice(grid_name, "grid", (*GRID_NAMES, *OPTIONAL_GRIDS))
        configs = self.grids.get(grid_name, self.grids["quick"])
        return [dict(config) for config in configs]


class _FamilyRegistry(Registry[Family]):
    """A :class:`~softbend.registry.Registry` whose entries are registered under their name."""

    def register(self, name: str, entry: Family, *, replace: bool = False) -> Family:
        if not isinstance(entry, Family) or entry.name != name:
            raise InputError(
                f"must be a Family registered under its own name; got {type(entry).__name__} "
                f"named {getattr(entry, 'name', None)!r} for {name!r}",
                key="entry",
            )
        return super().register(name, entry, replace=replace)


#: Every surrogate family, by name: ``plr``, ``xgb``, ``mlp`` and any registered since.
FAMILIES: Registry[Family] = _FamilyRegistry("surrogate family")


def family_names(models: str | Sequence[str]) -> tuple[str, ...]:
    """The families named by ``models``, each checked, without repeats, in order.

    Parameters
    ----------
    models : str or sequence of str
        Names, or one comma-separated text of names (``"plr,mlp"``).

    Raises
    ------
    softbend.registry.UnknownNameError
        For a name no family has, listing the known ones (key ``models``).
    softbend.errors.InputError
        For no name at all (key ``models``).
    """
    given = models
    if isinstance(models, str):
        models = models.split(",")
    names = [m.strip() if isinstance(m, str) else m for m in models]
    names = [m for m in names if m != ""]
    if not names:
        known = ", ".join(FAMILIES.names())
        raise InputError(
            must_be(f"at least one surrogate family name (known: {known})", given), key="models"
        )
    with keyed("models"):
        return tuple(dict.fromkeys(FAMILIES.check(name) for name in names))


def legacy_kinds() -> dict[str, str]:
    """``{older kind: family name}`` of the files of earlier schema versions."""
    return {
        old: name
        for name, family in FAMILIES.items()
        if family.storage is not None
        for old in family.storage.legacy_kinds
    }


class _Titles(Mapping[str, str]):
    """The title of each registered family, by name (a live view of :data:`FAMILIES`)."""

    def __getitem__(self, name: str) -> str:
        if name not in FAMILIES:
            raise KeyError(name)
        return FAMILIES.get(name).title

    def __iter__(self) -> Iterator[str]:
        return iter(FAMILIES.names())

    def __len__(self) -> int:
        return len(FAMILIES)


#: Long names of the families, by name.
MODEL_TITLES: Mapping[str, str] = _Titles()


# --- paper B's three families ----------------------------------------------------------------


def _make_plr(params: dict[str, Any], settings: FitSettings) -> Any:
    from softbend.surrogates.polynomial import PolynomialRegressor

    return PolynomialRegressor(**params)


def _make_xgb(params: dict[str, Any], settings: FitSettings) -> Any:
    XGBRegressor = require("xgboost", "The XGBoost surrogate").XGBRegressor

    return XGBRegressor(
        n_estimators=XGB_TREES,
        objective="reg:squarederror",
        tree_method="hist",
        random_state=settings.seed,
        n_jobs=settings.n_jobs,
        **params,
    )


def _make_mlp(params: dict[str, Any], settings: FitSettings) -> Any:
    from softbend.surrogates.mlp import NormalizedMLPRegressor

    return NormalizedMLPRegressor(
        **params, epochs=settings.epochs, seed=settings.seed, device=settings.device
    )


def _plr_onnx(model: Surrogate, opset: int | None) -> Any:
    from softbend.surrogates.onnx_graphs import polynomial_graph

    return polynomial_graph(cast("PolynomialRegressor", model), opset)


def _xgb_onnx(model: Surrogate, opset: int | None) -> Any:
    from softbend.surrogates.onnx_graphs import xgboost_graph

    return xgboost_graph(cast("XGBRegressor", model), opset)


def _mlp_onnx(model: Surrogate, opset: int | None) -> Any:
    from softbend.surrogates.onnx_graphs import mlp_graph

    return mlp_graph(cast("NormalizedMLPRegressor", model), opset)


_INPUT_STATE = ("n_features_in_", "x_mean_", "x_scale_", "y_mean_", "y_scale_")


def _paper_range(name: str) -> range:
    """The integers of paper B's grid ``name`` (Sec. 4.1), both ends included."""
    low, high = SURROGATE_TRAINING[name].value
    return range(int(low), int(high) + 1)


_MLP_PICK = tuple(SURROGATE_TRAINING["mlp_hidden"].value)

#: The MLP's ``small`` grid: two small networks, Adam's step 3e-3
#: (:mod:`softbend.surrogates.search` tells why).
SMALL_DATA_MLP_GRID: tuple[dict[str, Any], ...] = tuple(
    {"hidden_sizes": (h, h), "learning_rate": 3e-3} for h in (16, 32)
)

#: Degrees and ridge strengths (per sample, standardized units) of the polynomial's
#: ``small`` grid: every pair is tried, the grouped cross-validation chooses.
#: On the first 30 designs of ``examples/pneunet/simulations.csv`` the held-out RMSE was
#: 9.3° at degree 2 (any ridge up to 1e-3), and a ridge of 0.1 took degree 4 from 25.9° to
#: 18.8° (docs/design-log.md).
PLR_SMALL_DEGREES: tuple[int, ...] = (1, 2, 3, 4)
PLR_SMALL_ALPHAS: tuple[float, ...] = (1e-8, 1e-3, 1e-2, 1e-1, 1.0)

FAMILIES.register(
    "plr",
    Family(
        name="plr",
        title="polynomial regression",
        grids={
            "quick": tuple({"degree": d} for d in (2, 4, 6)),
            "paper": tuple({"degree": d} for d in _paper_range("plr_degrees")),
            "small": tuple(
                {"degree": d, "alpha": a} for d in PLR_SMALL_DEGREES for a in PLR_SMALL_ALPHAS
            ),
        },
        make=_make_plr,
        storage=Storage(
            "softbend.surrogates.polynomial",
            "PolynomialRegressor",
            POLYNOMIAL_SCHEMA,
            (*_INPUT_STATE, "powers_", "coef_"),
            legacy_kinds=("polynomial",),
        ),
        onnx=_plr_onnx,
    ),
)
FAMILIES.register(
    "xgb",
    Family(
        name="xgb",
        title="XGBoost",
        grids={
            "quick": tuple(
                {"max_depth": d, "learning_rate": r} for d in (6, 9) for r in (0.2, 0.4)
            ),
            "paper": tuple(
                {"max_depth": d, "learning_rate": round(0.1 * k, 1)}
                for d in _paper_range("xgb_max_depths")
                for k in range(1, 11)  # 0.1 to 1 by 0.1
            ),
        },
        make=_make_xgb,
        storage=Storage(
            "xgboost",
            "XGBRegressor",
            XGBOOST_SCHEMA,
            ("booster",),
            legacy_kinds=("xgboost",),
            extra="xgboost",
            codec=XGBoostCodec(),
        ),
        onnx=_xgb_onnx,
    ),
)
FAMILIES.register(
    "mlp",
    Family(
        name="mlp",
        title="normalized MLP",
        grids={
            "quick": ({"hidden_sizes": _MLP_PICK},),  # paper B's pick
            "paper": tuple(
                {"hidden_sizes": (a, b)}
                for a in _paper_range("mlp_hidden_units")
                for b in _paper_range("mlp_hidden_units")
            ),
            "small": SMALL_DATA_MLP_GRID,
        },
        make=_make_mlp,
        storage=Storage(
            "softbend.surrogates.mlp",
            "NormalizedMLPRegressor",
            MLP_SCHEMA,
            (*_INPUT_STATE, "coefs_", "intercepts_"),
        ),
        onnx=_mlp_onnx,
    ),
)


# --- the table base ---------------------------------------------------------------------------


def _make_table(params: dict[str, Any], settings: FitSettings) -> Any:
    from softbend.surrogates.table import TableRegressor

    return TableRegressor(**{"seed": settings.seed, **params})


FAMILIES.register(
    "table",
    Family(
        name="table",
        title="simulation table (curves, GP between designs)",
        grids={"quick": ({},), "paper": ({},)},
        make=_make_table,
        storage=Storage(
            "softbend.surrogates.table",
            "TableRegressor",
            TABLE_SCHEMA,
            (
                "n_features_in_",
                "designs_",
                "curve_offsets_",
                "curve_pressures_",
                "curve_angles_",
                "x_mean_",
                "x_scale_",
                "kernel_theta_",
                "gp_inputs_",
                "gp_targets_",
            ),
        ),
    ),
)
