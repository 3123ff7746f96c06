#!/usr/bin/python3
"""Validates every level in a folder against scene.schema.json (2020-12).

Usage: validate_levels_schema.py FOLDER [EXTRA.json ...]. Extra files (for
example a running state written by `stepwise run --out`, with its
`solver_state`) are checked against FOLDER's schema too.

Uses Debian's python3-jsonschema. Exits 1 naming each failing file and the
JSON path of the first problem, 0 when every level validates.
"""
import json
import pathlib
import sys

import jsonschema


def main() -> int:
    folder = pathlib.Path(sys.argv[1])
    schema = json.loads((folder / "scene.schema.json").read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    levels = sorted(p for p in folder.glob("*.json") if p.name != "scene.schema.json")
    levels += [pathlib.Path(extra) for extra in sys.argv[2:]]
    failures = 0
    for level in levels:
        errors = sorted(validator.iter_errors(json.loads(level.read_text())), key=lambda e: list(e.path))
        for error in errors[:3]:
            failures += 1
            where = "/" + "/".join(str(p) for p in error.path)
            print(f"{level}: {where}: {error.message}")
    print(f"{len(levels)} levels checked against {folder / 'scene.schema.json'}: "
          f"{failures} problems")
    if not levels:
        print("no levels found")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
