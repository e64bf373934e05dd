#!/usr/bin/env python3
"""Run the built `hysid` binary over a matrix of bad command lines and tally what happens.

Usage:
    python3 tools/fuzz_cli.py [BINARY] [--quick] [--jobs N] [--timeout S] [--show N]
                              [--only SUBSTRING] [--list] [--check-flags]

BINARY defaults to target/release/hysid. Every case runs in a fresh temporary working
directory holding copies of the inputs it needs, with a timeout, and is classified as

    panic      exit 101 or "panicked" on stderr
    signal     killed by a signal (SIGABRT from a failed allocation, SIGSEGV, ...)
    nonfinite  exit 0 with NaN/inf in stdout or in a file it wrote (printed bounds such as
               "[0, inf]" are settings, not results, and are left out)
    clobber    a run (failing or not) changed or removed a file that was there before it
               (an input, or a file an input links to)
    code       a run that must be refused (an output that is an input or another output:
               exit 2; degenerate data: a non-zero exit) exited otherwise
    stray      a failing run left a file behind (temporaries included)
    multiline  a failing run printed other than exactly one error line on stderr, last
               (plain progress lines of a long run may come before it)
    dump       the error line holds a debug dump of a dependency's error ({:?})
    unbounded  still running at the timeout
    ok         anything else

The script prints the tally, the exit codes seen, and the first few failures of each
class, and exits 1 if any case is not ok. `--quick` runs a fixed sample of about 200 cases
(for CI). Python 3 standard library only.

The matrix is data: COMMANDS below lists each subcommand with a base command line that
works, its numeric options and its input and output options. FLAG holds the spelling of the
options that are being renamed: change it there, and `--check-flags` compares the whole
table with `hysid <command> --help`.
"""

import argparse
import concurrent.futures
import hashlib
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

# --- The table ------------------------------------------------------------------------

# Output options by role: one place to update when one is renamed (the old spellings are
# still accepted with a deprecation warning, which would count as a second stderr line).
FLAG = {
    "plots": "--plots",  # plot directory of demo/identify/greybox/benchmark
    "sim_csv": "--csv",  # simulate's output CSV
    "model_out": "--model-out",  # identify's model file output
    "greybox_model_out": "--model-out",
    "rig_dir": "--data-out",  # actuator rig's data directory
    "gen_csv": "--csv",  # generate's CSV
}

# Bad values for every numeric option.
VALUES = ["0", "-1", "nan", "inf", "-inf", "1e308", "1e-320", "18446744073709551615",
          "1e11", "abc", ""]
# Further spellings, used in the full run only.
MORE_VALUES = ["-0", "1e-9", "4294967296", "1e400", "+inf", "NaN", "0x10", " 1",
               "100000", "-1e308"]

# Placeholders: {cascade} {model} {bw} {rb} {rig} {mat} are inputs copied into the case
# directory under those names.
COMMANDS = [
    {
        "name": "demo voros",
        "base": ["demo", "voros", "--uncertainty", "asymptotic", FLAG["plots"], "plots"],
        "plots_sub": ["voros-example1"],
        "numeric": ["--example", "--seed", "--replicates"],
        "inputs": {},
        "outputs": {"--json": "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "identify cascade",
        "base": ["identify", "cascade", "--data", "{cascade}", "--input", "x", "--output", "y",
                 "--hysteresis", "ch4", "--na", "2", "--nb", "2", "--delay", "1"],
        "numeric": ["--na", "--nb", "--delay", "--replicates", "--seed", "--ts"],
        "inputs": {"--data": "csv"},
        "outputs": {"--json": "file", FLAG["model_out"]: "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "identify hysteresis",
        "base": ["identify", "hysteresis", "--data", "{cascade}", "--input", "x", "--output",
                 "y", "--hysteresis", "ch4"],
        "numeric": ["--ts"],
        "inputs": {"--data": "csv"},
        "outputs": {"--json": "file", FLAG["model_out"]: "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "simulate",
        "base": ["simulate", "--model", "{model}", "--data", "{cascade}", "--input", "x",
                 "--output", "y"],
        "numeric": ["--ts"],
        "inputs": {"--data": "csv", "--model": "model"},
        "outputs": {"--json": "file", FLAG["sim_csv"]: "file"},
    },
    {
        "name": "generate voros",
        "base": ["generate", "voros", "--samples", "300", FLAG["gen_csv"], "gen.csv"],
        "numeric": ["--example", "--samples", "--seed"],
        "inputs": {},
        "outputs": {FLAG["gen_csv"]: "file"},
    },
    {
        "name": "greybox fit",
        "base": ["greybox", "fit", "--model", "rigid-body", "--data", "{rb}", "--input", "u",
                 "--output", "q", "--max-iterations", "5"],
        "numeric": ["--substeps", "--starts", "--seed", "--max-iterations", "--tolerance",
                    "--ts"],
        "name_values": ["--init", "--bounds"],
        "parameters": ["M", "Fv", "Fc", "offset", "gain", "nosuch"],
        "inputs": {"--data": "csv"},
        "outputs": {"--json": "file", FLAG["greybox_model_out"]: "file",
                    FLAG["plots"]: "dir"},
    },
    {
        "name": "greybox fit bouc-wen",
        "base": ["greybox", "fit", "--model", "bouc-wen", "--data", "{bw}", "--input", "u_N",
                 "--output", "y_m", "--max-iterations", "2", "--substeps", "2"],
        "numeric": ["--substeps", "--starts", "--max-iterations", "--tolerance"],
        "name_values": ["--init", "--bounds"],
        "parameters": ["mL", "cL", "kL", "alpha", "beta_gamma", "beta_delta", "nu"],
        "inputs": {"--data": "csv"},
        "outputs": {"--json": "file"},
    },
    {
        "name": "benchmark bouc-wen",
        "base": ["benchmark", "bouc-wen", "--train", "{bw}", "--starts", "1", "--substeps",
                 "2"],
        "numeric": ["--start-factor", "--starts", "--seed", "--substeps"],
        "name_values": ["--init"],
        "parameters": ["mL", "cL", "kL", "alpha", "nosuch"],
        "inputs": {"--train": "csv", "--test": "csv"},
        "outputs": {"--json": "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "benchmark bouc-wen generate",
        "base": ["benchmark", "bouc-wen", "generate", "--samples", "2000", "--periods", "1",
                 FLAG["gen_csv"], "gen.csv"],
        "numeric": ["--periods", "--samples", "--seed", "--noise"],
        "inputs": {},
        "outputs": {FLAG["gen_csv"]: "file"},
    },
    {
        "name": "actuator rig",
        "base": ["actuator", "rig", FLAG["rig_dir"], "rigout"],
        "numeric": ["--backlash", "--noise", "--seed", "--gear-ratio", "--saddle-mass"],
        "name_values": ["--truth"],
        "parameters": ["J", "Fv", "Fc", "k1", "k2", "A", "alpha", "nosuch"],
        "inputs": {},
        "outputs": {FLAG["rig_dir"]: "dir"},
    },
    {
        "name": "actuator identify",
        "slow": True,  # ~9 s a run: the short list of values only
        "base": ["actuator", "identify", "--data", "{rig}", "--max-iterations", "3"],
        "numeric": ["--gear-ratio", "--saddle-mass", "--cutoff", "--reversal-margin",
                    "--max-iterations", "--tolerance"],
        "inputs": {"--data": "rigdir"},
        "outputs": {"--json": "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "demo actuator",
        "slow": True,
        "base": ["demo", "actuator", "--max-iterations", "2", FLAG["plots"], "plots"],
        "plots_sub": ["actuator"],
        "numeric": ["--backlash", "--noise", "--gear-ratio", "--saddle-mass", "--cutoff",
                    "--reversal-margin", "--max-iterations", "--tolerance"],
        "inputs": {},
        "outputs": {"--json": "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "rigid-body ls",
        "base": ["rigid-body", "ls", "--data", "{rb}", "--position", "q", "--input", "u",
                 "--offset"],
        "numeric": ["--gain", "--cutoff", "--order", "--decimate", "--border"],
        "inputs": {"--data": "csv", "--validate": "csv"},
        "outputs": {"--json": "file"},
    },
    {
        "name": "identify operator",
        "base": ["identify", "operator", "--family", "pi", "--data", "{cascade}", "--input", "x",
                 "--output", "y"],
        "numeric": ["--ts", "--grid", "--lambda", "--dead-zones"],
        "inputs": {"--data": "csv"},
        "outputs": {"--json": "file", FLAG["model_out"]: "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "compare",
        "base": ["compare", "--data", "{cascade}", "--input", "x", "--output", "y",
                 "--families", "pi,backlash"],
        "numeric": ["--ts", "--grid", "--lambda"],
        "inputs": {"--data": "csv", "--validate": "csv"},
        "outputs": {"--json": "file", FLAG["model_out"]: "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "compensate",
        "base": ["compensate", "--model", "{op}", "--data", "{cascade}", "--reference", "y",
                 "--csv", "comp.csv"],
        "numeric": ["--ts"],
        "inputs": {"--data": "csv", "--model": "model"},
        "outputs": {"--csv": "file", "--json": "file", FLAG["plots"]: "dir"},
    },
    {
        "name": "export",
        "base": ["export", "--model", "{op}", "--target", "c", "--name", "m", "--out", "exported"],
        "numeric": ["--ts"],
        "inputs": {"--model": "model"},
        "outputs": {"--out": "dir"},
    },
]

# Input files: what a placeholder is copied from, by kind.
PLACEHOLDER_KIND = {"cascade": "csv", "bw": "csv", "rb": "csv", "model": "model",
                    "rig": "rigdir", "mat": "mat", "op": "model"}

# Address space of one case: 4 GiB.
MEMORY_KIB = 4 * 1024 * 1024

NONFINITE = re.compile(rb"(?<![A-Za-z_])(-?nan|NaN|-?inf|-?Inf|-?Infinity|inf%)(?![A-Za-z_])")
# Parameter bounds are printed as intervals, "[0, inf]" or "(-inf, 5)": an infinite bound is
# a setting, not a result, and is left out before the search for non-finite results.
BOUNDS = re.compile(rb"[\[(][^\[\]()\n]*,[^\[\]()\n]*[\])]")


def nonfinite_result(text):
    """The first non-finite number of `text` outside printed bounds, or None."""
    return NONFINITE.search(BOUNDS.sub(b"", text))

# --- Fixtures -------------------------------------------------------------------------


def make_fixtures(binary, root):
    """The valid inputs, made once: returns {placeholder: path}."""
    fx = {}
    run = lambda args: subprocess.run([binary] + args, cwd=root, capture_output=True,
                                      timeout=300, check=True)
    run(["generate", "voros", "--example", "1", "--samples", "400", FLAG["gen_csv"],
         "cascade.csv"])
    fx["cascade"] = os.path.join(root, "cascade.csv")
    run(["benchmark", "bouc-wen", "generate", "--samples", "3000", "--periods", "1",
         FLAG["gen_csv"], "bw.csv"])
    fx["bw"] = os.path.join(root, "bw.csv")
    run(["actuator", "rig", FLAG["rig_dir"], "rig"])
    fx["rig"] = os.path.join(root, "rig")
    # A rigid body with viscous and Coulomb friction: M q'' + Fv q' + Fc sgn q' = u.
    ts, m, fv, fc = 1e-3, 2.0, 5.0, 1.0
    rows = ["t,q,u"]
    for k in range(3000):
        t = k * ts
        q = 0.1 * math.sin(2 * math.pi * t) + 0.02 * math.sin(2 * math.pi * 7 * t)
        v = 0.2 * math.pi * math.cos(2 * math.pi * t) + 0.28 * math.pi * math.cos(
            2 * math.pi * 7 * t)
        a = -0.4 * math.pi ** 2 * math.sin(2 * math.pi * t) - 3.92 * math.pi ** 2 * math.sin(
            2 * math.pi * 7 * t)
        u = m * a + fv * v + fc * (1 if v > 0 else -1 if v < 0 else 0)
        rows.append(f"{t!r},{q!r},{u!r}")
    fx["rb"] = os.path.join(root, "rb.csv")
    with open(fx["rb"], "w") as f:
        f.write("\n".join(rows) + "\n")
    fx["model"] = os.path.join(root, "model.json")
    with open(fx["model"], "w") as f:
        f.write(model_json())
    # A PI operator of the cascade record's hysteresis, for compensate.
    run(["identify", "operator", "--family", "pi", "--data", "cascade.csv", "--input", "x",
         "--output", "y", FLAG["model_out"], "op.json"])
    fx["op"] = os.path.join(root, "op.json")
    return fx


def model_json(**override):
    """A valid ch_cascade model file (Example 1's truth), with entries overridden."""
    values = {"alpha": 0.3, "m1": 1.0, "c1": 0.5, "d": 3.0}
    values.update({k: v for k, v in override.items() if k in values})
    params = ", ".join(f'"{k}": {{"value": {v}, "std": 0.0}}' for k, v in values.items())
    delay = override.get("delay", 1)
    a = override.get("a", "-0.6, 0.2")
    return ('{"kind": "ch_cascade", "hysteresis": "ch4", "parameters": {' + params +
            f', "a": [{{"value": {a.split(",")[0]}, "std": 0}}, {{"value": {a.split(",")[-1]}, "std": 0}}],'
            ' "b": [{"value": 1.0, "std": 0}, {"value": 0.5, "std": 0}]}, "delay": ' +
            str(delay) + '}')


def bad_files(kind):
    """Corrupt inputs of a kind: [(label, {name: bytes} or special)]. The first name is the
    one passed on the command line."""
    csv = [
        ("empty", b""),
        ("header only", b"t,x,y,u,q,u_N,y_m\n"),
        ("random bytes", bytes(random.Random(7).randrange(256) for _ in range(2000))),
        ("ragged", b"t,x,y,u,q,u_N,y_m\n0,1,2\n1,2,3,4,5,6,7,8\n"),
        ("nan cell", b"t,x,y,u,q,u_N,y_m\n" + b"".join(
            b"%d,%s,1,1,1,1,1\n" % (k, b"nan" if k == 5 else b"0.5") for k in range(50))),
        ("huge value", b"t,x,y,u,q,u_N,y_m\n" + b"".join(
            b"%d,%s,%s,%s,%s,%s,%s\n" % ((k,) + ((b"1e308",) if k == 7 else (b"0.1",)) * 6)
            for k in range(200))),
        ("constant", b"t,x,y,u,q,u_N,y_m\n" + b"".join(
            b"%d,1,1,1,1,1,1\n" % k for k in range(200))),
        ("bom crlf", b"\xef\xbb\xbft,x,y,u,q,u_N,y_m\r\n0,1,1,1,1,1,1\r\n"),
        ("time not uniform", b"t,x,y,u,q,u_N,y_m\n" + b"".join(
            b"%d,%d,1,%d,1,%d,1\n" % (k * k, k, k, k) for k in range(50))),
        ("two samples", b"t,x,y,u,q,u_N,y_m\n0,1,1,1,1,1,1\n1,2,2,2,2,2,2\n"),
    ]
    # Degenerate records, refused whatever the command (expected to fail): every channel
    # scaled to 1e-300 (squares underflow: a zero loss whatever the fit) or 1e300 (squares
    # overflow), and a constant output beside a varying input.
    degenerate = [
        ("scaled 1e-300", varied_csv(1e-300)),
        ("scaled 1e300", varied_csv(1e300)),
        ("constant output", varied_csv(1.0, constant_outputs=True)),
    ]
    if kind == "csv":
        return [(label, {"in.csv": data}) for label, data in csv + degenerate] + [
            ("mat garbage", {"in.mat": b"MATLAB 5.0 MAT-file" + b"\0" * 105 + b"\0" * 8 +
                             b"\x00\x01IM" + b"\x0f\0\0\0\x40\0\0\0" + b"\x78\x9c" + b"\xff" * 62}),
            ("mat truncated header", {"in.mat": b"MATLAB 5.0"}),
            ("missing", {}),
            ("directory", {"in.csv/": b""}),
        ]
    if kind == "model":
        return [
            ("empty", {"in.json": b""}),
            ("not json", {"in.json": b"{kind: ch_cascade"}),
            ("negative alpha", {"in.json": model_json(alpha=-0.3).encode()}),
            ("huge alpha", {"in.json": model_json(alpha=1e308).encode()}),
            ("zero d", {"in.json": model_json(d=0).encode()}),
            ("unstable", {"in.json": model_json(a="-3.0, 2.5").encode()}),
            ("huge delay", {"in.json": model_json(delay=18446744073709551615).encode()}),
            ("delay 1e9", {"in.json": model_json(delay=1000000000).encode()}),
            ("nan string", {"in.json": model_json().replace("0.3", '"NaN"').encode()}),
            ("negative mass", {"in.json": b'{"kind": "rigid_body", "parameters": {"M": {"value": -1.0}, '
                               b'"Fv": {"value": 1.0}, "Fc": {"value": 0.1}, "offset": {"value": 0.0}, '
                               b'"gain": {"value": 1.0}}}'}),
            ("substeps 1e6", {"in.json": b'{"kind": "bouc_wen", "parameters": {}, "simulation": '
                              b'{"integrator": "rk4", "substeps": 1000000, "interpolation": "zoh"}}'}),
            ("missing", {}),
        ]
    if kind == "rigdir":
        return [
            ("empty dir", {"in/": b""}),
            ("missing", {}),
            ("garbage sets", {"in/": b"", **{f"in/dataset{k}.csv": b"t_s,tau_Nm,theta_rad\n0,nan,1\n"
                                             for k in range(1, 9)}}),
            ("short sets", {"in/": b"", **{f"in/dataset{k}.csv": b"t_s,tau_Nm,theta_rad\n0,1,1\n0.001,1,1\n"
                                           for k in range(1, 9)}}),
            ("a file", {"in": b"t_s\n"}),
        ]
    return []


def varied_csv(scale, constant_outputs=False):
    """A record whose every column varies (two sines and a ramp), times `scale`; with
    `constant_outputs` the output columns (y, q, y_m) are constant."""
    rows = [b"t,t_s,x,y,u,q,u_N,y_m"]
    for k in range(600):
        a = math.sin(0.05 * k) * (1 + 0.002 * k)
        b = math.sin(0.05 * k - 0.4) + 0.1 * math.sin(0.31 * k)
        out = 0.5 if constant_outputs else b
        cells = [k * 1e-3, k * 1e-3] + [v * scale for v in (a, out, a, out, a, out)]
        rows.append(",".join(repr(c) for c in cells).encode())
    return b"\n".join(rows) + b"\n"


# Rig truth files (DIR/rig.json) that make the tables non-finite: refused.
RIG_TRUTH = {"J": 5.0e-4, "Fv": 1.413e-3, "Fc": 0.2065, "k1": 11.31, "k2": 144.3,
             "alpha": 112.5, "A": 42.49}


def rig_truth(**override):
    truth = dict(RIG_TRUTH, **override)
    return ('{"truth": {' + ", ".join(f'"{k}": {v}' for k, v in truth.items()) + "}}").encode()


# --- Cases ----------------------------------------------------------------------------


class Case:
    def __init__(self, command, label, args, files=None, copies=None, links=None,
                 expect=None):
        self.command = command
        self.label = label
        self.args = args  # with placeholders
        self.files = files or {}  # name -> bytes, written in the case directory
        self.copies = copies or []  # placeholders to copy in
        self.links = links or []  # (kind "sym" or "hard", link name, target with placeholders)
        # The exit code the run must have: an int, "fail" (any non-zero), or None (any).
        self.expect = expect

    def describe(self):
        return f"[{self.command}] {self.label}: hysid " + " ".join(
            repr(a) if (a == "" or " " in a) else a for a in self.args)


def placeholders(args):
    found = []
    for a in args:
        for name in PLACEHOLDER_KIND:
            if "{" + name + "}" in a and name not in found:
                found.append(name)
    return found


def with_option(base, flag, value):
    """`base` with `flag value` replacing an existing `flag x`, else appended."""
    args = list(base)
    if flag in args:
        i = args.index(flag)
        if i + 1 < len(args):
            args[i + 1] = value
            return args
    return args + [flag, value]


def build_cases(full):
    cases = []
    for c in COMMANDS:
        values = VALUES + (MORE_VALUES if full and not c.get("slow") else [])
        base = c["base"]
        cases.append(Case(c["name"], "base (must succeed)", base, copies=placeholders(base)))
        for flag in c["numeric"]:
            for v in values:
                args = with_option(base, flag, v)
                cases.append(Case(c["name"], f"{flag} {v!r}", args, copies=placeholders(args)))
        for flag in c.get("name_values", []):
            for p in c.get("parameters", []):
                vals = values if flag != "--bounds" else [f"{v}:1" for v in values] + [
                    f"1:{v}" for v in values] + ["2:1", "1:1", ":", "1"]
                for v in vals:
                    args = base + [flag, f"{p}={v}"]
                    cases.append(Case(c["name"], f"{flag} {p}={v!r}", args,
                                      copies=placeholders(args)))
        for flag, kind in c["inputs"].items():
            for label, files in bad_files(kind):
                name = next(iter(files), "in.csv" if kind == "csv" else "in.json")
                args = with_option(base, flag, name.rstrip("/"))
                if kind == "rigdir":
                    args = with_option(base, flag, "in")
                cases.append(Case(c["name"], f"{flag} {label}", args, files=files,
                                  copies=placeholders(args)))
        for flag, kind in c["outputs"].items():
            targets = [("unwritable /proc", "/proc/hysid-fuzz/out" if kind == "dir"
                        else "/proc/hysid-fuzz.json"),
                       ("missing parent", "nosuchdir/x/out.json"),
                       ("existing file as dir" if kind == "dir" else "directory as file",
                        "afile" if kind == "dir" else "."),
                       ("empty path", "")]
            for label, target in targets:
                args = with_option(base, flag, target)
                cases.append(Case(c["name"], f"{flag} {label}", args, files={"afile": b"x"},
                                  copies=placeholders(args)))
            # Output equal to each input, spelled directly, as dir/../input, through a
            # symbolic link and a hard link; for an input directory also each file read
            # from inside it. Refused as a usage error (exit 2), the input unchanged.
            for name in placeholders(base):
                for label, target, links, files in clash_targets(name, kind):
                    args = with_option(base, flag, target)
                    cases.append(Case(c["name"], f"{flag} = input {name} {label}", args,
                                      files=files, copies=placeholders(base), links=links,
                                      expect=2))
            # A run that fails (bad first numeric option) must leave no output behind.
            if c["numeric"]:
                args = with_option(with_option(base, flag, "out1"), c["numeric"][0], "nan")
                cases.append(Case(c["name"], f"{flag} with a failing run", args,
                                  copies=placeholders(args)))
        # Two outputs on the same path, or on two hard links of one file, or a file output
        # inside the directory output: exit 2.
        outs = list(c["outputs"])
        if len(outs) >= 2:
            args = with_option(with_option(base, outs[0], "same"), outs[1], "same")
            cases.append(Case(c["name"], "two outputs, one path", args,
                              copies=placeholders(args), expect=2))
            files = [f for f in outs if c["outputs"][f] == "file"]
            if len(files) >= 2:
                args = with_option(with_option(base, files[0], "o1"), files[1], "o2")
                cases.append(Case(c["name"], "two outputs, hard links of one file", args,
                                  files={"o1": b"old"}, links=[("hard", "o2", "o1")],
                                  copies=placeholders(args), expect=2))
            dirs = [f for f in outs if c["outputs"][f] == "dir"]
            if files and dirs:
                # The demos write their plots into a subdirectory of --plots.
                inside = "/".join(["od"] + c.get("plots_sub", []) + ["x.json"])
                args = with_option(with_option(base, dirs[0], "od"), files[0], inside)
                cases.append(Case(c["name"], "a file output inside the directory output",
                                  args, copies=placeholders(args), expect=2))
        # Degenerate records on every CSV input: refused (a non-zero exit). compensate
        # reads no output: a constant reference (a set point) is a fair request.
        degenerate = DEGENERATE if c["name"] != "compensate" else DEGENERATE[:2]
        for case in cases:
            if (case.command == c["name"] and case.expect is None and
                    any(case.label.endswith(d) for d in degenerate)):
                case.expect = "fail"
        # A rig truth file whose values make the tables non-finite.
        if "rigdir" in c["inputs"].values():
            flag = next(f for f, k in c["inputs"].items() if k == "rigdir")
            for p, v in [("J", "1e308"), ("alpha", "1e300"), ("A", "-1e308"), ("k1", "1e13")]:
                args = with_option(base, flag, "{rig}")
                cases.append(Case(c["name"], f"{flag} rig.json truth {p}={v}", args,
                                  files={"rig/rig.json": rig_truth(**{p: v})},
                                  copies=placeholders(args), expect="fail"))
        # A true parameter of the rig that makes its simulation or tables non-finite.
        for flag in c.get("name_values", []):
            if flag == "--truth":
                for p in ["J", "Fv", "Fc", "k1", "k2", "alpha", "A"]:
                    for v in ["1e308", "1e300", "-1e308", "1e13"]:
                        args = base + [flag, f"{p}={v}"]
                        cases.append(Case(c["name"], f"{flag} {p}={v} (refused)", args,
                                          copies=placeholders(args), expect="fail"))
    return cases


DEGENERATE = ["scaled 1e-300", "scaled 1e300", "constant output"]


def clash_targets(name, kind):
    """Spellings of the input placeholder `name` as an output path of `kind` ("file" or
    "dir"): [(label, target, links, files)]. Links are made after the inputs are copied
    in."""
    ref = "{" + name + "}"
    targets = [
        ("directly", ref, [], {}),
        ("as sub/../input", "sub/../" + ref, [], {"sub/": b""}),
        ("through a symbolic link", "link_to_input", [("sym", "link_to_input", ref)], {}),
    ]
    if PLACEHOLDER_KIND[name] != "rigdir" and kind == "dir":
        targets.append(("the directory holding it", ".", [], {}))
    if PLACEHOLDER_KIND[name] == "rigdir":
        for inside in ["dataset1.csv", "rig.json"]:
            targets.append((f"file {inside} inside it", f"{ref}/{inside}", [], {}))
            targets.append((f"file {inside} inside it as ../", f"{ref}/../{ref}/{inside}", [],
                            {}))
        targets.append(("a hard link of dataset2.csv inside it", "hard_to_input",
                        [("hard", "hard_to_input", ref + "/dataset2.csv")], {}))
        targets.append(("a symbolic link to rig.json inside it", "link_to_file",
                        [("sym", "link_to_file", ref + "/rig.json")], {}))
        if kind == "dir":
            targets.append(("the directory holding it", ".", [], {}))
    else:
        targets.append(("through a hard link", "hard_to_input",
                        [("hard", "hard_to_input", ref)], {}))
    return targets


# --- Running and classifying ----------------------------------------------------------


def snapshot(root):
    state = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for d in dirnames:
            state[os.path.relpath(os.path.join(dirpath, d), root) + "/"] = None
        for f in filenames:
            p = os.path.join(dirpath, f)
            try:
                with open(p, "rb") as fh:
                    state[os.path.relpath(p, root)] = hashlib.sha1(fh.read()).hexdigest()
            except OSError:
                state[os.path.relpath(p, root)] = "?"
    return state


def run_case(binary, fixtures, case, timeout):
    with tempfile.TemporaryDirectory(prefix="hysid-fuzz-") as work:
        mapping = {}
        for name in case.copies:
            src = fixtures[name]
            dst = os.path.join(work, os.path.basename(src))
            if os.path.isdir(src):
                shutil.copytree(src, dst)
            else:
                shutil.copy(src, dst)
            mapping[name] = os.path.basename(src)
        for name, data in case.files.items():
            path = os.path.join(work, name)
            if name.endswith("/"):
                os.makedirs(path, exist_ok=True)
                continue
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "wb") as f:
                f.write(data)
        for kind, link, target in case.links:
            target = target.format(**mapping)
            if kind == "sym":
                os.symlink(target, os.path.join(work, link))
            else:
                os.link(os.path.join(work, target), os.path.join(work, link))
        args = [a.format(**mapping) if "{" in a else a for a in case.args]
        before = snapshot(work)
        start = time.monotonic()
        # Address space capped (ulimit -v) so that a runaway allocation fails in the case
        # (SIGABRT, counted as a signal) instead of pushing the shared machine into swap.
        limited = ["/bin/sh", "-c", f'ulimit -v {MEMORY_KIB} && exec "$0" "$@"', binary]
        try:
            proc = subprocess.run(limited + args, cwd=work, capture_output=True,
                                  timeout=timeout, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired as e:
            return "unbounded", None, f"still running after {timeout} s", time.monotonic() - start
        elapsed = time.monotonic() - start
        after = snapshot(work)
        return classify(proc, before, after, work, case.expect) + (elapsed,)


def classify(proc, before, after, work, expect=None):
    rc = proc.returncode
    err = proc.stderr.decode("utf-8", "replace")
    if rc < 0:
        return "signal", rc, f"killed by signal {-rc}; stderr: {err[-300:]!r}"
    if rc == 101 or "panicked" in err:
        return "panic", rc, err.strip()[-400:]
    # Inputs are sacred: nothing that was there before may change, whatever the exit.
    clobbered = sorted(n for n in before if not n.endswith("/") and after.get(n) != before[n])
    if clobbered:
        return "clobber", rc, f"changed or removed {clobbered}; stderr: {err.strip()[:200]!r}"
    if expect is not None and (rc == 0 if expect == "fail" else rc != expect):
        want = "a failure" if expect == "fail" else f"exit {expect}"
        return "code", rc, f"expected {want}; stderr: {err.strip()[:300]!r}"
    if rc == 0:
        bad = nonfinite_result(proc.stdout)
        where = "stdout" if bad else None
        if not bad:
            for name, digest in after.items():
                if name.endswith("/") or before.get(name) == digest:
                    continue
                try:
                    with open(os.path.join(work, name), "rb") as f:
                        bad = nonfinite_result(f.read(50_000_000))
                except OSError:
                    continue
                if bad:
                    where = name
                    break
        if bad:
            return "nonfinite", rc, f"{bad.group(0).decode()!r} in {where}"
        return "ok", rc, ""
    created = sorted(set(after) - set(before))
    changed = sorted(n for n in before if n in after and before[n] != after[n])
    removed = sorted(set(before) - set(after))
    if created or changed or removed:
        return "stray", rc, f"left {created} changed {changed} removed {removed}; stderr: {err.strip()[:200]!r}"
    lines = [l for l in err.splitlines() if l.strip()]
    # A run longer than a few seconds shows plain progress lines on a pipe (documented):
    # those may precede the one error line, which must be the last.
    progress = lines[:-1]
    if (not lines or not lines[-1].startswith("error: ") or
            any(l.startswith(("error", "warning")) or "panicked" in l for l in progress)):
        return "multiline", rc, f"{len(lines)} lines: {err.strip()[:300]!r}"
    if DEBUG_DUMP.search(lines[-1]):
        return "dump", rc, f"a debug dump in the error: {lines[-1][:300]!r}"
    return "ok", rc, ""


# A dependency's error printed with {:?}: `Os { code: 2, kind: NotFound, … }`, `Custom {
# kind: …`, `Error { … }`, `Some(…)` wrappers.
DEBUG_DUMP = re.compile(r"\w+ \{ \w+: |\bkind: [A-Z]|\bSome\(")


def check_flags(binary):
    """Compares the table's options with `hysid <command> --help`; returns the mismatches."""
    problems = []
    for c in COMMANDS:
        words = [w for w in c["base"] if not w.startswith("-") and "{" not in w][:3]
        path = []
        for w in words:
            path.append(w)
            probe = subprocess.run([binary] + path + ["--help"], capture_output=True)
            if probe.returncode != 0:
                path.pop()
                break
        help_text = subprocess.run([binary] + path + ["--help"], capture_output=True,
                                   text=True).stdout
        flags = set(c["numeric"]) | set(c["inputs"]) | set(c["outputs"]) | set(
            c.get("name_values", [])) | {a for a in c["base"] if a.startswith("--")}
        for flag in sorted(flags):
            if not re.search(re.escape(flag) + r"\b", help_text):
                problems.append(f"{c['name']}: {flag} is not in 'hysid {' '.join(path)} --help'")
    return problems


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("binary", nargs="?", default="target/release/hysid")
    ap.add_argument("--quick", action="store_true", help="a fixed sample of ~200 cases")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--show", type=int, default=5, help="failures shown per class")
    ap.add_argument("--only", help="run the cases whose description contains this")
    ap.add_argument("--list", action="store_true", help="list the cases and stop")
    ap.add_argument("--check-flags", action="store_true",
                    help="compare the table with --help and stop")
    opts = ap.parse_args()
    binary = os.path.abspath(opts.binary)
    if not os.path.isfile(binary):
        sys.exit(f"error: no binary at {binary}; build it with cargo build --release")
    if opts.check_flags:
        problems = check_flags(binary)
        print("\n".join(problems) or "every option of the table is in --help")
        sys.exit(1 if problems else 0)
    cases = build_cases(full=not opts.quick)
    if opts.quick:
        cases = random.Random(1).sample(cases, min(200, len(cases)))
    if opts.only:
        cases = [c for c in cases if opts.only in c.describe()]
    if opts.list:
        print("\n".join(c.describe() for c in cases))
        print(f"{len(cases)} cases")
        return
    fixtures_dir = tempfile.mkdtemp(prefix="hysid-fuzz-fixtures-")
    try:
        fixtures = make_fixtures(binary, fixtures_dir)
        results = []
        started = time.monotonic()
        with concurrent.futures.ThreadPoolExecutor(max_workers=opts.jobs) as pool:
            futures = {pool.submit(run_case, binary, fixtures, c, opts.timeout): c for c in cases}
            for n, fut in enumerate(concurrent.futures.as_completed(futures), 1):
                case = futures[fut]
                results.append((case,) + fut.result())
                if n % 100 == 0:
                    print(f"  {n}/{len(cases)} cases, {time.monotonic() - started:.0f} s",
                          file=sys.stderr, flush=True)
    finally:
        shutil.rmtree(fixtures_dir, ignore_errors=True)
    report(results, opts.show, time.monotonic() - started)
    sys.exit(0 if all(r[1] == "ok" for r in results) else 1)


def report(results, show, elapsed):
    classes = ["panic", "signal", "nonfinite", "clobber", "code", "stray", "multiline",
               "dump", "unbounded", "ok"]
    tally = {k: 0 for k in classes}
    codes = {}
    for case, cls, rc, detail, _ in results:
        tally[cls] += 1
        codes[rc] = codes.get(rc, 0) + 1
    print(f"{len(results)} bad command lines in {elapsed:.0f} s")
    print("  ".join(f"{k} {tally[k]}" for k in classes))
    print("exit codes: " + ", ".join(f"{k}: {v}" for k, v in sorted(
        codes.items(), key=lambda kv: (kv[0] is None, kv[0] or 0))))
    slow = sorted(results, key=lambda r: -r[4])[:5]
    print("slowest: " + "; ".join(f"{r[0].command} {r[0].label} {r[4]:.1f} s" for r in slow))
    for cls in classes[:-1]:
        failures = [r for r in results if r[1] == cls]
        if not failures:
            continue
        by_command = {}
        for r in failures:
            by_command[r[0].command] = by_command.get(r[0].command, 0) + 1
        print(f"\n{cls}: {len(failures)} (" + ", ".join(
            f"{k} {v}" for k, v in sorted(by_command.items())) + ")")
        for case, _, rc, detail, _ in failures[:show]:
            print(f"  {case.describe()}\n      exit {rc}: {detail}")


if __name__ == "__main__":
    main()
