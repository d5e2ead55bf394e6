#!/usr/bin/env bash
# The Table 1 FEM campaign behind softbend.datasets.table1_fem(), in 8 shards.
#
#   bash campaigns/table1_fem/run.sh shard K [WORKERS]   # sweep shard K of 8 (resumes)
#   bash campaigns/table1_fem/run.sh next [WORKERS]      # the first shard not yet complete
#   bash campaigns/table1_fem/run.sh ship                # merge complete shards, write the dataset
#
# Each shard is every 8th design of Table 1 (122 or 121 designs, about 20 CPU
# minutes per 60 designs), written to shard-K-of-8.duckdb one transaction per
# design: a shard killed at any point resumes where it stopped. 'ship' merges
# the shards into table1_fem.duckdb (not kept in git) and writes the package's
# dataset src/softbend/data/table1_fem (Parquet, provenance, checksums).
set -euo pipefail
cd "$(dirname "$0")/../.."
here=campaigns/table1_fem
softbend=${SOFTBEND:-.venv/bin/softbend}
shards=8
command="softbend campaign run $here/shard-K-of-$shards.duckdb --space table1 --backend fem --shard K/$shards (K = 0..$((shards - 1))); softbend campaign merge $here/table1_fem.duckdb $here/shard-*-of-$shards.duckdb; softbend campaign dataset $here/table1_fem.duckdb --out src/softbend/data/table1_fem --space table1"

run_shard() {
  local k=$1 workers=${2:-2}
  OMP_NUM_THREADS=1 "$softbend" campaign run "$here/shard-$k-of-$shards.duckdb" \
    --space table1 --backend fem --shard "$k/$shards" --workers "$workers" \
    2>&1 | tee -a "$here/shard-$k-of-$shards.log"
}

complete() {  # shard K has all its designs done
  local db="$here/shard-$1-of-$shards.duckdb"
  [ -f "$db" ] || return 1
  "$softbend" campaign status "$db" --json 2>/dev/null | python3 -c '
import json, sys
s = json.load(sys.stdin)
sys.exit(0 if s["done"] == s["n_designs_planned"] else 1)'
}

case "${1:-}" in
  shard) run_shard "$2" "${3:-2}" ;;
  next)
    for k in $(seq 0 $((shards - 1))); do
      if ! complete "$k"; then run_shard "$k" "${2:-2}"; exit 0; fi
    done
    echo "all $shards shards complete" ;;
  ship)  # the complete shards only (one still running holds its database's lock)
    done_shards=()
    for k in $(seq 0 $((shards - 1))); do
      if complete "$k"; then done_shards+=("$here/shard-$k-of-$shards.duckdb"); fi
    done
    [ ${#done_shards[@]} -gt 0 ] || { echo "no complete shard to ship" >&2; exit 2; }
    rm -f "$here/table1_fem.duckdb"
    "$softbend" campaign merge "$here/table1_fem.duckdb" "${done_shards[@]}"
    "$softbend" campaign dataset "$here/table1_fem.duckdb" --out src/softbend/data/table1_fem \
      --space table1 --command "$command" \
      --description "Paper B Table 1 (972 designs) swept by softbend's 3D FEM with its default options, 0 to 0.5 MPa in 0.005 MPa outputs, each sweep ending at the last pressure, 300 degrees, the stretch limit of the material model or an inflation instability." ;;
  *) sed -n 2,13p "$0"; exit 2 ;;
esac
