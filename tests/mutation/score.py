"""The mutation score of the CI gate: ``python -m tests.mutation.score [--suite S] [--mutant ID] [--keep DIR]``.

Runs the faithful copy and the catalogue's mutants on the quick profile of each suite (each mutant only on the
suites its bug lives in; :mod:`tests.mutation.campaign`) and prints a Markdown table: mutant, kind, suite,
caught (a violation naming it on a row the faithful copy passes), the first such violation, violations wrongly
naming core, and the wall time of its run. A run of the default suite with six copies beside core takes ~30
minutes on 2 shared cores; the whole catalogue on all three suites a few hours.

``--recheck DIR`` judges the runs a ``--keep DIR`` campaign kept against the tolerances as they are now (seconds;
a gate that adds metrics needs new runs).
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import tempfile
from pathlib import Path

import simparity
from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES
from tests.mutation.campaign import SuiteScore, recheck_suite, score_suite, score_witnesses
from tests.mutation.catalogue import MUTANTS, by_id
from tests.mutation.copy_of_core import FAITHFUL_NAME
from tests.mutation.gate import Violation
from tests.mutation.mutation import SUITES

LINE_LIMIT = 180
"""Characters of a violation line shown in the table (``simparity check RUN`` prints them whole)."""


def _cell(text: str) -> str:
    text = text if len(text) <= LINE_LIMIT else text[:LINE_LIMIT - 3] + "..."
    return text.replace("|", "\\|") or "-"


def _lines(violations: tuple[Violation, ...]) -> str:
    return f"{len(violations)}: {_cell(violations[0].line)}" if violations else "-"


def table(scores: list[SuiteScore]) -> list[str]:
    """The Markdown table of every verdict, the faithful copy first in each suite, and the score line."""
    kinds = {m.id: m.kind for m in MUTANTS}
    lines = ["| mutant | kind | suite | caught | first violation naming it | wrong blame | wall time |",
             "|---|---|---|---|---|---|---|"]
    caught = total = 0
    for score in scores:
        base = score.baseline
        own = base.naming(FAITHFUL_NAME)
        verdict = "passes (exit 0)" if base.exit_code == 0 else f"**fails**: {len(own)} violations name it"
        lines.append(f"| (faithful copy) | - | {score.suite} | {verdict} | {_cell(own[0].line if own else '')} | "
                     f"core's own {_lines(base.naming('core'))} | {base.seconds:.0f} s |")
        for mutant_id, found in score.verdicts.items():
            shared = next(len(r.engines) - 1 for r in score.runs if found.engine in r.engines)
            together = f" (run of {shared})" if shared > 1 else ""
            lines.append(f"| {mutant_id} | {kinds.get(mutant_id, '?')} | {score.suite} | "
                         f"{'yes' if found.caught else '**no**'} | {_cell(found.first)} | {_lines(found.wrong_blame)} | "
                         f"{found.seconds:.0f} s{together} |")
            caught += found.caught
            total += 1
    lines += ["", f"mutation score: {caught} of {total} (mutant, suite) pairs caught"]
    return lines


def gate_identity() -> str:
    """Which simparity and which shipped tolerances judged the runs (the gate may change between two scores)."""
    digest = hashlib.sha256(Path(DEFAULT_TOLERANCES).read_bytes()).hexdigest()[:12]
    return f"gate: simparity at {Path(simparity.__file__).parent}, tolerances sha256 {digest}"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.mutation.score", description=__doc__.splitlines()[0])
    parser.add_argument("--suite", action="append", choices=SUITES, help="a suite (repeatable; default: all)")
    parser.add_argument("--mutant", action="append", help="a mutant id (repeatable; default: the whole catalogue)")
    parser.add_argument("--keep", type=Path, help="a new folder to keep the runs in (default: a temporary one)")
    parser.add_argument("--recheck", type=Path, help="judge the runs kept in this folder again; runs nothing")
    parser.add_argument("--witness", action="store_true",
                        help="run each mutant on its witness scene of the suite alone (minutes, not hours; a catch "
                        "there is a catch by the suite, a miss says nothing)")
    args = parser.parse_args(argv)
    suites = args.suite or SUITES
    scores = []
    if args.recheck:
        scores = [recheck_suite(args.recheck / s) for s in suites if (args.recheck / s).is_dir()]
    else:
        mutants = [by_id(i) for i in args.mutant] if args.mutant else list(MUTANTS)
        with tempfile.TemporaryDirectory(prefix="simparity-mutation-") as scratch:
            for suite in suites:
                root = (args.keep or Path(scratch)) / suite
                done = score_witnesses(suite, mutants, root) if args.witness else [score_suite(suite, mutants, root)]
                scores += done
                print("\n".join(table(done)), file=sys.stderr, flush=True)  # progress: a suite takes long
    print("\n".join([gate_identity(), ""] + table(scores)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
