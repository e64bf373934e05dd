#!/usr/bin/env python3
"""Check hysid's layering (docs/architecture.md, "How the layering is checked").

1. Library: every `crate::…` path (and `super::…` path that climbs to the crate root) in
   `crates/hysid/src/**.rs`, outside `#[cfg(test)]` modules, comments and string literals,
   must name a layer at or below the file's own layer:

       error  <  numerics = data = toolchain = io  <  model  <  experiments  <  identify
              <  report  <  export

   `numerics` and `data` are peers (each may use the other); `toolchain` (the machine's C
   compiler) and `io` (the atomic output files) are ranked with them. Every top-level module
   of the library must have a rank: a module missing from `RANK` is itself a violation, so
   no module goes unchecked. `crate::Error` and `crate::Result` are the re-exports of
   `error`.

2. Command line: `crates/hysid-cli/src` holds no numerical code. The check is a textual
   heuristic (it sees no types) that flags
     * `hysid::numerics::` imports or paths of anything but a type (a lower-case last segment
       is a function or a module),
     * calls through the fit metrics (`metrics::`),
     * closures in `.map(` / `.fold(` / `.filter(` / `.for_each(` that do floating-point
       arithmetic (an arithmetic operator next to a float literal, or a float method such as
       `sqrt`, `powi`, `abs`, `ln`, `exp`),
     * `.sum::<f64>()` and `.product::<f64>()`,
     * compound assignments (`+=`, `-=`, `*=`, `/=`) by anything but an integer literal or
       text (`s += &format!(…)` builds a string).
   Limits: integer index arithmetic written with float methods, or arithmetic done by a
   helper the command line defines and calls, can be missed or misread; presentation
   arithmetic (scaling coordinates of a plot) is flagged like any other, deliberately: it
   belongs in a library module that Python can use too.

Usage: python3 tools/check_layers.py [REPO_ROOT]. Prints one line per violation
(`path:line: message`) and a summary; exits 1 when there is any violation. Python 3 standard
library only.
"""

import re
import sys
from pathlib import Path

RANK = {
    "error": 0,
    "numerics": 1,
    "data": 1,
    "toolchain": 1,
    "io": 1,
    "model": 2,
    "experiments": 3,
    "identify": 4,
    "report": 5,
    "export": 6,
}
# Items lib.rs re-exports at the crate root, with the layer they come from.
ROOT_REEXPORTS = {"Error": "error", "Result": "error"}


def strip_comments_and_strings(text):
    """The text with comments, string and char literals blanked (newlines kept, so line
    numbers stay right)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and not _ident_char(text, i - 1):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + len(hashes) + 2)
            j = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", text[i:j + 1]))
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]):
            j = text.find("'", i + 2) + 1
            out.append(" " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def _ident_char(text, i):
    return i >= 0 and (text[i].isalnum() or text[i] == "_")


def matching_brace(text, open_at):
    """Index just past the brace that closes the one at `open_at`."""
    depth = 0
    for j in range(open_at, len(text)):
        if text[j] == "{":
            depth += 1
        elif text[j] == "}":
            depth -= 1
            if depth == 0:
                return j + 1
    return len(text)


CFG_TEST = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*([;{])")


def blank_test_modules(code):
    """The code with inline `#[cfg(test)] mod x { … }` blanked; and the names of
    `#[cfg(test)] mod x;` declared in other files."""
    external = []
    while True:
        m = CFG_TEST.search(code)
        if not m:
            return code, external
        if m.group(2) == ";":
            external.append(m.group(1))
            end = m.end()
        else:
            end = matching_brace(code, m.end() - 1)
        code = code[:m.start()] + re.sub(r"[^\n]", " ", code[m.start():end]) + code[end:]


def module_path(src, path):
    """The module path of a source file, e.g. ['model', 'greybox', 'simulate']."""
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts.pop()
    return parts


def test_files(src, files):
    """Files that are `#[cfg(test)]` modules declared elsewhere (and everything below them)."""
    excluded = set()
    for path in files:
        _, external = blank_test_modules(strip_comments_and_strings(path.read_text()))
        own = module_path(src, path)
        is_dir_module = path.name in ("mod.rs", "lib.rs", "main.rs")
        base = src.joinpath(*own) if is_dir_module else path.with_suffix("")
        for name in external:
            excluded.add(base / (name + ".rs"))
            excluded.add(base / name)
    return {f for f in files if f in excluded or any(p in excluded for p in f.parents)}


def referenced_roots(code):
    """(line, first path segment) of every `crate::…` path and `super::…` path."""
    for m in re.finditer(r"(?<![\w$])crate\s*::\s*(\{|\w+)", code):
        line = code.count("\n", 0, m.start()) + 1
        if m.group(1) == "{":
            inner = code[m.end():matching_brace(code, m.end() - 1) - 1]
            depth, item = 0, ""
            for ch in inner + ",":
                if ch == "{":
                    depth += 1
                elif ch == "}":
                    depth -= 1
                if ch == "," and depth == 0:
                    name = re.match(r"\s*(\w+)", item)
                    if name and name.group(1) != "self":
                        yield line, ("crate", name.group(1))
                    item = ""
                else:
                    item += ch
        else:
            yield line, ("crate", m.group(1))
    for m in re.finditer(r"(?<![\w:])((?:super\s*::\s*)+)(\w+)", code):
        line = code.count("\n", 0, m.start()) + 1
        yield line, ("super", m.group(1).count("super"), m.group(2))


def layer_of(module, ref):
    """The layer a reference from `module` (a module path) lands in, or None."""
    if ref[0] == "crate":
        name = ref[1]
    else:
        ups, name = ref[1], ref[2]
        parent = module[: len(module) - ups]
        if parent:
            return parent[0]
    if name in RANK:
        return name
    return ROOT_REEXPORTS.get(name)


def check_library(root):
    src = root / "crates/hysid/src"
    files = sorted(src.rglob("*.rs"))
    skip = test_files(src, files)
    problems = []
    for path in files:
        if path in skip:
            continue
        module = module_path(src, path)
        if not module:
            continue  # lib.rs: the crate root may name every layer
        if module[0] not in RANK:
            problems.append(
                f"{path.relative_to(root)}:1: module '{module[0]}' has no layer rank; add it to RANK "
                "in tools/check_layers.py and to docs/architecture.md §1"
            )
            continue
        own = module[0]
        code, _ = blank_test_modules(strip_comments_and_strings(path.read_text()))
        for line, ref in referenced_roots(code):
            target = layer_of(module, ref)
            if target in RANK and RANK[target] > RANK[own]:
                problems.append(
                    f"{path.relative_to(root)}:{line}: layer '{own}' uses the higher layer '{target}'"
                )
    return problems


FLOAT_METHOD = r"\.(sqrt|powi|powf|abs|ln|log10|exp|hypot|mul_add|signum)\("
FLOAT_ARITH = r"(\d\.\d*|\d+\.\d*e-?\d+|f64::\w+)\s*[-+*/]|[-+*/]\s*(\d+\.\d*|f64::\w+)"
CLOSURE_CALL = re.compile(r"\.(map|fold|filter|for_each|flat_map|filter_map)\s*\(")


def closure_body(code, start):
    """The argument text of the call whose '(' ends the match at `start`."""
    depth = 0
    for j in range(start - 1, len(code)):
        if code[j] == "(":
            depth += 1
        elif code[j] == ")":
            depth -= 1
            if depth == 0:
                return code[start:j]
    return code[start:]


def check_cli(root):
    src = root / "crates/hysid-cli/src"
    files = sorted(src.rglob("*.rs"))
    skip = test_files(src, files)
    problems = []
    for path in files:
        if path in skip:
            continue
        code, _ = blank_test_modules(strip_comments_and_strings(path.read_text()))
        rel = path.relative_to(root)

        def flag(pos, message):
            problems.append(f"{rel}:{code.count(chr(10), 0, pos) + 1}: {message}")

        for m in re.finditer(r"hysid\s*::\s*numerics\s*::\s*([\w:]*)(\{[^}]*\})?", code):
            items = [m.group(1).rstrip(":").split("::")[-1]] if not m.group(2) else [
                s.strip().split("::")[-1] for s in m.group(2)[1:-1].split(",") if s.strip()
            ]
            for item in items:
                if item and item[0].islower() and item != "self":
                    flag(m.start(), f"uses hysid::numerics::…{item} (not a type): numerical code belongs in the library")
        for m in re.finditer(r"(?<![\w:])metrics\s*::\s*(\w+)", code):
            flag(m.start(), f"computes a fit metric (metrics::{m.group(1)}): the library's report should carry it")
        for m in CLOSURE_CALL.finditer(code):
            body = closure_body(code, m.end())
            if re.search(FLOAT_METHOD, body) or re.search(FLOAT_ARITH, body):
                flag(m.start(), f"floating-point arithmetic in .{m.group(1)}(…) over data")
        for m in re.finditer(r"\.(sum|product)\s*::\s*<\s*f64\s*>", code):
            flag(m.start(), f"floating-point .{m.group(1)}::<f64>() over data")
        for m in re.finditer(r"[-+*/]=(?!=)", code):
            rhs = code[m.end():code.find(";", m.end())].strip()
            textual = rhs == "" or rhs.startswith(("&", "format!", "'"))
            if code[m.start() - 1] in "<>=!" or textual or re.fullmatch(r"\d+", rhs):
                continue
            flag(m.start(), "compound arithmetic assignment (an accumulation over samples?)")
    return problems


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    library_only = "--library-only" in sys.argv[1:]
    root = Path(args[0] if args else Path(__file__).resolve().parent.parent)
    library = check_library(root)
    cli = [] if library_only else check_cli(root)
    for line in library + cli:
        print(line)
    print(
        f"check_layers: {len(library)} layer violation(s) in crates/hysid, "
        f"{len(cli)} numerical-code finding(s) in crates/hysid-cli"
    )
    return 1 if library or cli else 0


if __name__ == "__main__":
    sys.exit(main())
