"""Writing a stored run: ``results.csv`` and ``series.csv.gz`` (appended scene by scene) and ``run.json``."""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from simparity.comparisons.measure.metrics import headline_metric
from simparity.core.model.engine import Engine
from simparity.core.model.results import (
    COLUMNS,
    RESULTS_FILE,
    RESULTS_PARQUET_FILE,
    RUN_INFO_FILE,
    SCHEMA_VERSION,
    SERIES_COLUMNS,
    SERIES_FILE,
    SWEEP_COLUMN,
    ResultRow,
    SeriesRecord,
    sweep_column,
)
from simparity.core.model.run_info import RunInfo
from simparity.core.model.metric_catalogue import JOINT_ANGLE_ERROR_MAX
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_motion import JointMotionScene

DEFAULT_OUT_ROOT = Path("simparity-results")
"""Default parent folder of runs: each run goes to ``simparity-results/<UTC time>/``."""


def default_out_dir() -> Path:
    """A new folder ``simparity-results/<UTC date-time>[-k]/`` that does not exist yet."""
    stamp = DEFAULT_OUT_ROOT / dt.datetime.now(dt.timezone.utc).strftime("%Y%m%d-%H%M%S")
    candidate, k = stamp, 1
    while candidate.exists():
        candidate, k = stamp.with_name(f"{stamp.name}-{k}"), k + 1
    return candidate


def git_commit() -> str:
    """``git describe``-style commit of the project source (``unknown`` outside a checkout)."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=here, capture_output=True, text=True, timeout=10,
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() if out.returncode == 0 and out.stdout.strip() else "unknown"


def machine() -> dict:
    return {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
    }


def _orders(engine: Engine) -> dict[str, int]:
    orders = {i: engine.theoretical_order(i) for i in engine.integrators()}
    return {i: order for i, order in orders.items() if order is not None}


def _variants(engine: Engine) -> dict[str, list[str]]:
    """{integrator: [scheme, variant]} of the integrators that are variants of a scheme."""
    parts = {i: list(engine.integrator_variant(i)) for i in engine.integrators()}
    return {i: p for i, p in parts.items() if p[1]}


def _scene_info(scene) -> dict:
    """What a report needs of a scene beside its rows: what it is, where from, and for dynamics
    the number of bodies (per-call overhead), the error its schemes are ranked by and, with contact, the
    planes, the requested restitution (body x plane), core's methods and the rest speed; for a variant of a
    sweep, :class:`core.scene.SweepPoint` (base, index, count, values: {key: value} in the sweep's order)."""
    info = {"kind": scene.kind, "description": scene.description, "reference": scene.reference,
            "source": scene.source, "suites": list(scene.suites)}
    if isinstance(scene, DynamicsScene):
        info |= {"bodies": len(scene.bodies), "headline_metric": headline_metric(scene)}
        if scene.contact is not None:
            info["contact"] = {"planes": [p.name for p in scene.contact.planes],
                               "restitution": scene.contact.restitution.tolist(),
                               "methods": list(scene.contact.methods), "rest_speed": scene.contact.rest_speed}
    if isinstance(scene, JointMotionScene):  # reported as dynamics: its schemes ranked by the joint angle error
        info |= {"bodies": scene.copies, "headline_metric": JOINT_ANGLE_ERROR_MAX, "segments": scene.segments}
    if isinstance(scene, IKScene):
        info |= {"position_tolerance": scene.position_tolerance}
    if scene.sweep is not None:
        info["sweep"] = {"base": scene.sweep.base, "index": scene.sweep.index, "count": scene.sweep.count,
                         "values": dict(scene.sweep.values)}
    return info


def sweep_cells(scenes: list) -> tuple[list[str], dict[str, dict[str, object]]]:
    """(the columns a run's sweeps add to :data:`core.results.COLUMNS`, {scene name: {column: value}} of each
    swept scene). No columns when no scene was swept; else :data:`core.results.SWEEP_COLUMN` (the base
    scene's name), then one column per swept key in the order the scenes first sweep it."""
    columns: list[str] = []
    cells = {}
    for scene in scenes:
        if scene.sweep is None:
            continue
        cells[scene.name] = {SWEEP_COLUMN: scene.sweep.base} | {sweep_column(k): v for k, v in scene.sweep.values}
        columns += [column for column in cells[scene.name] if column not in columns]
    return columns, cells


def _series_frame(series: Sequence[SeriesRecord]) -> pd.DataFrame:
    """The points of ``series`` as rows of :data:`SERIES_COLUMNS`: each record's keys repeated along its points."""
    lengths = [len(record.x) for record in series]
    keys = {column: np.repeat([getattr(record, column) for record in series], lengths)
            for column in SERIES_COLUMNS if column not in ("x", "value")}
    return pd.DataFrame(keys | {"x": np.concatenate([r.x for r in series]),
                                "value": np.concatenate([r.value for r in series])}, columns=list(SERIES_COLUMNS))


class RunWriter:
    """Appends rows to ``results.csv`` and series to ``series.csv.gz`` as they are produced, so nothing
    computed is lost; :meth:`finish` adds ``results.parquet`` (pyarrow installed). A run of swept scenes
    (``scenes``) has the sweep columns of :func:`sweep_cells` after the fixed ones, filled from each row's scene."""

    def __init__(self, out_dir: Path, engines: list[Engine], command: str, scenes: list, profile: str = "") -> None:
        self.out_dir = Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.results_path = self.out_dir / RESULTS_FILE
        self.series_path = self.out_dir / SERIES_FILE
        (self.out_dir / RESULTS_PARQUET_FILE).unlink(missing_ok=True)  # a new (or resumed) run's CSV starts afresh
        self._sweep_columns, self._sweep_cells = sweep_cells(scenes)
        pd.DataFrame(columns=list(COLUMNS) + self._sweep_columns).to_csv(self.results_path, index=False)
        pd.DataFrame(columns=list(SERIES_COLUMNS)).to_csv(self.series_path, index=False)
        RunInfo(
            schema_version=SCHEMA_VERSION,
            created_utc=dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
            command=command,
            git_commit=git_commit(),
            machine=machine(),
            engine_versions={e.name: e.version() for e in engines},
            theoretical_orders={e.name: orders for e in engines if (orders := _orders(e))},
            integrator_variants={e.name: variants for e in engines if (variants := _variants(e))},
            scenes={s.name: _scene_info(s) for s in scenes},
            profile=profile,
        ).write(self.out_dir / RUN_INFO_FILE)

    def append(self, rows: list[ResultRow], series: Sequence[SeriesRecord] = ()) -> None:
        frame = pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))
        for column in self._sweep_columns:
            # object cells: an int stays an int, a float is written as its shortest exact text, "" is no value
            frame[column] = pd.Series([self._sweep_cells.get(r.scene, {}).get(column, "") for r in rows], dtype=object)
        frame.to_csv(self.results_path, mode="a", header=False, index=False, float_format="%.17g")
        if series:
            # Each append is one more gzip member; readers (gzip, pandas) read the members as one file.
            points = _series_frame(series)
            points.to_csv(self.series_path, mode="a", header=False, index=False, float_format="%.9g")

    def finish(self) -> None:
        """The run's rows are all appended (it ended, or was interrupted): ``results.parquet``, the typed copy of
        ``results.csv``, when pyarrow is installed."""
        from simparity.reports.store import write_parquet

        write_parquet(self.out_dir)
