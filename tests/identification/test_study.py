import warnings

import numpy as np
import pytest

from softbend.errors import DatasetError
from softbend.identification.study import (
    IdentificationConfig,
    identify,
    n_fits,
    split_by_sign,
)
from softbend.identification.synthetic import synthetic_dataset


@pytest.fixture(scope="module")
def small_dataset():
    data = synthetic_dataset(n_experiments=3, n_samples=256, seed=3)
    return [e for group in data.values() for e in group]


@pytest.fixture(scope="module")
def small_result(small_dataset):
    calls = []
    result = identify(small_dataset, progress=calls.append)
    return result, calls


def test_every_experiment_is_held_out_once_per_output_and_mode(small_result, small_dataset):
    result, calls = small_result
    assert len(calls) == n_fits(small_dataset) == 2 * 2 * (3 + 1)
    counts = result.metrics.groupby(["sign", "output", "mode"]).size()
    assert (counts == 3).all() and len(counts) == 8
    names = {e.name for e in small_dataset}
    assert set(result.metrics["experiment"]) == names


def test_held_out_predictions_keep_measured_initial_conditions(small_result):
    result, _ = small_result
    for (sign, output, name), pred in result.predictions.items():
        experiment = next(e for e in result.experiments[sign] if e.name == name)
        measured = getattr(experiment, output)
        lag = result.models[(sign, output)].max_lag_
        for y_hat in pred.values():
            assert y_hat.shape == measured.shape
            np.testing.assert_array_equal(y_hat[:lag], measured[:lag])


def test_one_step_beats_free_run_and_free_run_is_accurate(small_result):
    result, _ = small_result
    summary = result.summary().set_index(["sign", "output", "mode"])
    for sign in ("positive", "negative"):
        for output in ("rho", "length_mm"):
            one = summary.loc[(sign, output, "one-step"), "nrmse_mean"]
            free = summary.loc[(sign, output, "free-run"), "nrmse_mean"]
            assert one <= free
            assert free < 0.15


def test_final_models_are_trained_on_every_experiment_of_their_sign(small_result):
    result, _ = small_result
    for (sign, _output), model in result.models.items():
        assert model.n_experiments_ == len(result.experiments[sign])
        params = result.kernel_params[(sign, _output)]
        assert 0 < params["shape"] <= 2 and params["sigma"] > 0


def test_kernel_report_says_which_shape_each_model_used_and_why(small_result):
    # Paper A's layout (mixed excitation): regressors lighter-tailed than Gaussian.
    result, _ = small_result
    for params in result.kernel_params.values():
        assert params["shape_source"] == "moments" and params["moments_of"] == "differences"
        assert params["shape"] == 2.0 and params["shape_clipped"]
        assert params["kurtosis"] < params["gaussian_kurtosis"]
        assert "lighter tails" in params["shape_reason"]
        assert "clipped to 2" in params["shape_reason"]


def test_impulsive_data_get_a_shape_below_two_and_cv_says_it_chose(small_dataset):
    impulsive = synthetic_dataset(n_experiments=2, n_samples=200, seed=1, excitation="impulsive")
    result = identify(impulsive["negative"])
    params = result.kernel_params[("negative", "rho")]
    assert params["shape"] < 1.5 and not params["shape_clipped"]
    assert "heavier tails" in params["shape_reason"]
    chosen = identify(small_dataset[-2:], IdentificationConfig(kernel="cv"))
    params = chosen.kernel_params[("negative", "rho")]
    assert params["shape_source"] == "cv" and params["kurtosis"] is None
    assert "cross-validation" in params["shape_reason"]


def test_identification_is_deterministic(small_dataset):
    subset = [e for e in small_dataset if e.sign == "negative"][:2]
    a = identify(subset).metrics
    b = identify(subset).metrics
    assert a.equals(b)


def test_a_sign_with_one_experiment_is_refused(small_dataset):
    one = [e for e in small_dataset if e.sign == "positive"][:1]
    with pytest.raises(DatasetError, match="at least 2 positive-pressure experiments"):
        identify(one)


def test_split_by_sign_keeps_order(small_dataset):
    groups = split_by_sign(list(reversed(small_dataset)))
    assert list(groups) == ["positive", "negative"]
    assert all(e.sign == "negative" for e in groups["negative"])


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("C", 0.0),
        ("epsilon", -0.1),
        ("output_lags", 0),
        ("kernel", "grid"),
        ("moments_of", "pairs"),
    ],
)
def test_bad_configuration_names_the_field(field, value):
    with pytest.raises(ValueError, match=rf"^{field}: must") as info:
        IdentificationConfig(**{field: value})
    assert info.value.key == field


@pytest.mark.parametrize(
    ("field", "value", "shown"),
    [
        ("C", 1e300, r"a number in \(0, 10000\]; got 1e\+300"),
        ("epsilon", float("nan"), r"a number in \[0, 10\]; got nan"),
        ("input_lags", 1_000_000_000, r"an integer in \[1, 50\]; got 1000000000"),
        ("output_lags", 99999999999999999999, r"an integer in \[1, 50\]; got 9{20}"),
    ],
)
def test_settings_beyond_their_declared_range_are_refused(field, value, shown):
    with pytest.raises(ValueError, match=rf"^{field}: must be {shown}"):
        IdentificationConfig(**{field: value})


def test_lags_the_shortest_experiment_cannot_hold_are_refused_before_any_fit(small_dataset):
    short = synthetic_dataset(n_experiments=2, n_samples=16, seed=1)["positive"]
    calls = []
    with pytest.raises(ValueError, match=r"^output_lags: must be an "
                       r"integer in \[1, 12\] for these experiments.*16 sample"):  # fmt: skip
        identify(short, IdentificationConfig(output_lags=13), progress=calls.append)
    assert calls == []


def test_a_constant_output_is_refused_before_any_fit(small_dataset):
    from softbend.identification.data import Experiment

    rest = small_dataset[0]
    still = Experiment(
        "still", rest.time_s, np.full(rest.n_samples, 5.0), np.zeros(rest.n_samples),
        np.zeros(rest.n_samples),
    )  # fmt: skip
    calls = []
    with pytest.raises(DatasetError, match=r"'still' has a constant rho \(every sample 0\)"):
        identify([*small_dataset, still], progress=calls.append)
    assert calls == []


def test_a_diverged_free_run_is_an_error_not_nan_figures(small_dataset, monkeypatch):
    from softbend.errors import ConvergenceError
    from softbend.identification.narx import NARXRegressor

    def diverged(self, X, y_init, *, groups=None):
        warnings.warn("diverged", RuntimeWarning, stacklevel=2)
        return np.full(np.shape(X)[0], np.nan)

    monkeypatch.setattr(NARXRegressor, "simulate", diverged)
    pair = [e for e in small_dataset if e.sign == "negative"][:2]
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # the error only, no warning besides
        with pytest.raises(ConvergenceError, match=r"free-run prediction of rho.*not finite"):
            identify(pair)
