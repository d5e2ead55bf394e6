import numpy as np
import pandas as pd
import pytest

from softbend.errors import DatasetError
from softbend.surrogates.features import FEATURES, check_features, data_hash, training_data


def _samples(n_designs: int = 3, n_p: int = 4) -> pd.DataFrame:
    rows = []
    for d in range(n_designs):
        for k in range(n_p):
            rows.append(
                {
                    "design_id": f"d{d}",
                    "l_mm": 100.0 + d,
                    "r_mm": 6.0,
                    "t_mm": 2.0,
                    "b_mm": 2.0,
                    "phi_deg": 5.0,
                    "lc_mm": 8.0,
                    "pressure_mpa": 0.01 * k,
                    "angle_deg": 10.0 * k + d,
                    "converged": True,
                }
            )
    return pd.DataFrame(rows)


def test_columns_in_feature_order_and_groups_by_design():
    df = _samples()
    data = training_data(df.sample(frac=1.0, random_state=0)[::-1])
    assert data.X.shape == (12, len(FEATURES))
    assert data.n_groups == 3 and data.n_dropped == 0
    # Column 0 is l_mm, column 6 the pressure, whatever the table's column order.
    for x, y, g in zip(data.X, data.y, data.groups, strict=True):
        d = int(g[1:])
        assert x[0] == 100.0 + d
        assert y == pytest.approx(1000.0 * x[6] + d)


def test_unconverged_and_non_finite_rows_are_dropped_and_counted():
    df = _samples()
    df.loc[1, "converged"] = False
    df.loc[2, "angle_deg"] = np.nan
    df.loc[3, "t_mm"] = np.inf
    data = training_data(df)
    assert data.n_samples == 9 and data.n_dropped == 3
    assert training_data(df, converged_only=False).n_samples == 10


def test_missing_column_names_it():
    with pytest.raises(DatasetError, match=r"lacks the column.*phi_deg"):
        training_data(_samples().drop(columns="phi_deg"))


def test_no_usable_row_is_an_error():
    df = _samples()
    df["converged"] = False
    with pytest.raises(DatasetError, match="no converged row"):
        training_data(df)


def test_hash_is_stable_and_sensitive():
    X = np.arange(14.0).reshape(2, 7)
    y = np.array([1.0, 2.0])
    assert data_hash(X, y, ["a", "b"]) == data_hash(X.copy(), y.copy(), ["a", "b"])
    assert data_hash(X, y, ["a", "b"]) != data_hash(X, y + 1e-12, ["a", "b"])
    assert data_hash(X, y, ["a", "b"]) != data_hash(X, y, ["a", "c"])


def test_check_features_accepts_one_sample_and_names_bad_input():
    assert check_features(np.ones(7)).shape == (1, 7)
    with pytest.raises(ValueError, match="X: must have 7 columns"):
        check_features(np.ones((3, 6)))
    x = np.ones((2, 7))
    x[1, 6] = np.nan
    with pytest.raises(ValueError, match="'pressure_mpa' of row 1"):
        check_features(x)


@pytest.mark.parametrize(
    "groups",
    [
        None,
        np.array(["d1", "d2"] * 10, dtype=object),
        np.array(["d1", "dé"] * 10),  # NumPy's own strings
        np.arange(20),  # numbers: their text
        np.array([1.5, "x"] * 10, dtype=object),  # mixed: each one's text
    ],
)
def test_the_data_hash_is_its_definition_whatever_the_arrays_layout(groups):
    """SHA-256 of X's and y's float64 bytes in C order and the labels' text joined by \\x1f:
    the hash every saved model records, so it may never change."""
    import hashlib

    rng = np.random.default_rng(3)
    X = rng.normal(size=(3, 20)).T  # not C-contiguous
    y = rng.normal(size=40)[::2].astype(np.float32)  # strided, another dtype
    digest = hashlib.sha256()
    digest.update(np.ascontiguousarray(X, dtype=np.float64).tobytes())
    digest.update(np.ascontiguousarray(y, dtype=np.float64).tobytes())
    if groups is not None:
        digest.update("\x1f".join(str(g) for g in np.asarray(groups).tolist()).encode())
    assert data_hash(X, y, groups) == digest.hexdigest()[:16]
    # a pinned value, computed before the hash read the arrays' buffers without copies
    assert data_hash(np.zeros((2, 2)), np.zeros(2), ["a", "b"]) == "a5103c81b199711f"
