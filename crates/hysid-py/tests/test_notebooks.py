"""The tutorial notebooks run top to bottom without error (nbclient, a fresh kernel), so
they cannot rot."""

import pathlib

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOKS = pathlib.Path(__file__).resolve().parent.parent / "examples" / "notebooks"


@pytest.mark.parametrize("name", ["piezo_compensation.ipynb", "bouc_wen_benchmark.ipynb"])
def test_notebook_runs(name, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    book = nbformat.read(NOTEBOOKS / name, as_version=4)
    client = nbclient.NotebookClient(
        book, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOKS)}}
    )
    client.execute()
    errors = [o for c in book.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
    assert sum(c.cell_type == "code" for c in book.cells) >= 4


@pytest.mark.parametrize("name", ["piezo_compensation.ipynb", "bouc_wen_benchmark.ipynb"])
def test_notebook_ships_with_its_outputs(name):
    """The shipped file holds one run from top to bottom (`examples/notebooks/execute.py`):
    every code cell executed, in order, and each one that prints or draws kept its output."""
    book = nbformat.read(NOTEBOOKS / name, as_version=4)
    code = [c for c in book.cells if c.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1))
    assert all(c.outputs for c in code)
    assert not [o for c in code for o in c.outputs if o.output_type == "error"]
    if name == "piezo_compensation.ipynb":
        assert any("image/png" in o.get("data", {}) for c in code for o in c.outputs)
