"""``run.json``: what a stored run was (when, by which command and commit, on which machine, with which engines
and scenes), written and read through one dataclass, :class:`RunInfo`."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path

from simparity.core.model.errors import ResultsError, one_line
from simparity.core.model.json_input import (
    COUNT,
    NUMBER,
    POSITIVE,
    SCALAR,
    TEXT,
    WHOLE,
    JSONInputError,
    Shape,
    list_of,
    read_json,
    record,
    table_of,
)
from simparity.core.model.metric_catalogue import JOINT_ANGLE_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX
from simparity.core.model.results import READ_SCHEMA_VERSIONS, SCHEMA_VERSION

MAX_RUN_INFO_BYTES = 64_000_000
"""Largest ``run.json`` read [bytes]: a scene's entry is under 1 kB, and a run of 1,000 swept variants (the most one
file expands into) with the built-in scenes writes about 1 MB."""

_ALLOWED = "the run.json 'simparity run' wrote"
SCENE_HEADLINES = (POSITION_ERROR_MAX, ORIENTATION_ERROR_MAX, JOINT_ANGLE_ERROR_MAX)
"""The errors a report ranks a scene's schemes by (a dynamics scene's position or orientation error, a chain in
motion's joint angle error): the only ``headline_metric`` a run records."""
_HEADLINE = Shape(f"one of {', '.join(SCENE_HEADLINES)}", lambda v: v in SCENE_HEADLINES)
_SCENE = record(
    "a table of what the run recorded of a scene",
    kind=TEXT, description=TEXT, reference=TEXT, source=TEXT, suites=list_of(TEXT), bodies=COUNT,
    headline_metric=_HEADLINE, segments=COUNT, position_tolerance=NUMBER,
    contact=record("a table of the scene's contact", planes=list_of(TEXT), restitution=list_of(list_of(NUMBER)),
                   methods=list_of(TEXT), rest_speed=NUMBER),
    sweep=record("a table of the variant's sweep", base=TEXT, index=COUNT, count=COUNT, values=table_of(NUMBER)))
RUN_INFO_SHAPE = record(
    f"a table (JSON object): {_ALLOWED}",
    schema_version=WHOLE, created_utc=TEXT, command=TEXT, git_commit=TEXT, profile=TEXT,
    machine=table_of(SCALAR), engine_versions=table_of(TEXT), theoretical_orders=table_of(table_of(POSITIVE)),
    integrator_variants=table_of(table_of(list_of(TEXT, 2))), scenes=table_of(_SCENE), peak_memory=table_of(COUNT))
"""What each key of ``run.json`` holds (the keys a report, the gate and the history read); keys a newer writer
added are left out."""


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
        """The information in ``path``; raises ResultsError in one line naming the file and the key for a file that is
        not a run.json this simparity reads: not a regular file, larger than :data:`MAX_RUN_INFO_BYTES`, not JSON,
        nested too deeply or holding too long an integer (:func:`core.model.json_input.read_json`), another schema
        version, a key holding what :data:`RUN_INFO_SHAPE` does not allow. Fields a newer writer added are left out."""
        try:
            data = read_json(Path(path), MAX_RUN_INFO_BYTES, _ALLOWED)
        except JSONInputError as err:
            raise ResultsError(f"{one_line(path)}: {err}") from None
        problem = RUN_INFO_SHAPE.problem(data)
        if problem:
            raise ResultsError(f"{one_line(path)}: {problem}")
        assert isinstance(data, dict)  # the shape's first test
        if data.get("schema_version") not in READ_SCHEMA_VERSIONS:
            raise ResultsError(f"{one_line(path)}: schema_version {data.get('schema_version')!r:.20} (allowed: "
                               f"{', '.join(map(str, READ_SCHEMA_VERSIONS))}, the versions this simparity reads)")
        known = {f.name for f in dataclasses.fields(cls)}
        return cls(**{key: value for key, value in data.items() if key in known})
