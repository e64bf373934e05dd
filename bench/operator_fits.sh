#!/usr/bin/env bash
# Speed bar of the differential-operator fits: `hysid identify operator --family F` on the
# 20 000-sample records of crates/hysid/examples/differential_records.rs (each family's own
# operator, 40 dB output noise), whole process, for bouc-wen, duhem, dahl and jiles-atherton
# (and the asymmetric Bouc–Wen record), and — the "nothing else slower" check — PI and
# Preisach fitted to the Bouc–Wen record.
#
#   bench/operator_fits.sh                 # this tree's binary
#   bench/operator_fits.sh OLD_BINARY      # paired: OLD and NEW run back to back, in turn
#
# Prints per family the median, min and max wall seconds of RUNS runs (default 7) of each
# binary and the fit % of the last run. Build the old binary from the commit to compare
# against (git worktree add /tmp/old COMMIT && cargo build --release -p hysid-cli there).
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${RUNS:-7}
old=${1:-}
cargo build --release -q -p hysid-cli
cargo build --release -q -p hysid --example differential_records
new=./target/release/hysid
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
./target/release/examples/differential_records "$dir"

# Wall seconds of one run of binary $1 on family $2; the report in $dir/$3.json.
once() {
  /usr/bin/time -f "%e" -o "$dir/t" "$1" -q identify operator --family "${2%%@*}" \
    --data "$dir/${2##*@}.csv" --input u --output y --json "$dir/$3.json" >/dev/null
  cat "$dir/t"
}

stats() { sort -n | awk '{v[NR]=$1} END {printf "median %.3f s (min %.3f, max %.3f)", v[int((NR+1)/2)], v[1], v[NR]}'; }

fit() { python3 -c "import json,sys; print('%.4f' % json.load(open(sys.argv[1]))['fit']['fit_percent'])" "$1"; }

# FAMILY@RECORD
for family in bouc-wen@bouc-wen bouc-wen@bouc-wen-asym duhem@duhem dahl@dahl \
  jiles-atherton@jiles-atherton pi@bouc-wen preisach@bouc-wen; do
  : >"$dir/new.t"
  : >"$dir/old.t"
  for _ in $(seq "$runs"); do
    once "$new" "$family" new >>"$dir/new.t"
    if [ -n "$old" ]; then once "$old" "$family" old >>"$dir/old.t"; fi
  done
  printf '%-26s new: %s, fit %s %%\n' "$family" "$(stats <"$dir/new.t")" "$(fit "$dir/new.json")"
  if [ -n "$old" ]; then
    printf '%-26s old: %s, fit %s %%\n' "" "$(stats <"$dir/old.t")" "$(fit "$dir/old.json")"
  fi
done
