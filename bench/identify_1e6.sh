#!/usr/bin/env bash
# Speed bar of the cascade identification: `hysid identify cascade` on 10^6 samples of
# Example 1's input pattern (extended), SNR 50. Prints wall time and peak memory.
# About 1e8 model steps, well inside the default work budget (no --allow-long).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p hysid-cli -q
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
./target/release/hysid generate voros --example 1 --samples 1000000 --csv "$dir/big.csv"
/usr/bin/time -f "wall %e s, peak memory %M kB" \
  ./target/release/hysid identify cascade --data "$dir/big.csv" --input x --output y \
  --hysteresis ch4 --na 2 --nb 2 --delay 1 --json "$dir/report.json"
