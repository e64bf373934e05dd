"""Executes the tutorial notebooks in place, so that they ship with their outputs (figures
included: run it without ``MPLBACKEND`` set). From ``crates/hysid-py``, with the package
importable::

    python examples/notebooks/execute.py            # every notebook here
    python examples/notebooks/execute.py NAME.ipynb  # one

``tests/test_notebooks.py`` checks that the shipped files hold the outputs of a run from
top to bottom, and executes them afresh.
"""

import pathlib
import sys

import nbclient
import nbformat

HERE = pathlib.Path(__file__).resolve().parent


def main(names: list[str]) -> None:
    for path in [HERE / n for n in names] or sorted(HERE.glob("*.ipynb")):
        book = nbformat.read(path, as_version=4)
        client = nbclient.NotebookClient(
            book, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(HERE)}}
        )
        client.execute()
        for cell in book.cells:
            cell.metadata.pop("execution", None)  # wall-clock stamps: noise in a diff
        nbformat.write(book, path)
        print("executed", path.name)


if __name__ == "__main__":
    main(sys.argv[1:])
