"""Benchmark: fit time, memory and single-step latency of the GG-SVR (paper A §4).

Three measurements, each printed:

1. **Fit time on paper A's data**: the 3 060 NARX rows x 4 standardized
   regressors of the synthetic curling actuator (6 experiments x 512 samples,
   positive pressure, output ρ), C = 100, ε = 0.1, σ = 1. softbend's
   ``GeneralizedGaussianSVR`` at shape 2 (LIBSVM's RBF kernel) and at shape 1.5
   (active-set solver), against scikit-learn's ``SVR(kernel="rbf",
   gamma=1/(2σ²), C=c·C)``, the same model as shape 2 (c the kernel's density
   normalization). Best of ``--repeats`` interleaved runs each; the ratio is
   best/best. The agreement of the predictions with the reference (the RBF SVR,
   or LIBSVM on the dense precomputed Gram matrix at shape 1.5) is printed too.
2. **Peak memory of a large fit**: ``--rows`` rows (default 60 000: 10 minutes at
   100 Hz) of the synthetic actuator (positive pressure, ρ, 6 experiments at
   100 Hz), fitted in a fresh subprocess at shapes 2 and 1.5; its peak resident
   memory (``ru_maxrss``) minus that of the same process before the fit, and the
   fit's wall time. A dense Gram matrix would need 8·n² bytes (28.8 GB at 60 000).
3. **Single-step prediction latency** (the ``predictor()`` fast path, the call of free-run
   simulation and control loops), best of 5 x 2 000 calls, on the paper-A model.

Run::

    .venv/bin/python benchmarks/bench_gg_svr.py                       # all, 60 000 rows
    .venv/bin/python benchmarks/bench_gg_svr.py --rows 12000 --repeats 5  # quicker
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
import warnings

import numpy as np
from _record import record, table_figures

from softbend.identification.kernels import ShapeClippedWarning, gg_normalization
from softbend.identification.narx import lagged_matrix
from softbend.identification.synthetic import synthetic_dataset

warnings.simplefilter("ignore", ShapeClippedWarning)


def narx_rows(
    n_samples: int, dt_s: float, excitation: str = "mixed"
) -> tuple[np.ndarray, np.ndarray]:
    """Standardized NARX rows [y(t-1), y(t-2), u(t), u(t-1)] -> ρ(t), positive pressure."""
    experiments = synthetic_dataset(
        n_experiments=6, n_samples=n_samples, dt_s=dt_s, seed=0, excitation=excitation
    )
    group = experiments["positive"]
    u = np.concatenate([e.pressure_kpa for e in group])
    y = np.concatenate([e.rho for e in group])
    labels = np.concatenate([np.full(e.n_samples, i) for i, e in enumerate(group)])
    u = (u - u.mean()) / u.std()
    y = (y - y.mean()) / y.std()
    X, target, _ = lagged_matrix(u, y, labels)
    return X, target


def _best(call, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return best


def fit_times(repeats: int) -> dict:
    from sklearn.svm import SVR

    from softbend.identification.kernels import generalized_gaussian_kernel
    from softbend.identification.svr import GeneralizedGaussianSVR

    X, y = narx_rows(512, 0.02)
    c = gg_normalization(1.0, 2.0)
    sklearn_rbf = SVR(kernel="rbf", gamma=0.5, C=100.0 * c, epsilon=0.1)
    gg2 = GeneralizedGaussianSVR(sigma=1.0, shape=2.0)
    gg15 = GeneralizedGaussianSVR(sigma=1.0, shape=1.5)
    times = {"sklearn-rbf": np.inf, "gg-2": np.inf, "gg-1.5": np.inf}
    for _ in range(repeats):  # interleaved, so that a load change hits all three
        times["sklearn-rbf"] = min(times["sklearn-rbf"], _best(lambda: sklearn_rbf.fit(X, y), 1))
        times["gg-2"] = min(times["gg-2"], _best(lambda: gg2.fit(X, y), 1))
        times["gg-1.5"] = min(times["gg-1.5"], _best(lambda: gg15.fit(X, y), 1))
    X_test = X[::5] + 0.01
    # Dense reference at 1.5: LIBSVM on the full precomputed Gram matrix (what fit did before).
    gram = generalized_gaussian_kernel(X, sigma=1.0, shape=1.5)
    start = time.perf_counter()
    dense = SVR(kernel="precomputed", C=100.0, epsilon=0.1).fit(gram, y)
    dense_s = time.perf_counter() - start
    dense_pred = dense.predict(generalized_gaussian_kernel(X_test, X, sigma=1.0, shape=1.5))
    return {
        "rows": int(X.shape[0]),
        "sklearn_rbf_s": times["sklearn-rbf"],
        "gg2_s": times["gg-2"],
        "gg15_s": times["gg-1.5"],
        "ratio_gg2": times["gg-2"] / times["sklearn-rbf"],
        "ratio_gg15": times["gg-1.5"] / times["sklearn-rbf"],
        "dense_solve_only_gg15_s": dense_s,
        "n_support": {
            "sklearn-rbf": int(sklearn_rbf.support_.size),
            "gg-2": gg2.n_support_,
            "gg-1.5": gg15.n_support_,
            "dense-1.5": int(dense.support_.size),
        },
        "max_abs_diff_gg2_vs_rbf": float(
            np.max(np.abs(gg2.predict(X_test) - sklearn_rbf.predict(X_test)))
        ),
        "max_abs_diff_gg15_vs_dense": float(np.max(np.abs(gg15.predict(X_test) - dense_pred))),
        "target_range": float(np.ptp(y)),
        "_model": gg2,
    }


_CHILD = r"""
import json, resource, sys, time, warnings
import numpy as np
from softbend.identification.svr import GeneralizedGaussianSVR
warnings.simplefilter("ignore")
data = np.load({path!r})
X, y = data["X"], data["y"]
GeneralizedGaussianSVR(sigma=1.0, shape={shape}).fit(X[:200], y[:200])  # imports warmed up
page = resource.getpagesize()
with open("/proc/self/statm") as statm:
    current = int(statm.read().split()[1]) * page / 1024  # resident now, KiB
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
model = GeneralizedGaussianSVR(sigma=1.0, shape={shape}).fit(X, y)
seconds = time.perf_counter() - start
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({{"rows": int(X.shape[0]), "seconds": seconds, "n_support": model.n_support_,
                  "rss_before_fit_mib": current / 1024, "rss_peak_mib": after / 1024,
                  "fit_adds_at_most_mib": (after - current) / 1024}}))
"""


def large_fit(rows: int, shapes: tuple[float, ...], excitation: str = "mixed") -> dict:
    """Fit ``rows`` NARX rows in a fresh process per shape; peak RSS from ``ru_maxrss``.

    ``fit_adds_at_most_mib`` is the process's peak minus its resident memory just
    before the fit: an upper bound of what the fit needs (the peak may have been
    set earlier, by the imports).
    """
    import tempfile
    from pathlib import Path

    # 6 experiments at 100 Hz; 2 initial conditions each
    X, y = narx_rows(rows // 6 + 2, 0.01, excitation)
    results = {}
    with tempfile.TemporaryDirectory() as folder:
        path = str(Path(folder) / "rows.npz")
        np.savez(path, X=X, y=y)
        for shape in shapes:
            done = subprocess.run(
                [sys.executable, "-c", _CHILD.format(path=path, shape=shape)],
                capture_output=True,
                text=True,
                check=True,
                timeout=3600,
            )
            result = json.loads(done.stdout.strip().splitlines()[-1])
            result["dense_gram_gib"] = 8 * result["rows"] ** 2 / 2**30
            results[str(shape)] = result
    return results


def latency_us(model) -> float:
    x = np.zeros(model.n_features_in_)
    predict_one = model.predictor()
    predict_one(x)
    return 1e6 * min(
        _best(lambda: [predict_one(x) for _ in range(2000)], 1) / 2000 for _ in range(5)
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=60_000, help="rows of the large fit")
    parser.add_argument("--repeats", type=int, default=15, help="interleaved fit timings")
    parser.add_argument("--skip-large", action="store_true")
    parser.add_argument(
        "--excitation",
        default="mixed",
        choices=("mixed", "impulsive"),
        help="excitation of the large fit's data",
    )
    parser.add_argument(
        "--shapes", type=float, nargs="+", default=[2.0, 1.5], help="shapes of the large fit"
    )
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    fits = fit_times(args.repeats)
    model = fits.pop("_model")
    report = {"fit_paper_a": fits, "predict_one_us": latency_us(model)}
    if not args.skip_large:
        report["large_fit"] = large_fit(args.rows, tuple(args.shapes), args.excitation)
    figures = {
        f"paper A fit, {label}": round(1e3 * fits[key], 1)
        for label, key in (
            ("scikit-learn SVR rbf", "sklearn_rbf_s"),
            ("GG-SVR shape 2", "gg2_s"),
            ("GG-SVR shape 1.5", "gg15_s"),
        )
    }
    units = dict.fromkeys(figures, "ms")
    figures["single-step prediction"], units["single-step prediction"] = (
        round(report["predict_one_us"], 2),
        "µs",
    )
    large = {f"large fit, shape {k}": v for k, v in report.get("large_fit", {}).items()}
    columns = {
        "rows": ("rows", ""),
        "seconds": ("wall time", "s"),
        "rss_peak_mib": ("process peak RSS", "MiB"),
        "fit_adds_at_most_mib": ("fit adds at most", "MiB"),
    }
    more, more_units = table_figures(large, columns, digits=1)
    record("gg_svr", {**figures, **more}, units={**units, **more_units}, notes=args.excitation)
    if args.json:
        print(json.dumps(report, indent=2))
        return
    f, n_sv = fits, fits["n_support"]
    print(f"paper A's data: {f['rows']} rows x 4, C = 100, eps = 0.1, sigma = 1")
    print(f"  (best of {args.repeats} interleaved fits; target range {f['target_range']:.2f})")
    rows = [
        ("scikit-learn SVR rbf", f["sklearn_rbf_s"], 1.0, n_sv["sklearn-rbf"], ""),
        (
            "GG-SVR shape 2 (rbf)",
            f["gg2_s"],
            f["ratio_gg2"],
            n_sv["gg-2"],
            f"max |diff| vs rbf {f['max_abs_diff_gg2_vs_rbf']:.1e}",
        ),
        (
            "GG-SVR shape 1.5",
            f["gg15_s"],
            f["ratio_gg15"],
            n_sv["gg-1.5"],
            f"max |diff| vs dense Gram {f['max_abs_diff_gg15_vs_dense']:.1e}",
        ),
    ]
    for name, seconds, ratio, n_support, note in rows:
        print(f"  {name:<22}{1e3 * seconds:8.1f} ms  x{ratio:5.2f}  n_SV {n_support:<5d} {note}")
    dense_ms = 1e3 * f["dense_solve_only_gg15_s"]
    print(f"  (LIBSVM on the dense Gram at shape 1.5, solve only: {dense_ms:.1f} ms)")
    print(f"single-step prediction (predict_one): {report['predict_one_us']:.2f} µs")
    for shape, r in report.get("large_fit", {}).items():
        print(
            f"large fit ({args.excitation}), shape {shape}: {r['rows']} rows in "
            f"{r['seconds']:.1f} s, n_SV {r['n_support']}, process peak RSS "
            f"{r['rss_peak_mib']:.0f} MiB (the fit: at most {r['fit_adds_at_most_mib']:.0f} MiB "
            f"over the {r['rss_before_fit_mib']:.0f} MiB before it; a dense Gram: "
            f"{r['dense_gram_gib']:.1f} GiB)"
        )


if __name__ == "__main__":
    main()
