"""Watching the probe processes a command starts (:mod:`comparisons.engines.probe`): how many per engine, and what
each answered."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import pytest

from simparity.comparisons.engines import probe as engine_probe
from simparity.core.model.engine import Engine


@dataclass
class ProbeSpy:
    """The probes started since :func:`spy_probes`, by engine spec, and the last answer of each (a
    :class:`~comparisons.engines.probe.DescribedEngine` or the engine standing in for one that cannot run)."""

    started: Counter = field(default_factory=Counter)
    answers: dict[str, Engine] = field(default_factory=dict)
    processes: list = field(default_factory=list)
    """Every probe's process (a ``subprocess.Popen``), in the order started."""


def spy_probes(monkeypatch: pytest.MonkeyPatch) -> ProbeSpy:
    """A :class:`ProbeSpy` of the probes from now on (until ``monkeypatch`` is undone): each still starts its process
    and answers as it would."""
    spy = ProbeSpy()

    class Spied(engine_probe._Probe):
        def __init__(self, name: str, scenes: list) -> None:
            spy.started[name] += 1
            super().__init__(name, scenes)
            spy.processes.append(self.process)

        def result(self) -> Engine:
            spy.answers[self.name] = answer = super().result()
            return answer

    monkeypatch.setattr(engine_probe, "_Probe", Spied)
    return spy
