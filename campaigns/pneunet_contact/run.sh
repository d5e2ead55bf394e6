#!/usr/bin/env bash
# The PneuNet dataset with wall-to-wall contact (softbend.datasets' pneunet, again), in 16 shards.
#
#   bash campaigns/pneunet_contact/run.sh shard K [WORKERS]   # sweep shard K of 16 (resumes)
#   bash campaigns/pneunet_contact/run.sh next [WORKERS]      # the first shard not yet complete
#   bash campaigns/pneunet_contact/run.sh ship                # merge complete shards, write the dataset
#
# The same seeded Sobol sample as the contact-free dataset (256 designs, seed 0),
# each swept with --contact on from 0 to 50 kPa or 180 degrees (about 35 CPU s
# for the reference design on one thread). Each shard is every 16th design,
# written to shard-K-of-16.duckdb one transaction per design: a shard stopped
# at any point resumes where it stopped. 'ship' merges the complete shards
# into pneunet_contact.duckdb (not kept in git) and writes the package's
# dataset src/softbend/data/pneunet (Parquet, provenance, checksums).
set -euo pipefail
cd "$(dirname "$0")/../.."
here=campaigns/pneunet_contact
softbend=${SOFTBEND:-.venv/bin/softbend}
shards=16
space=(--family pneunet --space sobol:256 --seed 0 --contact on)
command="softbend campaign run $here/shard-K-of-$shards.duckdb ${space[*]} --shard K/$shards (K = 0..$((shards - 1))); softbend campaign merge $here/pneunet_contact.duckdb $here/shard-*-of-$shards.duckdb; softbend campaign dataset $here/pneunet_contact.duckdb --out src/softbend/data/pneunet --space sobol:256"

run_shard() {
  local k=$1 workers=${2:-2}
  OMP_NUM_THREADS=1 "$softbend" campaign run "$here/shard-$k-of-$shards.duckdb" \
    "${space[@]}" --shard "$k/$shards" --workers "$workers" \
    2>&1 | tee -a "$here/shard-$k-of-$shards.log"
}

complete() {  # shard K has all its designs done
  local db="$here/shard-$1-of-$shards.duckdb"
  [ -f "$db" ] || return 1
  "$softbend" campaign status "$db" --json 2>/dev/null | python3 -c '
import json, sys
s = json.load(sys.stdin)
sys.exit(0 if s["done"] + s["failed"] == s["n_designs_planned"] else 1)'
}

case "${1:-}" in
  shard) run_shard "$2" "${3:-2}" ;;
  next)
    for k in $(seq 0 $((shards - 1))); do
      if ! complete "$k"; then run_shard "$k" "${2:-2}"; exit 0; fi
    done
    echo "all $shards shards complete" ;;
  ship)  # every shard complete: the dataset is the whole sample or nothing
    shard_files=()
    for k in $(seq 0 $((shards - 1))); do
      complete "$k" || { echo "shard $k of $shards is not complete" >&2; exit 2; }
      shard_files+=("$here/shard-$k-of-$shards.duckdb")
    done
    rm -f "$here/pneunet_contact.duckdb"
    "$softbend" campaign merge "$here/pneunet_contact.duckdb" "${shard_files[@]}"
    "$softbend" campaign dataset "$here/pneunet_contact.duckdb" --out src/softbend/data/pneunet \
      --space sobol:256 --command "$command" \
      --description "256 PneuNets (softbend's pneunet family; a scrambled Sobol sample, seed 0) swept by softbend's 3D FEM with the family's default options and frictionless penalty contact between the facing walls of neighbouring chambers, 0 to 50 kPa in 1 kPa outputs, each sweep ending at the last pressure, 180 degrees or where Newton stops converging." ;;
  *) sed -n 2,14p "$0"; exit 2 ;;
esac
