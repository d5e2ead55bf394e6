"""The registry of surrogate families: one name per family, no silent default."""

from __future__ import annotations

import pytest

from softbend.errors import InputError
from softbend.registry import UnknownNameError
from softbend.surrogates.families import (
    FAMILIES,
    GRID_NAMES,
    MODEL_NAMES,
    MODEL_TITLES,
    Family,
    FitSettings,
    family_names,
    legacy_kinds,
)
from softbend.surrogates.search import _make, grid, search


def _toy(name="toy", **changes):
    fields = {
        "name": name,
        "title": "toy",
        "grids": {"quick": ({},), "paper": ({},)},
        "make": lambda params, settings: None,
    }
    return Family(**{**fields, **changes})


def test_paper_b_families_are_registered_under_their_command_line_names():
    assert FAMILIES.names()[:3] == MODEL_NAMES == ("plr", "xgb", "mlp")
    assert {name: FAMILIES.get(name).name for name in MODEL_NAMES} == {n: n for n in MODEL_NAMES}
    assert dict(MODEL_TITLES) == {
        "plr": "polynomial regression",
        "xgb": "XGBoost",
        "mlp": "normalized MLP",
        "table": "simulation table (curves, GP between designs)",
    }
    assert legacy_kinds() == {"polynomial": "plr", "xgboost": "xgb"}


def test_the_small_grids_are_a_family_s_own_or_its_quick_one():
    small_plr = grid("small", "plr")
    # every degree with every ridge strength; paper B's grids are left as they were
    assert {c["degree"] for c in small_plr} == {1, 2, 3, 4}
    assert {c["alpha"] for c in small_plr} == {1e-8, 1e-3, 1e-2, 1e-1, 1.0}
    assert len(small_plr) == 20
    assert grid("small", "mlp") == [
        {"hidden_sizes": (16, 16), "learning_rate": 3e-3},
        {"hidden_sizes": (32, 32), "learning_rate": 3e-3},
    ]
    assert grid("small", "xgb") == grid("quick", "xgb")  # none of its own
    assert grid("small", "table") == [{}]
    assert _toy(grids={"quick": ({},), "paper": ({},), "small": ({"a": 1},)}).configs("small") == [
        {"a": 1}
    ]
    with pytest.raises(InputError, match="grids"):
        _toy(grids={"quick": ({},), "paper": ({},), "huge": ({},)})
    with pytest.raises(InputError, match="grids"):
        _toy(grids={"quick": ({},), "paper": ({},), "small": ()})


def test_the_grids_are_paper_b_s_and_the_quick_ones():
    assert grid("quick", "plr") == [{"degree": 2}, {"degree": 4}, {"degree": 6}]
    assert grid("paper", "plr") == [{"degree": d} for d in range(2, 11)]
    assert grid("quick", "xgb") == [
        {"max_depth": 6, "learning_rate": 0.2},
        {"max_depth": 6, "learning_rate": 0.4},
        {"max_depth": 9, "learning_rate": 0.2},
        {"max_depth": 9, "learning_rate": 0.4},
    ]
    paper_xgb = grid("paper", "xgb")
    assert len(paper_xgb) == 200 and paper_xgb[0] == {"max_depth": 1, "learning_rate": 0.1}
    assert paper_xgb[-1] == {"max_depth": 20, "learning_rate": 1.0}
    assert grid("quick", "mlp") == [{"hidden_sizes": (63, 65)}]
    paper_mlp = grid("paper", "mlp")
    assert len(paper_mlp) == 121 and paper_mlp[0] == {"hidden_sizes": (55, 55)}
    # a copy each time: changing one does not change the family
    paper_mlp[0]["hidden_sizes"] = (1, 1)
    assert grid("paper", "mlp")[0] == {"hidden_sizes": (55, 55)}


def test_the_factories_build_what_the_search_fits():
    plr = _make("plr", {"degree": 3}, seed=3, n_jobs=2, device="cpu", epochs=7)
    assert type(plr).__name__ == "PolynomialRegressor" and plr.degree == 3
    xgb = _make("xgb", {"max_depth": 3}, seed=3, n_jobs=2, device="cpu", epochs=7)
    params = xgb.get_params()
    assert (params["n_estimators"], params["random_state"], params["n_jobs"]) == (300, 3, 2)
    assert (params["tree_method"], params["max_depth"]) == ("hist", 3)
    pytest.importorskip("torch")
    mlp = _make("mlp", {"hidden_sizes": (5, 6)}, seed=3, n_jobs=2, device="cpu", epochs=7)
    assert (mlp.hidden_sizes, mlp.epochs, mlp.seed, mlp.device) == ((5, 6), 7, 3, "cpu")


@pytest.mark.parametrize(
    "call",
    [
        lambda: grid("quick", "svm"),
        lambda: _make("svm", {}, seed=0, n_jobs=1, device="cpu", epochs=1),
        lambda: family_names("plr,svm"),
        lambda: FAMILIES.get("svm"),
    ],
    ids=["grid", "factory", "names", "get"],
)
def test_an_unknown_family_is_one_line_listing_the_known_ones(call):
    with pytest.raises(UnknownNameError) as info:
        call()
    message = str(info.value)
    assert "'svm'" in message and "known: plr, xgb, mlp, table" in message and "\n" not in message


def test_search_refuses_an_unknown_family_before_any_fit(small_data):
    with pytest.raises(
        UnknownNameError,
        match=r"models: Unknown surrogate family 'svm'; known: plr, xgb, mlp, table",
    ):
        search(small_data, models=["plr", "svm"])
    with pytest.raises(UnknownNameError, match=r"param_grid: Unknown surrogate family 'svm'"):
        search(small_data, models=["plr"], param_grid={"svm": [{}]})
    with pytest.raises(ValueError, match="models: must be at least one surrogate family name"):
        search(small_data, models=[])


def test_family_names_reads_text_or_names_in_order_without_repeats():
    assert family_names(" plr, mlp,plr ,,") == ("plr", "mlp")
    assert family_names(["xgb", "plr", "xgb"]) == ("xgb", "plr")
    with pytest.raises(InputError, match="must be at least one surrogate family") as info:
        family_names(" , ")
    assert info.value.key == "models"


def test_a_family_is_checked_when_built_and_registered_under_its_name():
    with pytest.raises(
        ValueError, match=r"grids: must give .* of the surrogate family 'toy'.*'paper'"
    ):
        _toy(grids={"quick": ({},)})
    with pytest.raises(
        ValueError, match=r"grids: must hold dicts of parameters of the surrogate family 'toy'"
    ):
        _toy(grids={"quick": ({},), "paper": ("degree",)})
    with pytest.raises(ValueError, match="title: must be a non-empty string"):
        _toy(title=" ")
    with pytest.raises(ValueError, match="make: must be callable"):
        _toy(make=None)
    with pytest.raises(ValueError, match="registered under its own name"):
        FAMILIES.register("other", _toy())
    with pytest.raises(ValueError, match="already registered"):
        FAMILIES.register("plr", _toy("plr"))
    assert "toy" not in FAMILIES and "other" not in FAMILIES
    assert tuple(_toy().grids) == GRID_NAMES
    assert _toy().configs("quick") == [{}]
    with pytest.raises(ValueError, match="grid: must be one of"):
        _toy().configs("huge")


def test_a_registered_family_is_searched_with_its_own_grid_and_factory(small_data):
    from sklearn.linear_model import Ridge

    made = []

    def make(params, settings):
        made.append((params, settings))
        return Ridge(**params)

    FAMILIES.register(
        "ridge",
        Family("ridge", "ridge regression", {"quick": ({"alpha": 1.0},), "paper": ({},)}, make),
    )
    try:
        assert MODEL_TITLES["ridge"] == "ridge regression"
        result = search(small_data, models="ridge", folds=3, seed=4)
    finally:
        FAMILIES.unregister("ridge")
    assert "ridge" not in MODEL_TITLES
    assert list(result.families) == ["ridge"]
    assert type(result.families["ridge"].model).__name__ == "Ridge"
    assert list(result.cv_results["model"]) == ["ridge"]
    assert made[0] == ({"alpha": 1.0}, FitSettings(seed=4, n_jobs=None, device="auto", epochs=200))
    assert len(made) == 3 + 1  # three folds and the refit
