#!/usr/bin/env bash
# The GPU checks of the batched MLP trainer in one run, for a machine with one CUDA GPU
# and a Python that has torch, numpy, scikit-learn, pandas, pyarrow and pytest (softbend
# is used from src/, nothing is installed). Each part has its own time limit, so that a
# slow part does not cost the others; output goes to the terminal and to LOG.
#   bash benchmarks/bench_mlp_gpu.sh [LOG]
set -uo pipefail
cd "$(dirname "$0")/.."
LOG=${1:-bench_mlp_gpu.log}
PY=${PYTHON:-python3}
export PYTHONPATH=src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
{
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  $PY -c "import torch; print('torch', torch.__version__, 'CUDA', torch.version.cuda)"
  echo "== GPU equivalence tests (the test suite's conftest needs DuckDB: not loaded)"
  timeout 100 $PY -m pytest -q --noconftest -p no:cacheprovider -m "slow or not slow" \
    tests/surrogates/test_batched.py -k "cuda"
  echo "== training paths, paper grid (121 x 5 folds) on the shipped FEM data"
  timeout 300 $PY benchmarks/bench_mlp_search.py --fem --configs 121 --epochs 10 --device cuda \
    --variants "${VARIANTS:-host+nograph,device+nograph,device+graph,device+graph+tf32,device+graph+compile,device+graph+compile+tf32}" --json
  echo "== the exhaustive paper-grid search and refit, 1000 epochs"
  for precision in ${SEARCHES:-fp32 tf32}; do
    flags=$([ "$precision" = tf32 ] && echo --tf32)
    timeout 160 $PY benchmarks/bench_mlp_search.py --search --device cuda $flags
  done
} 2>&1 | tee "$LOG"
