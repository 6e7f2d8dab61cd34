"""Loads that change with time, applied at every stage of a MuJoCo step through its control callback.

MuJoCo reads ``qfrc_applied`` and ``xfrc_applied`` as inputs: set from Python before ``mj_step``, they are held over
the step, so RK4's four stages see the value at the step's start and a sinusoid then shows order 1. MuJoCo calls
its control callback (``mujoco.set_mjcb_control``) inside every ``mj_forward``, after positions and velocities and
before the accelerations: once per step for Euler and the implicit integrators, at each of RK4's four stages with
``d.time`` set to the stage's time t + c dt (``mj_RungeKutta``; measured in ``tests/references/mujoco``). The
callback writes the stage's loads into ``qfrc_applied`` there, so each stage sees its own.

The callback is process-global: :func:`stage_callback` installs it for one run and removes it after, whatever
happens; simparity steps one simulation at a time per process (each case in its worker, or in turn), so no other
model's step sees it. ``mujoco.rollout`` is not used with it (its threads would call back into Python).

Its cost, measured on forced-particle's body with RK4 at dt = 2.5 ms (2026-11-29, best of 5 runs of 800 steps): 46 us
a step with the callback against 17 us for the same ``mj_step`` loop with a constant applied force set once per
step, so about 7 us for each of RK4's four calls into Python (the load's evaluation and ``mj_applyFT``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager

import mujoco

StageCallback = Callable[[mujoco.MjModel, mujoco.MjData], None]

DETAIL = ("loads that change with time evaluated at every stage's d.time by MuJoCo's control callback "
          "(mjcb_control, installed for this run only), as seen from inside the step for a held load")
"""What the rows' detail says of the timed loads."""


class StepClock:
    """The time of the step being taken, kept by the adapter: MuJoCo's ``d.time`` is a running sum of dt, which drifts
    from k dt by ~1e-16 relative a step (5e-11 s after 40,000 steps, beyond a hold's tolerance of 1e-9 of a 10 ms
    period), so a stage's time is the step's own start k dt plus the offset ``d.time - mujoco_start`` MuJoCo gives
    the stage within the step (c dt, exact to rounding).

    Attributes
    ----------
    step_start : float
        k dt [s], the step's start as every engine counts it.
    mujoco_start : float
        ``d.time`` at the step's start.
    """

    def __init__(self) -> None:
        self.step_start = 0.0
        self.mujoco_start = 0.0

    def start(self, step: int, dt: float, mujoco_time: float) -> None:
        """The step ``step`` (from 0) of ``dt`` [s] begins; MuJoCo's clock reads ``mujoco_time``."""
        self.step_start, self.mujoco_start = step * dt, mujoco_time

    def stage_time(self, mujoco_time: float) -> float:
        """The time [s] of the stage MuJoCo evaluates at ``d.time`` = ``mujoco_time``."""
        return self.step_start + (mujoco_time - self.mujoco_start)


@contextmanager
def stage_callback(callback: StageCallback | None) -> Iterator[None]:
    """``callback`` installed as MuJoCo's control callback for the ``with`` block (nothing when None)."""
    if callback is None:
        yield
        return
    mujoco.set_mjcb_control(callback)
    try:
        yield
    finally:
        mujoco.set_mjcb_control(None)
