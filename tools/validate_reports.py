#!/usr/bin/env python3
"""Validate hysid reports against the published JSON Schema.

Usage: validate_reports.py SCHEMA.json REPORT.json [REPORT.json ...]

Every report (and every report nested in ``details.steps``) must validate against the
schema generated from the library's types (``docs/schema/hysid.report.v1.json``). Uses the
``jsonschema`` package (an implementation independent of hysid's own serde types). Exits 1
when a report does not validate, 2 on usage errors.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import jsonschema


def nested_steps(report: dict[str, Any]) -> list[dict[str, Any]]:
    details = report.get("details")
    if isinstance(details, dict) and isinstance(details.get("steps"), list):
        return [s for s in details["steps"] if isinstance(s, dict)]
    return []


def main(argv: list[str]) -> int:
    if len(argv) < 3:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    schema = json.loads(Path(argv[1]).read_text())
    validator = jsonschema.Draft202012Validator(schema)
    failures = 0
    count = 0
    for name in argv[2:]:
        report = json.loads(Path(name).read_text())
        for part in [report, *nested_steps(report)]:
            count += 1
            for error in validator.iter_errors(part):
                failures += 1
                where = "/".join(str(p) for p in error.absolute_path)
                print(f"{name}: {where}: {error.message}", file=sys.stderr)
    print(f"{count} reports checked, {failures} schema violations")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
