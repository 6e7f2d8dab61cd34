"""What ``run.json`` says of a session's run (:class:`core.model.run_info.RunInfo`): when, by which command and
commit, on which machine, with which engines (their versions, declared orders and variants) and scenes (what a
report needs of each)."""

from __future__ import annotations

import datetime as dt
import os
import platform
import subprocess
from pathlib import Path

from simparity.comparisons.measure.metrics import headline_metric
from simparity.core.model.engine import Engine
from simparity.core.model.metric_catalogue import JOINT_ANGLE_ERROR_MAX
from simparity.core.model.results import SCHEMA_VERSION
from simparity.core.model.run_info import RunInfo
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.joint_motion import JointMotionScene


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


def describe_run(engines: list[Engine], command: str, scenes: list, profile: str = "") -> RunInfo:
    """``run.json`` of a run of ``scenes`` on ``engines`` by ``command`` under ``profile``, created now."""
    return RunInfo(
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
    )
