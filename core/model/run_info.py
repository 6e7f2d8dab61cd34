"""``run.json``: what a stored run was (when, by which command and commit, on which machine, with which engines
and scenes), written and read through one dataclass, :class:`RunInfo`."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

from simparity.core.model.errors import ResultsError, one_line
from simparity.core.model.results import READ_SCHEMA_VERSIONS, SCHEMA_VERSION

_MAPPINGS = ("machine", "engine_versions", "theoretical_orders", "integrator_variants", "scenes", "peak_memory")


@dataclass(frozen=True)
class RunInfo:
    """A run's information (``run.json``).

    ``machine``: platform, CPUs, Python; ``engine_versions``: {engine: version}; ``theoretical_orders``:
    {engine: {integrator: order}} of the engines that declare any; ``integrator_variants``: {engine: {integrator:
    [scheme, variant]}} of those with variants; ``scenes``: {scene: what a report needs of it (kind, reference,
    suites, source, bodies, contact, sweep)}; ``profile``: the run profile (``full`` or ``quick``; "" for a run an
    older simparity wrote, which did not record it); ``peak_memory``: {``this_process_bytes``,
    ``largest_child_bytes``} [bytes], the peak resident memory of the run's process and of its largest child process
    (a case worker, or a child a worker forked), written when the run ends ({} for a run that did not record it)."""

    schema_version: int = SCHEMA_VERSION
    created_utc: str = ""
    command: str = ""
    git_commit: str = ""
    machine: dict = field(default_factory=dict)
    engine_versions: dict = field(default_factory=dict)
    theoretical_orders: dict = field(default_factory=dict)
    integrator_variants: dict = field(default_factory=dict)
    scenes: dict = field(default_factory=dict)
    profile: str = ""
    peak_memory: dict = field(default_factory=dict)

    def scene(self, name: str) -> dict:
        """What the run recorded of scene ``name`` ({} for a scene it did not run)."""
        return self.scenes.get(name, {})

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)

    def write(self, path: Path) -> None:
        Path(path).write_text(json.dumps(self.as_dict(), indent=2) + "\n", encoding="utf-8")

    @classmethod
    def read(cls, path: Path) -> "RunInfo":
        """The information in ``path``; raises ResultsError for a file that is not a run.json this simparity reads
        (unreadable, another schema version, a field of the wrong type). Fields a newer writer added are left out."""
        try:
            data = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as err:
            raise ResultsError(f"{one_line(path)}: unreadable: {one_line(err)} (allowed: the run.json 'simparity run' "
                               "wrote)") from None
        if not isinstance(data, dict):
            raise ResultsError(f"{one_line(path)}: not a run's information (allowed: the run.json 'simparity run' wrote)")
        if data.get("schema_version") not in READ_SCHEMA_VERSIONS:
            raise ResultsError(f"{path}: schema_version {data.get('schema_version')!r:.20} (allowed: "
                               f"{', '.join(map(str, READ_SCHEMA_VERSIONS))}, the versions this simparity reads)")
        known = {f.name for f in dataclasses.fields(cls)}
        values = {key: value for key, value in data.items() if key in known}
        for key in _MAPPINGS:
            if not isinstance(values.get(key, {}), dict):
                raise ResultsError(f"{path}: {key} is not a table (allowed: the run.json 'simparity run' wrote)")
        for key in ("created_utc", "command", "git_commit", "profile"):
            if not isinstance(values.get(key, ""), str):
                raise ResultsError(f"{path}: {key} is not text (allowed: the run.json 'simparity run' wrote)")
        return cls(**values)
