#!/usr/bin/env bash
# Paired speed bar of the Bouc–Wen benchmark fit: hysid against the CasADi route of
# bench/casadi_bouc_wen.py (the same model, RK4 grid, band-limited input, criterion, start and
# Levenberg–Marquardt rules; symbolic model, forward AD sensitivities, generated C compiled by
# the system compiler). Whole process wall time (/usr/bin/time -f %e) of
#
#   hysid     hysid -q benchmark bouc-wen --train data/bouc-wen/train_multisine_5periods.csv
#                   --start-factor 2 --starts 1 --json FILE
#   compiled  python bench/casadi_bouc_wen.py --json FILE      (C generated and compiled each run)
#   cached    python bench/casadi_bouc_wen.py --cache DIR ...  (compiled library reused)
#
# run back to back in turn, RUNS rounds (default 7; the order rotates from round to round), after
# one untimed warm-up round (page cache, and the cache variant's library). Prints median, min and
# max of each, the medians of the paired ratios CasADi / hysid, the load average, and once the
# largest relative difference between hysid's estimates and CasADi's.
#
#   bench/bouc_wen_fit.sh                  # this tree's release binary (not rebuilt here)
#   RUNS=5 HYSID=/path/to/hysid bench/bouc_wen_fit.sh
#
# The first run makes a venv with casadi and numpy (pip, from the package registry) in
# $BOUC_WEN_VENV (default ~/.cache/hysid-bench/casadi-venv) and reuses it after that.
# Build the binary first: cargo build --release -p hysid-cli.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${RUNS:-7}
hysid=${HYSID:-./target/release/hysid}
venv=${BOUC_WEN_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/hysid-bench/casadi-venv}
train=data/bouc-wen/train_multisine_5periods.csv
if [ ! -x "$hysid" ]; then
  echo "no binary at $hysid: cargo build --release -p hysid-cli, or set HYSID" >&2
  exit 1
fi
if ! "$venv/bin/python" -c "import casadi, numpy" 2>/dev/null; then
  python3 -m venv "$venv"
  "$venv/bin/python" -m pip install -q casadi numpy
fi
py=$venv/bin/python
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

# One run of variant $1 (its report in $dir/$1.json); prints its wall seconds.
once() {
  case $1 in
    hysid) set -- "$hysid" -q benchmark bouc-wen --train "$train" --start-factor 2 --starts 1 \
             --json "$dir/hysid.json" ;;
    compiled) set -- "$py" bench/casadi_bouc_wen.py -q --data "$train" --json "$dir/compiled.json" ;;
    cached) set -- "$py" bench/casadi_bouc_wen.py -q --data "$train" --cache "$dir/cache" \
              --json "$dir/cached.json" ;;
  esac
  /usr/bin/time -f "%e" -o "$dir/t" "$@" >/dev/null
  cat "$dir/t"
}

stats() { sort -n | awk '{v[NR]=$1} END {printf "median %.3f s (min %.3f, max %.3f)", v[int((NR+1)/2)], v[1], v[NR]}'; }
ratios() { paste "$dir/$1.t" "$dir/hysid.t" | awk '{print $1/$2}' | sort -n | awk '{v[NR]=$1} END {printf "median %.2f (min %.2f, max %.2f)", v[int((NR+1)/2)], v[1], v[NR]}'; }

echo "hysid: $("$hysid" --version 2>/dev/null | head -1); $("$py" -c 'import casadi, numpy; print("casadi", casadi.__version__, "numpy", numpy.__version__)'); $(${CC:-cc} --version | head -1)"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg); $runs rounds"
variants=(hysid compiled cached)
for v in "${variants[@]}"; do once "$v" >/dev/null; : >"$dir/$v.t"; done
for round in $(seq "$runs"); do
  for k in 0 1 2; do
    v=${variants[$(((round + k) % 3))]}
    once "$v" >>"$dir/$v.t"
  done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
for v in "${variants[@]}"; do printf '%-9s %s\n' "$v" "$(stats <"$dir/$v.t")"; done
printf 'CasADi compiled each run / hysid: %s\n' "$(ratios compiled)"
printf 'CasADi cached library / hysid:    %s\n' "$(ratios cached)"
python3 - "$dir" <<'EOF'
import json, sys
d = sys.argv[1]
hysid = {p["name"]: p["value"] for p in json.load(open(f"{d}/hysid.json"))["model"]["parameters"]}
for variant in ("compiled", "cached"):
    c = json.load(open(f"{d}/{variant}.json"))
    rel = {k: abs(v - hysid[k]) / abs(hysid[k]) for k, v in c["parameters"].items()}
    worst = max(rel, key=rel.get)
    print(f"estimates, CasADi {variant} vs hysid: max relative difference {rel[worst]:.1e} ({worst}); "
          f"criterion {c['criterion']:.10e}, {c['iterations']} iterations, {c['evaluations']} simulations")
EOF
