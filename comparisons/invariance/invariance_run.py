"""``simparity run --transform NAME[,NAME]``: a run's invariance rows, computed on the run's own executor.

After a run's scenes are done, each is run again under the named fixed transforms
(:data:`comparisons.invariance.transforms.FIXED_TRANSFORMS`), and, where the comparison needs them, under one-ulp
perturbations, on the same engines, workers, limits and journal (so ``--resume`` keeps what finished); the
comparison (:mod:`comparisons.invariance.metamorphic`) gives each scene x engine x integrator x dt its invariance rows,
which join the run's results, report and ``--check``. Transformed runs are timed once: their times are not
compared.
"""

from __future__ import annotations

from simparity.comparisons.engines.probe import EngineProbes, asked_about
from simparity.comparisons.engines.registry import ENGINE_NAMES, make_engine
from simparity.comparisons.execute.execution import Executor, run_scenes
from simparity.comparisons.execute.journal import Journal
from simparity.comparisons.invariance.metamorphic import CHANGES_METRIC, RATIO_METRIC, check_invariance
from simparity.comparisons.invariance.transforms import Transform
from simparity.core.model.engine import Engine
from simparity.core.model.results import OK, ResultRow

INVARIANCE_REPEATS = 0
"""Timed repeats of a transformed or perturbed run: one cold call (timing is never compared)."""


def _built_in(name: str) -> Engine | None:
    """A built-in engine built here (a reference, a chain's FK resolution); None for a user's engine, which is
    never built in simparity's own process."""
    return make_engine(name) if name in ENGINE_NAMES else None


def invariance_rows(scenes: list, base_rows: list[list[ResultRow]], transforms: tuple[Transform, ...],
                    engines: list[Engine], executor: Executor, journal: Journal | None,
                    specs: dict[str, str] | None, probes: EngineProbes, say) -> list[list[ResultRow]]:
    """The invariance rows of each scene (in order) under ``transforms``, given its rows ``base_rows``; a user's
    engine is asked about the new scenes by its kept probe in ``probes``; ``say`` hears one line per scene."""
    def run(batch: list) -> list[list[ResultRow]]:
        described = asked_about(engines, batch, specs, probes)  # a user's engine knows only the run's own scenes
        return [rows for _, rows, _ in run_scenes(batch, described, make_engine, INVARIANCE_REPEATS, executor, journal,
                                                 None, specs)]

    out = []
    for item in check_invariance(scenes, transforms, run, _built_in, base_rows=base_rows):
        rows = item.rows()
        broken = sum(1 for r in rows if r.status == OK and ((r.metric.startswith(RATIO_METRIC) and r.value > 1)
                                                            or (r.metric.startswith(CHANGES_METRIC) and r.value > 0)))
        cases = sum(1 for r in rows if r.metric.startswith(RATIO_METRIC))
        say(f"{item.scene.name}: invariance under {', '.join(t.name for t in transforms)}: {cases} cases x transforms, "
            f"{broken} rows not invariant")
        out.append(rows)
    return out
