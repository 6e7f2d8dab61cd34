"""The gate against the catalogue: every mutant on the quick profile of each suite its bug lives in.

Per suite, first the baseline (core beside the faithful copy), then the mutants in batches: several copies share
one run (violation lines name their engine, and each engine's cases run in processes of their own), except a
mutant whose bug reaches other engines' rows (:func:`tests.mutation.catalogue.judges_others`), which runs alone
so that a violation naming core is its doing. A batch holds at most :data:`BATCH_SIZE` copies, so a run that
gives no verdict loses few. The runs are kept in the campaign's folder and can be judged again
(:func:`recheck_suite`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simparity.comparisons.scenes import library
from tests.mutation.catalogue import judges_others
from tests.mutation.copy_of_core import FAITHFUL_NAME, MUTANT_NAME, materialise
from tests.mutation.gate import GateRun, Verdict, check_run, run_gate, verdicts
from tests.mutation.mutation import Mutation

BATCH_SIZE = 6
"""Copies per run beside core: each adds about core's own cost to the run, so six keep a batch of the default
suite within ~30 minutes on 2 shared cores while saving five runs' fixed cost (planning, probes, report)."""

FAITHFUL_RUN = "faithful"
BATCH_RUN = "batch-{number}"
WITNESS_RUN = "{scene}-{part}"
"""The folders of a suite's runs in the campaign's folder."""


@dataclass
class SuiteScore:
    """One suite: the faithful copy's run (the baseline) and each mutant's verdict, by mutant id."""

    suite: str
    baseline: GateRun
    verdicts: dict[str, Verdict] = field(default_factory=dict)
    runs: list[GateRun] = field(default_factory=list)

    def add(self, run: GateRun) -> None:
        """A batch's run and the verdicts of its copies (engines ``mutant-<id>``)."""
        self.runs.append(run)
        names = list(run.engines[1:])
        prefix = MUTANT_NAME.format(id="")
        for verdict in verdicts(run, names, self.baseline, FAITHFUL_NAME):
            self.verdicts[verdict.engine.removeprefix(prefix)] = verdict


def batches(mutants: list[Mutation]) -> list[list[Mutation]]:
    """Runs of one suite: each mutant that judges others alone, the rest :data:`BATCH_SIZE` at a time."""
    alone = [[m] for m in mutants if judges_others(m)]
    shared = [m for m in mutants if not judges_others(m)]
    return alone + [shared[i:i + BATCH_SIZE] for i in range(0, len(shared), BATCH_SIZE)]


def score_suite(suite: str, mutants: list[Mutation], root: Path) -> SuiteScore:
    """Materialise the faithful copy and ``mutants`` (those whose ``suites`` include ``suite``) under ``root``
    (a fresh folder), run the baseline and the batches, and collect the verdicts."""
    root.mkdir(parents=True, exist_ok=False)
    copies_root = root / "copies"
    copies_root.mkdir()
    score = SuiteScore(suite, run_gate([materialise(None, copies_root)], suite, root / FAITHFUL_RUN))
    chosen = [m for m in mutants if suite in m.suites]
    for number, batch in enumerate(batches(chosen)):
        score.add(run_gate([materialise(m, copies_root) for m in batch], suite, root / BATCH_RUN.format(number=number)))
    return score


def score_witnesses(suite: str, mutants: list[Mutation], root: Path) -> list[SuiteScore]:
    """The gate on each mutant's witness scene alone (its quick profile), a run per witness: the faithful copy
    first (the baseline), then the mutants that witness shares, in batches as :func:`batches` forms them.

    Mutants whose witness is not a scene of ``suite`` are left out. A catch here is a catch by ``suite``: every verdict is about one row of one scene, and a scene's rows do
    not depend on the other scenes of the run. A miss here says nothing of the whole suite (run
    :func:`score_suite`). Minutes where the whole suite takes hours: the mutants' witnesses are a dozen of its
    scenes, each run once per batch."""
    root.mkdir(parents=True, exist_ok=False)
    copies_root = root / "copies"
    copies_root.mkdir()
    faithful = materialise(None, copies_root)
    in_suite = {scene.name for scene in library.suite(suite)}
    chosen = [m for m in mutants if suite in m.suites and m.witness in in_suite]  # others: score_suite
    scores = []
    for scene in sorted({m.witness for m in chosen}):
        scenes = (scene,)
        label = f"{suite}:{scene}"
        score = SuiteScore(label, run_gate([faithful], suite, root / WITNESS_RUN.format(scene=scene, part=FAITHFUL_RUN),
                                           scenes))
        for number, batch in enumerate(batches([m for m in chosen if m.witness == scene])):
            out = root / WITNESS_RUN.format(scene=scene, part=BATCH_RUN.format(number=number))
            score.add(run_gate([materialise(m, copies_root) for m in batch], suite, out, scenes))
        scores.append(score)
    return scores


def recheck_suite(root: Path) -> SuiteScore:
    """The verdicts of the tolerances as they are now on the runs :func:`score_suite` kept in ``root``."""
    baseline = check_run(root / FAITHFUL_RUN)
    score = SuiteScore(baseline.suite, baseline)
    number = 0
    while (root / BATCH_RUN.format(number=number)).is_dir():
        score.add(check_run(root / BATCH_RUN.format(number=number)))
        number += 1
    return score
