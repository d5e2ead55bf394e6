"""The training data's support: each design's swept pressure and the angle limit."""

from __future__ import annotations

import json

import numpy as np
import pytest

from softbend.design import sfrba_design
from softbend.errors import SchemaError
from softbend.surrogates.features import training_ranges
from softbend.surrogates.persistence import load_surrogate, save_surrogate
from softbend.surrogates.polynomial import PolynomialRegressor
from softbend.surrogates.predict import predict_angles
from softbend.surrogates.support import ANGLE_TOLERANCE, Support, support_from_rows

A = (100.0, 6.0, 2.0, 2.0, 5.0, 8.0)
B = (160.0, 10.0, 4.0, 4.0, 15.0, 12.0)


def _rows(design, pmax, n=6, slope=1000.0):
    p = np.linspace(0.0, pmax, n)
    X = np.column_stack([np.tile(design, (n, 1)), p])
    return X, slope * p


@pytest.fixture
def two_designs():
    XA, yA = _rows(A, 0.2)
    XB, yB = _rows(B, 0.4, slope=500.0)
    return support_from_rows(np.vstack([XA, XB]), np.concatenate([yA, yB]))


def test_each_design_keeps_its_largest_pressure_and_the_largest_angle(two_designs):
    s = two_designs
    assert s.designs.shape == (2, 6)
    np.testing.assert_allclose(s.max_pressure(np.array([A, B])), [0.2, 0.4])
    assert s.max_angle_deg == pytest.approx(200.0)
    assert s.angle_limit_deg == pytest.approx(200.0 * (1 + ANGLE_TOLERANCE))


def test_between_two_designs_the_supported_pressure_lies_between_theirs(two_designs):
    middle = (np.array(A) + np.array(B)) / 2
    near_a = np.array(A) + 0.1 * (np.array(B) - np.array(A))
    p_mid, p_near_a = two_designs.max_pressure(np.array([middle, near_a]))
    assert p_mid == pytest.approx(0.3)  # equidistant: the mean
    assert 0.2 < p_near_a < p_mid  # closer to A: closer to A's pressure


def test_a_pressure_past_the_design_s_sweep_is_beyond_even_inside_the_box(two_designs):
    X = np.array([[*A, 0.1], [*A, 0.3], [*B, 0.3]])
    assert two_designs.supported(X).tolist() == [True, False, True]
    phrases = two_designs.beyond(X)
    assert len(phrases) == 1 and "pressure 0.3 MPa" in phrases[0] and "0.2 MPa" in phrases[0]


def test_an_angle_past_the_largest_trained_on_is_beyond(two_designs):
    X = np.array([[*A, 0.1], [*A, 0.1]])
    ok = two_designs.supported(X, [150.0, 210.0])
    assert ok.tolist() == [True, False]
    assert any("angle 210" in p for p in two_designs.beyond(X, [150.0, 210.0]))
    assert two_designs.beyond(X, [150.0, 203.0]) == []  # inside the tolerance


def test_merging_keeps_every_design_and_the_larger_pressure_of_a_shared_one(two_designs):
    XA, yA = _rows(A, 0.25, slope=1300.0)
    merged = two_designs.merged(support_from_rows(XA, yA))
    assert merged.designs.shape == (2, 6)
    np.testing.assert_allclose(merged.max_pressure(np.array([A, B])), [0.25, 0.4])
    assert merged.max_angle_deg == pytest.approx(325.0)


def test_the_record_round_trips(two_designs):
    again = Support.from_dict(json.loads(json.dumps(two_designs.to_dict())))
    np.testing.assert_array_equal(again.designs, two_designs.designs)
    np.testing.assert_array_equal(again.max_pressure_mpa, two_designs.max_pressure_mpa)
    assert again.max_angle_deg == two_designs.max_angle_deg


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda d: d.pop("designs"), "lacks designs"),
        (lambda d: d.__setitem__("max_pressure_mpa", [0.2]), "one pressure per design"),
        (lambda d: d.__setitem__("max_angle_deg", "a lot"), "numbers only"),
        (lambda d: d.__setitem__("parameters", ["l_mm"]), "must be the parameters"),
        (lambda d: d["max_pressure_mpa"].__setitem__(0, -1.0), ">= 0 MPa"),
    ],
)
def test_a_broken_record_is_refused_on_load_naming_the_file(two_designs, tmp_path, change, message):
    X = np.array([[*A, 0.1], [*B, 0.2], [*A, 0.0], [*B, 0.0]])
    model = PolynomialRegressor(degree=1).fit(X, X[:, 6] * 900)
    record = two_designs.to_dict()
    change(record)
    path = save_surrogate(model, tmp_path / "m.json", metadata={"support": record})
    with pytest.raises(SchemaError, match=message) as err:
        load_surrogate(path)
    assert str(path) in str(err.value) and ": metadata.support" in str(err.value)


def test_predict_flags_a_pressure_past_the_design_s_sweep_and_strict_refuses(two_designs, tmp_path):
    X = np.vstack([_rows(A, 0.2)[0], _rows(B, 0.4)[0]])
    model = PolynomialRegressor(degree=1).fit(X, 1000 * X[:, 6])
    metadata = {"training_ranges": training_ranges(X), "support": two_designs.to_dict()}
    path = save_surrogate(model, tmp_path / "m.json", metadata=metadata)
    result = predict_angles(path, sfrba_design(*A), [0.1, 0.3])
    assert result.outside_training_ranges == []  # inside the box ...
    assert result.supported.tolist() == [True, False]  # ... but past A's sweep
    assert result.beyond_support and result.extrapolated == result.beyond_support
    payload = result.to_dict()
    assert payload["supported"] == [True, False] and payload["beyond_training_support"]
    with pytest.raises(ValueError, match=r"pressure 0\.3 MPa beyond"):
        predict_angles(path, sfrba_design(*A), [0.1, 0.3], strict=True)
    assert predict_angles(path, sfrba_design(*A), [0.1], strict=True).supported.tolist() == [True]


def test_strict_refuses_a_model_that_records_no_support(tmp_path):
    X = np.vstack([_rows(A, 0.2)[0], _rows(B, 0.4)[0]])
    model = PolynomialRegressor(degree=1).fit(X, 1000 * X[:, 6])
    path = save_surrogate(
        model, tmp_path / "m.json", metadata={"training_ranges": training_ranges(X)}
    )
    assert predict_angles(path, sfrba_design(*A), [0.1]).supported is None
    with pytest.raises(ValueError, match="records no training support"):
        predict_angles(path, sfrba_design(*A), [0.1], strict=True)


def test_the_shipped_mlp_refuses_the_long_design_past_its_sweep():
    # A 150 mm design inside the box at 0.3 MPa: the FEM of its neighbours stops near 0.13 MPa
    # (300°), and the MLP's curve runs on to about 580°.
    from importlib.resources import files

    path = files("softbend") / "data" / "transfer" / "table1_fem_mlp.json"
    design = sfrba_design(150, 8, 2, 2, 5, 8)
    result = predict_angles(path, design, [0.1, 0.3])
    assert result.outside_training_ranges == []
    assert result.supported.tolist() == [True, False]
    assert any("angle" in p for p in result.beyond_support)
    with pytest.raises(ValueError, match="beyond"):
        predict_angles(path, design, [0.3], strict=True)


def test_the_support_of_rows_is_each_distinct_design_in_order_with_its_largest_pressure():

    rng = np.random.default_rng(5)
    for _ in range(100):
        n, d = int(rng.integers(1, 60)), int(rng.integers(1, 5))
        scale = rng.choice([1.0, 0.5, -1.25], d)
        designs = rng.integers(-2, 3, (n, d)).astype(float) * scale  # repeats, ties, negatives
        X = np.column_stack([designs, rng.uniform(0.0, 0.3, n)])
        support = support_from_rows(X, np.ones(n), parameters=tuple(f"p{k}" for k in range(d)))
        # the definition: np.unique's distinct rows, each design's largest pressure
        unique, inverse = np.unique(designs, axis=0, return_inverse=True)
        largest = np.array([X[inverse.ravel() == k, -1].max() for k in range(len(unique))])
        assert np.array_equal(support.designs, unique)
        assert np.array_equal(support.max_pressure_mpa, largest)
