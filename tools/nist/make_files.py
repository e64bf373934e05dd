#!/usr/bin/env python3
"""Writes the equation files and CSV records of NIST's StRD nonlinear regression problems.

Reads the 27 `.dat` files in `data/nist-strd/` (NIST's own, unchanged) and writes, for each
problem NAME:

* `data/nist-strd/csv/NAME.csv` — the data, columns `x,y` (Nelson: `x1,x2,y`), each value the
  text of the `.dat` file unchanged, except Nelson's `y`, which is ln of NIST's response (the
  model NIST certifies is log[y] = b1 - b2*x1*exp[-b3*x2]), written as the shortest decimal
  that reads back to the same double (Python's repr of math.log).
* `data/nist-strd/models/NAME_start1.toml`, `NAME_start2.toml` — the model y = f(x; b) as a
  discrete-time equation file with one dummy state and the model in `[output]`, each
  parameter's initial value the start (NIST's "Start 1", far; "Start 2", near).

The model expressions are NIST's "Model:" blocks written in hysid's expression language
(`**` as `^`, `arctan` as `atan`, `exp[...]` as `exp(...)`); nothing else is changed.
Run from the repository root: `python3 tools/nist/make_files.py`. Standard library only.
"""

import math
import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
DIR = ROOT / "data" / "nist-strd"

MODELS = {
    "Misra1a": "b1*(1 - exp(-b2*x))",
    "Chwirut2": "exp(-b1*x)/(b2 + b3*x)",
    "Chwirut1": "exp(-b1*x)/(b2 + b3*x)",
    "Lanczos3": "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)",
    "Gauss1": "b1*exp(-b2*x) + b3*exp(-(x - b4)^2/b5^2) + b6*exp(-(x - b7)^2/b8^2)",
    "Gauss2": "b1*exp(-b2*x) + b3*exp(-(x - b4)^2/b5^2) + b6*exp(-(x - b7)^2/b8^2)",
    "DanWood": "b1*x^b2",
    "Misra1b": "b1*(1 - (1 + b2*x/2)^(-2))",
    "Kirby2": "(b1 + b2*x + b3*x^2)/(1 + b4*x + b5*x^2)",
    "Hahn1": "(b1 + b2*x + b3*x^2 + b4*x^3)/(1 + b5*x + b6*x^2 + b7*x^3)",
    "Nelson": "b1 - b2*x1*exp(-b3*x2)",
    "MGH17": "b1 + b2*exp(-x*b4) + b3*exp(-x*b5)",
    "Lanczos1": "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)",
    "Lanczos2": "b1*exp(-b2*x) + b3*exp(-b4*x) + b5*exp(-b6*x)",
    "Gauss3": "b1*exp(-b2*x) + b3*exp(-(x - b4)^2/b5^2) + b6*exp(-(x - b7)^2/b8^2)",
    "Misra1c": "b1*(1 - (1 + 2*b2*x)^(-0.5))",
    "Misra1d": "b1*b2*x*((1 + b2*x)^(-1))",
    "Roszman1": "b1 - b2*x - atan(b3/(x - b4))/pi",
    "ENSO": "b1 + b2*cos(2*pi*x/12) + b3*sin(2*pi*x/12)"
    " + b5*cos(2*pi*x/b4) + b6*sin(2*pi*x/b4)"
    " + b8*cos(2*pi*x/b7) + b9*sin(2*pi*x/b7)",
    "MGH09": "b1*(x^2 + x*b2)/(x^2 + x*b3 + b4)",
    "Thurber": "(b1 + b2*x + b3*x^2 + b4*x^3)/(1 + b5*x + b6*x^2 + b7*x^3)",
    "BoxBOD": "b1*(1 - exp(-b2*x))",
    "Rat42": "b1/(1 + exp(b2 - b3*x))",
    "MGH10": "b1*exp(b2/(x + b3))",
    "Eckerle4": "(b1/b2)*exp(-0.5*((x - b3)/b2)^2)",
    "Rat43": "b1/((1 + exp(b2 - b3*x))^(1/b4))",
    "Bennett5": "b1*(b2 + x)^(-1/b3)",
}


def lines_of(header, what):
    """The 1-based line range the header gives for `what` ('Starting Values', 'Data')."""
    m = re.search(what + r"\s*\(lines\s+(\d+)\s+to\s+(\d+)\)", header, re.IGNORECASE)
    return int(m.group(1)), int(m.group(2))


def parse(path):
    text = path.read_text()
    lines = text.splitlines()
    header = "\n".join(lines[:10])
    a, b = lines_of(header, "Starting Values")
    starts = []
    for line in lines[a - 1 : b]:
        m = re.match(r"\s*(b\d+)\s*=\s*(\S+)\s+(\S+)\s+(\S+)\s+(\S+)", line)
        starts.append((m.group(1), m.group(2), m.group(3)))
    a, b = lines_of(header, "Data")
    rows = [line.split() for line in lines[a - 1 : b] if line.strip()]
    return starts, rows


def number(text):
    """A TOML number for a start value of the .dat file (the same double)."""
    return repr(float(text))


def main():
    (DIR / "csv").mkdir(exist_ok=True)
    (DIR / "models").mkdir(exist_ok=True)
    for name, expr in MODELS.items():
        starts, rows = parse(DIR / f"{name}.dat")
        inputs = ["x1", "x2"] if name == "Nelson" else ["x"]
        with open(DIR / "csv" / f"{name}.csv", "w") as f:
            f.write(",".join(inputs + ["y"]) + "\n")
            for row in rows:
                y, xs = row[0], row[1:]
                assert len(xs) == len(inputs), (name, row)
                if name == "Nelson":
                    y = repr(math.log(float(y)))
                f.write(",".join(xs + [y]) + "\n")
        for k in (1, 2):
            quoted = ", ".join(f'"{i}"' for i in inputs)
            params = "\n".join(f"{b} = {number(s[k - 1])}" for b, *s in starts)
            response = "ln of the response" if name == "Nelson" else "the response"
            text = f"""# NIST StRD nonlinear regression problem {name}, from start {k}
# ({'far' if k == 1 else 'near'}): y = {expr}, y {response}.
# A static map posed as a discrete-time model: one dummy state, the model in [output].
# Written by tools/nist/make_files.py from data/nist-strd/{name}.dat; fit with
#   hysid greybox fit --model-file data/nist-strd/models/{name}_start{k}.toml \\
#     --data data/nist-strd/csv/{name}.csv {' '.join('--input ' + i for i in inputs)} --output y

[model]
name = "nist_{name.lower()}"
time = "discrete"
states = ["s"]
inputs = [{quoted}]
outputs = ["y"]

[parameters]
{params}

[equations]
s = "s"

[output]
y = "{expr}"
"""
            (DIR / "models" / f"{name}_start{k}.toml").write_text(text)


if __name__ == "__main__":
    main()
