#!/usr/bin/env bash
# The user-model route against the built-in model, whole process: the Bouc–Wen equation file
# (examples/equations/bouc_wen.toml) and `--model bouc-wen` fitted to the benchmark's
# training record from every free parameter at twice its nominal value, one start, RK4 × 4,
# band-limited input — run back to back in turn, RUNS times each (default 9):
#
#   file     the default (--evaluator auto): the C compiler's code, loaded from the cache
#            (every run after a machine's first)
#   cc       --evaluator cc: the same, the C route demanded
#   cold     --evaluator cc, the cache emptied before each run: the compilation counted
#   tape     --evaluator tape: the tape interpreter
#   builtin  --model bouc-wen
#
# Prints per route the median, min and max wall seconds (/usr/bin/time), the ratio of
# medians to the built-in and the median of the round-by-round ratios (each round runs every
# route once, in turn, so a drift of the machine's speed cancels); checks once that the
# file's estimates equal the built-in's to 1e-9 relative and that every route's equal the
# tape's to the bit. For a tighter paired figure of one route, farm-bench pairs two commands
# run by run (the closing comment gives the command).
#
#   bench/equation_fit.sh
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${RUNS:-9}
cargo build --release -q -p hysid-cli
bin=./target/release/hysid
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
common=(--data data/bouc-wen/train_multisine_5periods.csv --input u_N --output y_m
  --starts 1 --substeps 4 --interpolation band-limited
  --init mL=4 --init cL=20 --init kL=1e5 --init alpha=1e5
  --init beta_gamma=1600 --init beta_delta=-2200)
file=(-q greybox fit --model-file examples/equations/bouc_wen.toml "${common[@]}")
builtin=(-q greybox fit --model bouc-wen "${common[@]}")

# Wall seconds of one run; the report in $dir/$1.json.
once() {
  local name=$1
  shift
  /usr/bin/time -f "%e" -o "$dir/t" "$@" --json "$dir/$name.json" >/dev/null
  cat "$dir/t"
}

stats() { sort -n | awk '{v[NR]=$1} END {printf "median %.3f s (min %.3f, max %.3f)", v[int((NR+1)/2)], v[1], v[NR]}'; }
median() { sort -n | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }

export HYSID_CACHE_DIR="$dir/cache"
unset HYSID_EVALUATOR
"$bin" "${file[@]}" --evaluator cc >/dev/null # fill the cache
routes=(file cc cold tape builtin)
for route in "${routes[@]}"; do : >"$dir/$route.t"; done
for _ in $(seq "$runs"); do
  once file "$bin" "${file[@]}" >>"$dir/file.t"
  once cc "$bin" "${file[@]}" --evaluator cc >>"$dir/cc.t"
  rm -rf "$dir/cache"
  once cold "$bin" "${file[@]}" --evaluator cc >>"$dir/cold.t"
  once tape "$bin" "${file[@]}" --evaluator tape >>"$dir/tape.t"
  once builtin "$bin" "${builtin[@]}" >>"$dir/builtin.t"
done
base=$(median <"$dir/builtin.t")
for route in "${routes[@]}"; do
  m=$(median <"$dir/$route.t")
  paired=$(paste "$dir/$route.t" "$dir/builtin.t" | awk '{print $1 / $2}' | median)
  printf '%-8s %s, %.2f× the built-in (round by round: %.2f×)\n' "$route" \
    "$(stats <"$dir/$route.t")" "$(python3 -c "print($m / $base)")" "$paired"
done
python3 - "$dir" <<'EOF'
import json, sys
d = sys.argv[1]
def values(name):
    report = json.load(open(f"{d}/{name}.json"))
    return {p["name"]: p["value"] for p in report["model"]["parameters"]}
built, tape = values("builtin"), values("tape")
worst = max(abs(values("file")[k] - built[k]) / abs(built[k]) for k in built if built[k] != 0)
same = all(values(route) == tape for route in ("file", "cc", "cold"))
print(f"estimates: file vs built-in max relative difference {worst:.1e}; "
      f"every route == tape to the bit: {same}")
EOF
# Paired run by run (A B A B …), e.g. the cached C route against the built-in model:
#   HYSID_CACHE_DIR=/tmp/c farm-bench -n 21 --timeout 600 \
#     --vs "target/release/hysid ${builtin[*]}" -- target/release/hysid ${file[*]} --evaluator cc
