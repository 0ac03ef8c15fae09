#!/usr/bin/python3
"""Prints the path of one executable that cargo built, read from cargo's JSON
messages on standard input (`--message-format=json`), so the Makefile does not
depend on the wording or layout of cargo's human-readable output.

usage: cargo ... --message-format=json | cargo_executable.py KIND NAME

KIND is the target kind (bin, test, bench, example), NAME the target name,
e.g. `cargo test --release --test mpi --no-run --message-format=json |
scripts/cargo_executable.py test mpi`. Exits with status 1 and one line on
standard error when cargo reported a build error or built no such executable.
"""
import json
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: cargo ... --message-format=json | cargo_executable.py KIND NAME")
    kind, name = sys.argv[1], sys.argv[2]
    found = None
    failed = False
    for line in sys.stdin:
        try:
            message = json.loads(line)
        except json.JSONDecodeError:
            continue  # not a message (cargo's JSON lines are one object each)
        reason = message.get("reason")
        if reason == "compiler-message" and message.get("message", {}).get("level") == "error":
            failed = True
            rendered = message["message"].get("rendered") or message["message"].get("message", "")
            sys.stderr.write(rendered)
        elif reason == "build-finished" and not message.get("success", True):
            failed = True
        elif reason == "compiler-artifact" and message.get("executable"):
            target = message.get("target", {})
            if target.get("name") == name and kind in target.get("kind", []):
                found = message["executable"]
    if failed or found is None:
        what = "the build failed" if failed else "cargo built no such executable"
        sys.exit(f"cargo_executable: no {kind} target '{name}': {what}")
    print(found)


if __name__ == "__main__":
    main()
