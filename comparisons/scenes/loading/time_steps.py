"""The time steps of a scene stepped through time (``dt`` or ``rate_hz``): a ladder of whole numbers of steps."""

from __future__ import annotations

from simparity.comparisons.scenes.limits import allowed_at_most
from simparity.comparisons.scenes.loading.reader import TableReader

# duration / dt may differ from a whole number by this much (rounding of a decimal dt).
STEP_COUNT_RTOL = 1e-9


def time_step_ladder(sim: TableReader, duration: float, n_bodies: int) -> tuple[float, ...]:
    """The time steps [s]: each a whole number of steps of the duration, no two with the same
    number of steps, each within the step limit."""
    key = "dt" if sim.has("dt") else "rate_hz"
    values = sim.numbers(key)
    if len(values) > sim.limits.max_dts:
        raise sim.fail(key, f"{len(values)} time steps", allowed_at_most(sim.limits, "max_dts"))
    dts = values if key == "dt" else tuple(1.0 / h for h in values)
    counts: dict[int, int] = {}
    for i, dt in enumerate(dts):
        steps = duration / dt  # finite: both are inside their ranges
        if dt > duration or abs(steps - round(steps)) > STEP_COUNT_RTOL * steps:
            raise sim.fail(f"{key}[{i}]", f"duration {duration:g} s is not a whole number of steps of {dt:g} s",
                           "time steps that divide the duration")
        if round(steps) in counts:
            raise sim.fail(f"{key}[{i}]", f"{values[i]:.17g} gives the same {round(steps):,} steps as "
                           f"{key}[{counts[round(steps)]}]", "distinct time steps")
        counts[round(steps)] = i
        if steps * n_bodies > sim.limits.max_steps:
            raise sim.fail(f"{key}[{i}]", f"{steps:,.0f} steps x {n_bodies} bodies = {steps * n_bodies:,.0f} body-steps "
                           f"at {dt:g} s", allowed_at_most(sim.limits, "max_steps", "per time step"))
    return dts
