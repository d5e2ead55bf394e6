"""Benchmark: NARX identification of the (synthetic) curling actuator, four model families.

Same data (``synthetic_dataset(seed)``: 6 x 512 samples per pressure sign), same
held-out experiments (leave-one-experiment-out), same regressor
[y(t-1), y(t-2), u(t), u(t-1)], for

- ``gg-svr``: softbend's generalized-Gaussian SVR, σ and shape by the moment method
  (paper A), C = 100, ε = 0.1 (standardized output);
- ``rbf-svr``: scikit-learn SVR, RBF kernel, C = 100, ε = 0.1, gamma tuned by
  3-fold contiguous (unshuffled) cross-validation of the one-step error on the
  training experiments only;
- ``linear-arx``: least-squares linear ARX (same regressor);
- ``sysidentpy``: SysIdentPy's polynomial NARX (degree 2) with FROLS term selection
  (AIC), the established peer. SysIdentPy has no current-input term, so its input
  series is shifted by one sample to give it u(t) and u(t-1); it fits one series,
  so the training experiments are concatenated (a few rows at each boundary mix
  experiments).

Printed per model (mean over 2 signs x 2 outputs x held-out experiments): one-step
and free-run NRMSE (RMSE / range of the measured output), worst free-run NRMSE,
fit time per model, and single-step prediction latency (one regressor vector, the
call a control loop or free-run simulation makes). Run::

    .venv/bin/python benchmarks/bench_identification.py            # all 6 folds
    .venv/bin/python benchmarks/bench_identification.py --folds 2  # quicker
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np
from _record import record, table_figures
from sklearn.linear_model import LinearRegression
from sklearn.model_selection import GridSearchCV, KFold
from sklearn.svm import SVR

from softbend.identification.kernels import ShapeClippedWarning
from softbend.identification.narx import NARXRegressor
from softbend.identification.svr import GeneralizedGaussianSVR
from softbend.identification.synthetic import synthetic_dataset
from softbend.metrics import nrmse

MODELS = ("gg-svr", "rbf-svr", "linear-arx", "sysidentpy")
GAMMAS = (0.03, 0.1, 0.3, 1.0, 3.0)


def _stack(experiments, output):
    u = np.concatenate([e.pressure_kpa for e in experiments])[:, None]
    y = np.concatenate([getattr(e, output) for e in experiments])
    groups = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(experiments)])
    return u, y, groups


def _latency_us(call, repeats=2000):
    call()
    best = np.inf
    for _ in range(5):
        start = time.perf_counter()
        for _ in range(repeats):
            call()
        best = min(best, (time.perf_counter() - start) / repeats)
    return best * 1e6


class _NarxAdapter:
    """Fit/predict interface shared by the softbend-based models."""

    def __init__(self, name):
        if name == "gg-svr":
            estimator = GeneralizedGaussianSVR(C=100.0, epsilon=0.1)
        elif name == "rbf-svr":
            estimator = GridSearchCV(
                SVR(kernel="rbf", C=100.0, epsilon=0.1),
                {"gamma": list(GAMMAS)},
                cv=KFold(3),
                scoring="neg_root_mean_squared_error",
            )
        else:
            estimator = LinearRegression()
        self.name = name
        self.model = NARXRegressor(estimator=estimator)

    def fit(self, experiments, output):
        u, y, groups = _stack(experiments, output)
        self.model.fit(u, y, groups=groups)
        return self

    def predict(self, experiment, output):
        u, y, groups = _stack([experiment], output)
        return (
            self.model.predict_one_step(u, y, groups=groups),
            self.model.simulate(u, y, groups=groups),
        )

    def single_step_call(self):
        inner = self.model.estimator_
        x = np.zeros(len(self.model.regressor_names_))
        if self.name == "gg-svr":
            predict_one = inner.predictor()
            return lambda: predict_one(x)
        row = x[None, :]
        return lambda: inner.predict(row)


class _SysIdentPyAdapter:
    name = "sysidentpy"

    def __init__(self):
        from sysidentpy.basis_function import Polynomial
        from sysidentpy.model_structure_selection import FROLS
        from sysidentpy.parameter_estimation import LeastSquares

        self.model = FROLS(
            ylag=2,
            xlag=2,
            order_selection=True,
            info_criteria="aic",
            n_info_values=15,
            estimator=LeastSquares(),
            basis_function=Polynomial(degree=2),
            model_type="NARMAX",  # FROLS fits no noise terms: this is a polynomial NARX
        )

    @staticmethod
    def _shifted(u):
        # x'(k) = u(k+1): SysIdentPy's x'(k-1), x'(k-2) are then u(k), u(k-1).
        return np.concatenate([u[1:], u[-1:]])

    def fit(self, experiments, output):
        u, y, _ = _stack(experiments, output)
        self.model.fit(X=self._shifted(u), y=y[:, None])
        return self

    def predict(self, experiment, output):
        u, y, _ = _stack([experiment], output)
        x = self._shifted(u)
        one_step = self.model.predict(X=x, y=y[:, None], steps_ahead=1).ravel()
        free_run = self.model.predict(X=x, y=y[:2, None]).ravel()
        return one_step[: y.size], free_run[: y.size]

    def single_step_call(self):
        return None


def _make(name):
    return _SysIdentPyAdapter() if name == "sysidentpy" else _NarxAdapter(name)


def run(folds: int, seed: int) -> dict[str, dict[str, float]]:
    dataset = synthetic_dataset(seed=seed)
    results: dict[str, dict[str, list[float]]] = {
        m: {"one": [], "free": [], "fit_s": [], "latency_us": []} for m in MODELS
    }
    for _sign, experiments in dataset.items():
        for output in ("rho", "length_mm"):
            for k in range(min(folds, len(experiments))):
                train = [e for i, e in enumerate(experiments) if i != k]
                held_out = experiments[k]
                measured = getattr(held_out, output)
                for name in MODELS:
                    model = _make(name)
                    start = time.perf_counter()
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", ShapeClippedWarning)
                        model.fit(train, output)
                    results[name]["fit_s"].append(time.perf_counter() - start)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", RuntimeWarning)
                        one_step, free_run = model.predict(held_out, output)
                    results[name]["one"].append(nrmse(measured[2:], one_step[2:]))
                    results[name]["free"].append(nrmse(measured[2:], free_run[2:]))
                    call = model.single_step_call()
                    if call is not None and k == 0:
                        results[name]["latency_us"].append(_latency_us(call))
    summary = {}
    for name, r in results.items():
        free = np.asarray(r["free"], dtype=float)
        summary[name] = {
            "one_step_nrmse_pct": 100 * float(np.mean(r["one"])),
            "free_run_nrmse_pct": 100 * float(np.nanmean(free)),
            "free_run_nrmse_worst_pct": 100 * float(np.nanmax(free)),
            "diverged_runs": int(np.sum(~np.isfinite(free))),
            "fit_s": float(np.mean(r["fit_s"])),
            "single_step_us": float(np.median(r["latency_us"])) if r["latency_us"] else None,
            "n_heldout": int(free.size),
        }
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folds", type=int, default=6, help="held-out experiments per group")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    summary = run(args.folds, args.seed)
    columns = {
        "one_step_nrmse_pct": ("one-step NRMSE", "%"),
        "free_run_nrmse_pct": ("free-run NRMSE", "%"),
        "free_run_nrmse_worst_pct": ("worst free-run NRMSE", "%"),
        "diverged_runs": ("diverged runs", ""),
        "fit_s": ("fit", "s"),
        "single_step_us": ("single step", "µs"),
    }
    figures, units = table_figures(summary, columns)
    record(
        "identification",
        figures,
        units=units,
        notes=f"{args.folds} folds, seed {args.seed}; "
        f"mean over {summary['gg-svr']['n_heldout']} held-out runs",
    )
    if args.json:
        print(json.dumps(summary, indent=2))
        return
    header = (
        f"{'model':<12}{'one-step %':>11}{'free-run %':>11}{'worst %':>9}"
        f"{'diverged':>9}{'fit s':>8}{'1-step µs':>11}"
    )
    print(header)
    for name, s in summary.items():
        latency = f"{s['single_step_us']:.1f}" if s["single_step_us"] is not None else "n/a"
        print(
            f"{name:<12}{s['one_step_nrmse_pct']:>11.2f}{s['free_run_nrmse_pct']:>11.2f}"
            f"{s['free_run_nrmse_worst_pct']:>9.2f}{s['diverged_runs']:>9d}"
            f"{s['fit_s']:>8.2f}{latency:>11}"
        )
    print(f"(NRMSE = RMSE / range; mean over {summary['gg-svr']['n_heldout']} held-out runs)")


if __name__ == "__main__":
    main()
