# A campaign swept in resumable shards, each committed when complete; sourced by a
# campaign's run.sh, which sets before it:
#
#   here         the campaign's folder (campaigns/NAME)
#   shards       how many shards
#   space        the array of `softbend campaign run` arguments that name the designs
#   merged       the merged database, not kept in git ($here/NAME.duckdb)
#   dataset      the package's dataset folder that `ship` writes
#   space_text   the whole design space, as `softbend campaign dataset --space` takes it
#   description  the dataset's one paragraph
#
# and then calls `shards_main "$@"`:
#
#   bash campaigns/NAME/run.sh shard K [WORKERS]   # sweep shard K (resumes)
#   bash campaigns/NAME/run.sh next [WORKERS]      # the first shard not yet complete
#   bash campaigns/NAME/run.sh ship                # every shard complete: merge, write the dataset
#
# Each shard is every N-th design of the space, written to shard-K-of-N.duckdb one
# transaction per design: a shard stopped at any point resumes where it stopped.
set -euo pipefail
softbend=${SOFTBEND:-.venv/bin/softbend}

shard_db() { echo "$here/shard-$1-of-$shards.duckdb"; }

run_shard() {
  local k=$1 workers=${2:-2}
  OMP_NUM_THREADS=1 "$softbend" campaign run "$(shard_db "$k")" \
    "${space[@]}" --shard "$k/$shards" --workers "$workers" \
    2>&1 | tee -a "$here/shard-$k-of-$shards.log"
}

complete() {  # shard K has every design recorded (done or failed)
  local db
  db=$(shard_db "$1")
  [ -f "$db" ] || return 1
  "$softbend" campaign status "$db" --json 2>/dev/null | python3 -c '
import json, sys
s = json.load(sys.stdin)
sys.exit(0 if s["done"] + s["failed"] == s["n_designs_planned"] else 1)'
}

ship() {  # the dataset is the whole space or nothing
  local files=() k
  for k in $(seq 0 $((shards - 1))); do
    complete "$k" || { echo "shard $k of $shards is not complete" >&2; exit 2; }
    files+=("$(shard_db "$k")")
  done
  local command="softbend campaign run $here/shard-K-of-$shards.duckdb ${space[*]} --shard K/$shards (K = 0..$((shards - 1))); softbend campaign merge $merged $here/shard-*-of-$shards.duckdb; softbend campaign dataset $merged --out $dataset --space $space_text"
  rm -f "$merged"
  "$softbend" campaign merge "$merged" "${files[@]}"
  # written beside, then put in the package's place: the dataset it replaces is git's
  local staged=$here/dataset.new
  rm -rf "$staged"
  "$softbend" campaign dataset "$merged" --out "$staged" --space "$space_text" \
    --command "$command" --description "$description"
  rm -f "$staged/.softbend-manifest.json"
  rm -rf "$dataset"
  mv "$staged" "$dataset"
}

shards_main() {
  case "${1:-}" in
    shard) run_shard "$2" "${3:-2}" ;;
    next)
      local k
      for k in $(seq 0 $((shards - 1))); do
        if ! complete "$k"; then run_shard "$k" "${2:-2}"; exit 0; fi
      done
      echo "all $shards shards complete" ;;
    ship) ship ;;
    *) sed -n 2,12p "$0"; exit 2 ;;
  esac
}
