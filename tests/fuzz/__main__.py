"""``python -m tests.fuzz [--only TEXT ...] [--base DIR] [--keep DIR]``: try every fuzzed input (or those whose id
holds one of the TEXTs) and print the failures grouped by class, each class with its count and one input's
reproduction (the command line, on the input kept under --keep). The valid run the inputs are made from is made once
into --base (reused when it is there)."""

from __future__ import annotations

import argparse
import shlex
import sys
import tempfile
import time
from collections import defaultdict
from functools import partial
from pathlib import Path

from tests.fuzz.base import make_base
from tests.fuzz.families import all_cases
from tests.fuzz.oracle import Base, Call, failure_class, judge, try_call


def _base(folder: Path) -> Base:
    if (folder / "run" / "run.json").is_file():
        return Base(folder / "run", folder / "history.sqlite", folder / "tiny.toml")
    return make_base(folder)


def _reproduction(call: Call) -> str:
    if isinstance(call.function, partial):  # read_run(path), the one library call tried
        return f"python -c 'import simparity; simparity.read_run({str(call.function.args[0])!r})'"
    return "simparity " + shlex.join(call.argv)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz")
    parser.add_argument("--only", action="append", default=[], help="only the inputs whose id holds this text "
                        "(repeatable: any of them; a family's inputs: --only run_results/)")
    parser.add_argument("--base", type=Path, default=Path(tempfile.gettempdir()) / "simparity-fuzz-base")
    parser.add_argument("--keep", type=Path, default=None, help="folder to keep every input in (default: a new one)")
    args = parser.parse_args(argv)
    base = _base(args.base)
    keep = args.keep or Path(tempfile.mkdtemp(prefix="simparity-fuzz-"))
    failures: dict[str, list[tuple[str, str, str]]] = defaultdict(list)
    chosen = [case for case in all_cases() if not args.only or any(text in case.id for text in args.only)]
    start = time.perf_counter()
    for k, case in enumerate(chosen):
        folder = keep / f"{k:04d}"
        folder.mkdir(parents=True)
        call = case.build(folder, base)
        verdict = judge(case, call, try_call(call, folder))
        print(f"{case.id}: {verdict or 'ok'}", flush=True)
        if verdict:
            failures[f"{case.family}: {failure_class(verdict)}"].append((case.id, verdict, _reproduction(call)))
    print(f"\n{len(chosen)} inputs in {time.perf_counter() - start:.0f} s, {sum(map(len, failures.values()))} failing; "
          f"inputs kept in {keep}")
    for name, items in sorted(failures.items()):
        print(f"\n{name}: {len(items)}")
        print(f"  e.g. {items[0][2]}\n       -> {items[0][1][:300]}")
        for case_id, _, _ in items:
            print(f"  - {case_id}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
