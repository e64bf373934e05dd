#!/usr/bin/env bash
# Real-time figures of the exported C: for every streaming model of the library bench
# (crates/hysid-bench/src/lib.rs: PI with 20 plays, a 20-level Preisach plane, the Bouc–Wen
# grey-box with RK4 and 4 sub-steps, every operator family's registry example), writes its
# model file (`cargo run --example stream_models`), exports it with `hysid export --target c`
# and `--inverse`, compiles bench/export_step_bench.c with the export (cc -std=c99 -O2) and
# prints ns per step (best of 7 runs of 10^6 samples with minor loops) and sizeof(NAME_state).
# A model the exporter refuses gets its one-line reason instead of figures.
# The library's figures: cargo bench -p hysid-bench --bench stream (time ÷ 10 000 steps).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
target=${CARGO_TARGET_DIR:-$root/target}
cargo build --release -q -p hysid-cli
cargo build --release -q -p hysid-bench --example stream_models
hysid=$target/release/hysid
cc=${CC:-cc}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$target/release/examples/stream_models" "$dir/models" > /dev/null
echo "nproc $(nproc); $(uptime | sed 's/.*load/load/'); $($cc --version | head -1)"
printf '%-30s %-8s %12s %12s\n' model dir "C ns/step" "state bytes"
for model in "$dir"/models/*.json; do
  name=$(basename "$model" .json)
  out=$dir/$name
  mkdir -p "$out"
  if ! err=$("$hysid" export -q --model "$model" --target c --name fwd --out "$out/fwd" 2>&1 >/dev/null); then
    printf '%-30s %-8s %s\n' "$name" forward "not exported: ${err#error: }"
    continue
  fi
  inv=()
  if err=$("$hysid" export -q --model "$model" --target c --inverse --name inv --out "$out/inv" 2>&1 >/dev/null); then
    inv=(-DINV=inv "-DINV_H=\"$out/inv/inv.h\"" "$out/inv/inv.c")
  else
    inv_err=${err#error: }
  fi
  "$cc" -std=c99 -O2 -DFWD=fwd "-DFWD_H=\"$out/fwd/fwd.h\"" -o "$out/bench" \
    bench/export_step_bench.c "$out/fwd/fwd.c" "${inv[@]}" -lm
  "$out/bench" | while read -r direction ns bytes _checksum; do
    printf '%-30s %-8s %12s %12s\n' "$name" "$direction" "$ns" "$bytes"
  done
  if [ ${#inv[@]} -eq 0 ]; then
    printf '%-30s %-8s %s\n' "$name" inverse "not exported: $inv_err"
  fi
done
