"""The standalone scripts in docs/examples that need only an engine run and print what the docs quote."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "docs" / "examples"
AT_REST = 1e-6
"""The settled rod's soft contact carries the closed form to its residual motion (measured 6.155000 N both)."""
TORQUE_SHARE = 1.0
"""[N] Read without the torque the force misses its share tau / l = 1.25 N; more than 1 N tells it from rounding."""


def test_mujoco_s_contact_force_needs_the_applied_forces():
    out = subprocess.run([sys.executable, str(EXAMPLES / "mujoco_contact_force_applied.py")], capture_output=True,
                         text=True, check=True, timeout=60).stdout
    lines = {line.split("=")[0].strip(): line.split("=")[1].split()[0] for line in out.splitlines() if "=" in line}
    closed = float(lines["closed form m g / 2 + tau / (l cos)"])
    simulated = float(lines["MuJoCo, qfrc_applied as simulated"])
    without = float(lines["MuJoCo, the same state, qfrc_applied 0"])
    assert abs(simulated - closed) < AT_REST * closed
    assert closed - without > TORQUE_SHARE
