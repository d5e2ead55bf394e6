"""Identify a NARX/GG-SVR model of the curling actuator (paper A) from the Python API.

Five of the six synthetic positive-pressure experiments train the bending-grade
model; the sixth is held out and simulated free-run (the model feeds back its
own predictions), as a controller's internal model would be used.

Run: ``python examples/identify_curling_actuator.py``
"""

from __future__ import annotations

import numpy as np

from softbend.identification import NARXRegressor, synthetic_dataset
from softbend.metrics import regression_metrics


def main(seed: int = 0) -> dict[str, float]:
    """Fit on five experiments, simulate the sixth; return its free-run metrics."""
    experiments = synthetic_dataset(seed=seed)["positive"]
    train, test = experiments[:-1], experiments[-1]

    # Inputs are pressure in kPa; the output is the bending grade rho (1/L0 units,
    # dimensionless). ``groups`` keeps lags from spanning two experiments.
    X = np.concatenate([e.pressure_kpa for e in train])
    y = np.concatenate([e.rho for e in train])
    groups = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(train)])

    model = NARXRegressor().fit(X, y, groups=groups)  # GG-SVR, phi = [y(t-1), y(t-2), u(t), u(t-1)]
    svr = model.estimator_
    print(f"kernel: sigma = {svr.sigma_:.3f}, shape = {svr.shape_:.3f} (estimated)")

    free_run = model.simulate(test.pressure_kpa, test.rho)
    metrics = regression_metrics(test.rho, free_run)
    print(
        f"held-out {test.name}: free-run NRMSE {100 * metrics['nrmse']:.2f} %, "
        f"fit {metrics['fit_percent']:.1f} %"
    )
    return metrics


if __name__ == "__main__":
    main()
