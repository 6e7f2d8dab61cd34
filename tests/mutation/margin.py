"""How wide a catch is: ``python -m tests.mutation.margin --mutant ID [--mutant ID] SCENE [SCENE ...] [--keep DIR]``.

A catch at 1.07 x its bound is one faithful implementations' spread away from a miss; a mutant should have witness
scenes that catch it by a wide margin. For each scene alone (its quick profile) this runs the faithful copy, then the
mutants, beside core (:func:`tests.mutation.gate.run_gate`), and prints per scene the violations naming the mutant (on
rows the faithful copy passes) with each one's margin: how many times over its bound the value is (value / bound for
an upper bound, bound / value for a lower one, the side it left for a range). A verdict (diverged, saturated, a
status) has no ratio: its margin is reported as ``verdict``.
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from tests.mutation.campaign import batches
from tests.mutation.catalogue import by_id
from tests.mutation.copy_of_core import FAITHFUL_NAME, MUTANT_NAME, CoreCopy, materialise
from tests.mutation.gate import GateRun, Verdict, Violation, check_run, run_gate, verdicts

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_FOUND_AND_BOUND = re.compile(
    rf"(?P<found>[^:]*), bound (?P<op><=|>=|in) \[?(?P<low>{_NUMBER})(?:, (?P<high>{_NUMBER})\])?")
"""``...: <found>, bound <= X`` / ``>= X`` / ``in [X, Y]`` in a violation line (comparisons/gate/violation.py)."""

_VALUE = re.compile(rf"(?<![\w.]){_NUMBER}(?![\w.])")
"""The first number of the found part (a grouped line may name a metric before it)."""


@dataclass(frozen=True)
class Catch:
    """One violation naming the mutant and its margin (None: a verdict, no ratio)."""

    violation: Violation
    margin: float | None


def margin(line: str) -> float | None:
    """How many times over its bound a violation line's value is; None for a verdict (no number against a bound)."""
    match = _FOUND_AND_BOUND.search(line)
    value = _VALUE.search(match.group("found")) if match else None
    if match is None or value is None:
        return None
    found, low = float(value.group(0)), float(match.group("low"))
    op, high = match.group("op"), match.group("high")
    if op == "<=" or (high is not None and found > float(high)):
        bound = low if op == "<=" or high is None else float(high)
        return found / bound if bound > 0 else math.inf
    return low / found if found > 0 else math.inf


def catches(verdict: Verdict) -> list[Catch]:
    """The violations of ``verdict``, widest margin first (verdicts last)."""
    found = [Catch(v, margin(v.line)) for v in verdict.violations]
    return sorted(found, key=lambda c: -1.0 if c.margin is None else c.margin, reverse=True)


def _gate(copies: list[CoreCopy], out: Path, scene: str) -> GateRun:
    """The run of ``copies`` beside core on ``scene`` into ``out``; a run kept there already is judged again."""
    return check_run(out) if out.is_dir() else run_gate(copies, "default", out, (scene,))


def measure(mutant_ids: list[str], scenes: list[str], root: Path) -> dict[tuple[str, str], list[Catch]]:
    """Per (mutant, scene), the mutant's catches beyond the faithful copy's violations: per scene the faithful copy's
    run, then the mutants' in batches (:func:`tests.mutation.campaign.batches`). The runs are kept under ``root``;
    measuring again into the same folder judges the kept runs again (and runs only what is missing)."""
    root.mkdir(parents=True, exist_ok=True)
    copies = Path(tempfile.mkdtemp(prefix="copies-", dir=root))  # fresh: a run names its engines, not its folder
    faithful = materialise(None, copies)
    mutants = [[materialise(m, copies) for m in batch] for batch in batches([by_id(i) for i in mutant_ids])]
    out = {}
    for scene in scenes:
        base = _gate([faithful], root / f"{scene}-faithful", scene)
        for number, batch in enumerate(mutants):
            run = _gate(batch, root / f"{scene}-batch-{number}", scene)
            for verdict in verdicts(run, [c.engine_name for c in batch], base, FAITHFUL_NAME):
                out[(verdict.engine.removeprefix(MUTANT_NAME.format(id="")), scene)] = catches(verdict)
    return out


def table(found: dict[tuple[str, str], list[Catch]]) -> list[str]:
    """Markdown rows: mutant, scene, lines naming it, the widest margin and its line."""
    rows = ["| mutant | scene | lines naming it | widest margin | its line |", "|---|---|---|---|---|"]
    for (mutant_id, scene), caught in sorted(found.items()):
        widest = caught[0] if caught else None
        shown = "-" if widest is None else "verdict" if widest.margin is None else f"{widest.margin:.3g} x"
        line = widest.violation.line.replace("|", "\\|") if widest else "not caught"
        rows.append(f"| {mutant_id} | {scene} | {len(caught)} | {shown} | {line} |")
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.mutation.margin", description=__doc__.splitlines()[0])
    parser.add_argument("--mutant", action="append", required=True, help="a mutant id of tests/mutation/catalogue.py "
                        "(repeatable)")
    parser.add_argument("scenes", nargs="+", help="built-in scenes, each run alone")
    parser.add_argument("--keep", type=Path, help="a new folder to keep the runs in (default: a temporary one)")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="simparity-margin-") as scratch:
        found = measure(args.mutant, args.scenes, args.keep or Path(scratch) / "runs")
    print("\n".join(table(found)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
