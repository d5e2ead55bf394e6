"""Helpers shared by the CLI tests."""

import pytest

from softbend.design import sfrba_design


def one_error_line(capsys) -> str:
    """The single ``softbend: error: …`` line a failed command wrote to stderr."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("softbend: error: ")
    return err[0]


@pytest.fixture(scope="session")
def small_base_file(tmp_path_factory):
    """A small MLP on analytical sweeps, saved like a surrogate (the transfer CLI's base)."""
    import numpy as np

    from softbend.analytical import AnalyticalModel
    from softbend.models import default_pressures_mpa
    from softbend.surrogates.mlp import NormalizedMLPRegressor
    from softbend.surrogates.persistence import save_surrogate

    rows, angles = [], []
    for values in [
        (100, 6, 2, 2, 5, 8),
        (120, 6, 2, 2, 5, 8),
        (100, 8, 2, 2, 5, 8),
        (100, 6, 3, 2, 5, 8),
        (140, 8, 3, 3, 10, 10),
    ]:
        design = sfrba_design(*values)
        sweep = AnalyticalModel().sweep(design, default_pressures_mpa(0.15, 0.01))
        ok = np.asarray(sweep.converged, dtype=bool)
        rows.append(design.feature_rows(sweep.pressure_mpa[ok]))
        angles.append(sweep.angle_deg[ok])
    model = NormalizedMLPRegressor(
        hidden_sizes=(8, 8), epochs=100, batch_size=64, learning_rate=3e-3, device="cpu"
    )
    model.fit(np.vstack(rows), np.concatenate(angles))
    return save_surrogate(model, tmp_path_factory.mktemp("base") / "base.json")
