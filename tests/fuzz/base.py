"""The valid inputs the families damage, made once per session: a stored run and its history database."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

from tests.fuzz.oracle import Base

TINY_SCENE = """[scene]
name = "fuzz-tiny"
kind = "dynamics"
reference = "analytic"

[world]
gravity_world = [0.0, 0.0, -9.81]

[[body]]
name = "ball"
mass = 1.0
inertia_body_diagonal = [0.1, 0.1, 0.1]
velocity_world = [1.0, 0.0, 0.0]

[simulation]
duration = 0.1
dt = [0.01, 0.005]
"""
"""A dynamics scene of 20 steps at most: what options that need ``simparity run`` are tried with."""

STORED_SCENE = "lecture-projectile"
"""The stored run's scene: cheap (2,700 steps per integrator, quick), bounded by the shipped tolerances, so its check
passes (exit 0) untouched."""


def make_base(folder: Path) -> Base:
    """A stored run of :data:`STORED_SCENE` on core (quick profile), recorded in a history database of its own."""
    from simparity.comparisons.cli.main import main

    folder.mkdir(parents=True, exist_ok=True)
    run, history, scene = folder / "run", folder / "history.sqlite", folder / "tiny.toml"
    scene.write_text(TINY_SCENE, encoding="utf-8")
    out = io.StringIO()
    with contextlib.redirect_stderr(io.StringIO()) as err:
        code = main(["run", STORED_SCENE, "--quick", "--engines", "core", "--jobs", "1", "--out", str(run),
                     "--history", str(history)], out)
    if code != 0:
        raise RuntimeError(f"the valid run failed (exit {code}): {out.getvalue()[-500:]} {err.getvalue()[-500:]}")
    return Base(run_dir=run, history=history, scene=scene)
