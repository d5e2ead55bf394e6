"""Benchmark: where does the generalized-Gaussian kernel's shape pay? (paper A §4)

Held-out free-run NRMSE of NARX models of the synthetic curling actuator
(:func:`softbend.identification.synthetic.synthetic_dataset`, 6 experiments x 512
samples per pressure sign) in three scenarios:

- ``mixed``: paper A's layout (six profile kinds); the regressors are
  lighter-tailed than Gaussian;
- ``impulsive``: the ``"impulsive"`` excitation, the actuator held at an operating
  point with rare short pressure pulses; the regressors are heavy-tailed;
- ``backlash``: the mixed excitation on an actuator with wide rate-independent
  hysteresis (play radii 5/15/30 kPa, weights 0.25 each: a 12.5 kPa half-width
  instead of 1.7), whose NARX map has kinks at every reversal; a
  less smooth kernel (γ < 2) could pay there whatever the regressors' tails.

Models, all on paper A's regressor [y(t-1), y(t-2), u(t), u(t-1)] (standardized),
C = 100, epsilon = 0.1, leave-one-experiment-out (each held-out experiment is
predicted by models that never saw it; every choice below is made on the
training experiments only):

- ``gg-moments``: GeneralizedGaussianSVR, σ and shape by the fourth-moment method
  on the kernel's argument x - z (the default, ``moments_of="differences"``);
- ``gg-moments-regressors`` / ``gg-moments-components``: the same with the moments
  of the centred regressor vectors / of the pooled standardized components (the
  earlier default);
- ``gg-cv-shape``: GeneralizedGaussianSVR with σ by the moments (the pooled
  standard deviation, 1 on standardized regressors) and the shape chosen by
  grouped (leave-one-training-experiment-out) cross-validation of the one-step
  RMSE over shape in {0.5, 1, 1.5, 2};
- ``gg-cv``: GeneralizedGaussianSVR with (σ, shape) chosen by grouped
  (leave-one-training-experiment-out) cross-validation of the one-step RMSE over
  σ in {0.5, 1, 2} x shape in {0.5, 1, 1.5, 2};
- ``rbf-cv``: scikit-learn's SVR, RBF kernel, gamma = 1/(2σ²) chosen by the same
  grouped cross-validation over σ in {0.5, 1, 2}.

Printed: mean and worst free-run NRMSE (RMSE / range of the measured output) and
mean one-step NRMSE over signs x outputs x held-out experiments, and the shapes
each model used. Run::

    .venv/bin/python benchmarks/bench_gg_shape.py        # full: 6 folds x 2 signs (~23 min)
    .venv/bin/python benchmarks/bench_gg_shape.py --folds 1 --signs positive  # ~3 min

(times on a shared 2-core machine; the cross-validated models take nearly all of it).
"""

from __future__ import annotations

import argparse
import json
import time
import warnings

import numpy as np
from _record import record, table_figures
from sklearn.svm import SVR

from softbend.identification.kernels import ShapeClippedWarning
from softbend.identification.narx import NARXRegressor
from softbend.identification.svr import GeneralizedGaussianSVR
from softbend.identification.synthetic import CurlingActuator, synthetic_dataset
from softbend.metrics import nrmse

MODELS = (
    "gg-moments",
    "gg-moments-regressors",
    "gg-moments-components",
    "gg-cv-shape",
    "gg-cv",
    "rbf-cv",
)
SIGMAS = (0.5, 1.0, 2.0)
SHAPES = (0.5, 1.0, 1.5, 2.0)
OUTPUTS = ("rho", "length_mm")
SCENARIOS = ("mixed", "impulsive", "backlash")
BACKLASH = CurlingActuator(play_radii_kpa=(5.0, 15.0, 30.0), play_weights=(0.25, 0.25, 0.25))


def _dataset(scenario: str, seed: int):
    if scenario == "backlash":
        return synthetic_dataset(seed=seed, actuator=BACKLASH)
    return synthetic_dataset(seed=seed, excitation=scenario)


def _stack(experiments, output):
    u = np.concatenate([e.pressure_kpa for e in experiments])[:, None]
    y = np.concatenate([getattr(e, output) for e in experiments])
    groups = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(experiments)])
    return u, y, groups


def _fit(estimator, experiments, output):
    u, y, groups = _stack(experiments, output)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShapeClippedWarning)
        return NARXRegressor(estimator=estimator).fit(u, y, groups=groups)


def _one_step_rmse(model, experiment, output):
    u, y, groups = _stack([experiment], output)
    y_hat = model.predict_one_step(u, y, groups=groups)
    return float(np.sqrt(np.mean((y_hat - y)[model.max_lag_ :] ** 2)))


def _grouped_cv(make, grid, experiments, output):
    """The grid point with the lowest leave-one-experiment-out one-step RMSE."""
    best = None
    for point in grid:
        errors = []
        for k in range(len(experiments)):
            train = [e for i, e in enumerate(experiments) if i != k]
            errors.append(_one_step_rmse(_fit(make(*point), train, output), experiments[k], output))
        score = float(np.mean(errors))
        if best is None or score < best[0]:
            best = (score, point)
    return best[1]


def _gg(sigma=None, shape=None, moments_of="differences"):
    return GeneralizedGaussianSVR(
        C=100.0, epsilon=0.1, sigma=sigma, shape=shape, moments_of=moments_of
    )


def _rbf(sigma):
    return SVR(kernel="rbf", C=100.0, epsilon=0.1, gamma=1.0 / (2.0 * sigma**2))


def _model(name, train, output):
    """Fit model ``name`` on the training experiments; returns (model, kernel label)."""
    if name == "gg-moments":
        model = _fit(_gg(), train, output)
    elif name == "gg-moments-regressors":
        model = _fit(_gg(moments_of="regressors"), train, output)
    elif name == "gg-moments-components":
        model = _fit(_gg(moments_of="components"), train, output)
    elif name == "gg-cv-shape":
        sigma = _fit(_gg(), train, output).estimator_.sigma_
        (shape,) = _grouped_cv(lambda g: _gg(sigma, g), [(g,) for g in SHAPES], train, output)
        model = _fit(_gg(sigma, shape), train, output)
    elif name == "gg-cv":
        grid = [(s, g) for s in SIGMAS for g in SHAPES]
        sigma, shape = _grouped_cv(lambda s, g: _gg(s, g), grid, train, output)
        model = _fit(_gg(sigma, shape), train, output)
    else:
        (sigma,) = _grouped_cv(_rbf, [(s,) for s in SIGMAS], train, output)
        return _fit(_rbf(sigma), train, output), {"sigma": sigma, "shape": 2.0}
    inner = model.estimator_
    return model, {"sigma": inner.sigma_, "shape": inner.shape_}


def run(scenario: str, folds: int, seed: int, signs: tuple[str, ...]) -> dict:
    dataset = _dataset(scenario, seed)
    rows = {m: {"free": [], "one": [], "shapes": [], "fit_s": []} for m in MODELS}
    for sign in signs:
        experiments = dataset[sign]
        for output in OUTPUTS:
            for k in range(min(folds, len(experiments))):
                train = [e for i, e in enumerate(experiments) if i != k]
                held_out = experiments[k]
                u, y, groups = _stack([held_out], output)
                for name in MODELS:
                    start = time.perf_counter()
                    model, kernel = _model(name, train, output)
                    rows[name]["fit_s"].append(time.perf_counter() - start)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", RuntimeWarning)
                        free = model.simulate(u, y, groups=groups)
                    one = model.predict_one_step(u, y, groups=groups)
                    rows[name]["free"].append(nrmse(y[2:], free[2:]))
                    rows[name]["one"].append(nrmse(y[2:], one[2:]))
                    rows[name]["shapes"].append(round(kernel["shape"], 3))
    summary = {}
    for name, r in rows.items():
        free = np.asarray(r["free"], dtype=float)
        summary[name] = {
            "free_run_nrmse_pct": 100 * float(np.nanmean(free)),
            "free_run_nrmse_worst_pct": 100 * float(np.nanmax(free)),
            "one_step_nrmse_pct": 100 * float(np.mean(r["one"])),
            "diverged": int(np.sum(~np.isfinite(free))),
            "shapes": r["shapes"],
            "seconds": float(np.sum(r["fit_s"])),
            "n_heldout": int(free.size),
        }
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folds", type=int, default=6, help="held-out experiments per model")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--signs", nargs="+", default=["positive", "negative"])
    parser.add_argument("--scenarios", nargs="+", default=list(SCENARIOS), choices=SCENARIOS)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    results = {
        scenario: run(scenario, args.folds, args.seed, tuple(args.signs))
        for scenario in args.scenarios
    }
    columns = {
        "free_run_nrmse_pct": ("free-run NRMSE", "%"),
        "free_run_nrmse_worst_pct": ("worst free-run NRMSE", "%"),
        "one_step_nrmse_pct": ("one-step NRMSE", "%"),
        "diverged": ("diverged", ""),
    }
    figures, units = table_figures(
        {f"{sc}, {m}": r for sc, summary in results.items() for m, r in summary.items()}, columns
    )
    record(
        "gg_shape", figures, units=units, notes=f"{args.folds} folds, signs {', '.join(args.signs)}"
    )
    if args.json:
        print(json.dumps(results, indent=2))
        return
    for scenario, summary in results.items():
        n = next(iter(summary.values()))["n_heldout"]
        print(f"\nscenario={scenario}  ({n} held-out runs: signs x outputs x folds)")
        print(f"{'model':<24}{'free-run %':>11}{'worst %':>9}{'one-step %':>11}{'div':>5}  shapes")
        for name, s in summary.items():
            shapes = sorted(set(s["shapes"]))
            print(
                f"{name:<24}{s['free_run_nrmse_pct']:>11.2f}{s['free_run_nrmse_worst_pct']:>9.2f}"
                f"{s['one_step_nrmse_pct']:>11.2f}{s['diverged']:>5d}  {shapes}"
            )
    print("\n(NRMSE = RMSE / range of the measured output; free run = the model feeds back")
    print(" its own outputs from the first 2 measured samples of the held-out experiment)")


if __name__ == "__main__":
    main()
