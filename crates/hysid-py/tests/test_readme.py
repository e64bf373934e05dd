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


def python_blocks() -> list:
    """Every python block of the package README."""
    text = (HERE.parent / "README.md").read_text(encoding="utf-8")
    return re.findall(r"```python\n(.*?)```", text, re.S)


def notebook_code(path: pathlib.Path) -> str:
    """The code cells of a notebook, in order, as one program (IPython magics left out)."""
    import json

    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    lines = []
    for cell in cells:
        if cell["cell_type"] == "code":
            source = "".join(cell["source"])
            lines += [line for line in source.splitlines() if not line.lstrip().startswith(("%", "!"))]
            lines.append("")
    return "\n".join(lines)


def test_every_block_that_uses_hysid_is_a_complete_program() -> None:
    for block in python_blocks():
        if "hysid." in block:
            assert re.search(r"^import .*\bhysid\b|^from hysid", block, re.M), (
                f"this block uses hysid without importing it:\n{block}"
            )


def test_readme_blocks_and_notebooks_pass_mypy_strict(tmp_path: pathlib.Path) -> None:
    """`mypy --strict` on every README block that imports hysid and on each notebook's code:
    the types a user meets are the ones the package promises (a Result's model is there)."""
    files = []
    for k, block in enumerate(python_blocks()):
        if re.search(r"^import .*\bhysid\b|^from hysid", block, re.M):
            files.append(tmp_path / f"readme_block_{k}.py")
            files[-1].write_text(block, encoding="utf-8")
    assert len(files) >= 4, "the README's examples were not found"
    for notebook in sorted((HERE.parent / "examples" / "notebooks").glob("*.ipynb")):
        files.append(tmp_path / f"notebook_{notebook.stem}.py")
        files[-1].write_text(notebook_code(notebook), encoding="utf-8")
    done = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--no-incremental", *map(str, files)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_equation_block_runs(tmp_path: pathlib.Path) -> None:
    """The README's equation-model example runs as written and recovers the plant."""
    block = next(b for b in python_blocks() if "from_equations_file" in b)
    code = block.replace('"examples/', f'"{ROOT}/examples/')
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "duffing.model.json").is_file()
    assert "k3:" in done.stdout, done.stdout
