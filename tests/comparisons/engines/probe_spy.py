"""Counting the probe processes a command starts (:mod:`comparisons.engines.probe`), by the engine they describe."""

from __future__ import annotations

from collections import Counter

import pytest

from simparity.comparisons.engines import probe as engine_probe


def counted_probes(monkeypatch: pytest.MonkeyPatch) -> Counter:
    """A Counter of the probes started from now on (until ``monkeypatch`` is undone), by engine spec: each still
    starts its process."""
    started: Counter = Counter()

    class Counted(engine_probe._Probe):
        def __init__(self, name: str, scenes: list) -> None:
            started[name] += 1
            super().__init__(name, scenes)

    monkeypatch.setattr(engine_probe, "_Probe", Counted)
    return started
