"""The package README's quick start runs as written (from the repository root)."""

import os
import pathlib
import re
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent.parent


def quick_start() -> str:
    text = (HERE.parent / "README.md").read_text(encoding="utf-8")
    section = text.split("## Python quick start", 1)[1]
    match = re.search(r"```python\n(.*?)```", section, re.S)
    assert match, "the quick start has no python block"
    return match.group(1)


def test_quick_start_runs(tmp_path: pathlib.Path) -> None:
    code = quick_start()
    assert len(code.strip().splitlines()) <= 12, "the quick start is meant to be short"
    # The model file's path is relative to the repository root; run in a temporary
    # directory (the example writes cascade.json) with that path made absolute.
    code = code.replace('"crates/hysid-py/', f'"{ROOT}/crates/hysid-py/')
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env=dict(os.environ),
    )
    assert done.returncode == 0, done.stderr
    assert "fit " in done.stdout and "a1" in done.stdout, done.stdout
    assert (tmp_path / "cascade.json").is_file()
