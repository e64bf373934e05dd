#!/usr/bin/env bash
# Builds and installs the Python package in a fresh virtual environment and runs its
# pytest suite (called from .ci/run). Usage: crates/hysid-py/tests/run.sh [pytest args]
# HYSID_PY_VENV picks the venv's folder (default: a new temporary one).
# HYSID_CLI (optional): a hysid binary to compare against live.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
venv="${HYSID_PY_VENV:-$(mktemp -d)/venv}"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
# The Rust build reuses CARGO_TARGET_DIR when it is set (CI: the workspace's target/).
"$venv/bin/python" -m pip install -q "$here[test]"
cd "$here"
"$venv/bin/ruff" format --check python tests examples
"$venv/bin/ruff" check python tests examples
"$venv/bin/mypy" --strict python/hysid
"$venv/bin/python" -m pytest -q -rs -s tests "$@"
