"""Loads that change with time in a scene file: a time function table (``function = "smooth"`` or ``"held"``) and a
body's ``[[body.load]]`` (docs/scenes.md, "Forces that change with time").

A smooth function::

    function = "smooth"
    polynomial = [[0.0, 0.0, 1.0], [0.0, 0.0, 0.5]]     # c_0 + c_1 t + ..., one row of components per power of t
    [[...sinusoid]]
    amplitude = [2.0, 0.0, 0.0]                         # A sin(2 pi f t + phi)
    frequency_hz = 1.5
    phase_rad = 0.0

A zero-order hold::

    function = "held"
    period = 0.05                                       # the control period [s]
    phase = 0.0                                         # the first sample instant [s], 0 <= phase < period
    samples = [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]       # held from phase + k period to the next instant
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.scenes.loading.reader import SAMPLES_WHY, TableReader
from simparity.core.model.errors import echo
from simparity.core.model.ranges import RANGES
from simparity.core.model.scenes.time_functions import (
    FUNCTIONS,
    HELD,
    LOAD_FRAMES,
    WORLD,
    HeldFunction,
    Sinusoid,
    SmoothFunction,
    TimedLoad,
    TimeFunction,
)

SMOOTH_KEYS = ("polynomial", "sinusoid")
HELD_KEYS = ("period", "phase", "samples")
FUNCTION_KEYS = ("function",) + SMOOTH_KEYS + HELD_KEYS
SINUSOID_KEYS = ("amplitude", "frequency_hz", "phase_rad")
LOAD_KEYS = ("frame", "point_body", "force", "torque")
MAX_POLYNOMIAL_TERMS = 16
"""Powers of t a polynomial may have (t^0 to t^15): beyond, t^k over a scene's duration overflows or cancels, and no
load is written so."""


def _row(r: TableReader, key: str, value, powers: np.ndarray) -> np.ndarray:
    """``value``, a list of len(powers) numbers, component i scaled by length_scale ** powers[i], each in range."""
    if value is None:
        raise r.fail(key, "missing required key", f"a list of {len(powers)} numbers")
    if not isinstance(value, list) or len(value) != len(powers):
        got = f"{len(value):,} values" if isinstance(value, list) else echo(value)
        raise r.fail(key, f"expected a list of {len(powers)} numbers, got {got}", f"a list of {len(powers)} numbers")
    return np.array([r.in_range(f"{key}[{j}]", r.checked(f"{key}[{j}]", v) * r.scale ** p)
                     for j, (v, p) in enumerate(zip(value, powers))])


def _rows(r: TableReader, key: str, powers: np.ndarray, limit: int, why: str) -> np.ndarray:
    """A non-empty list of at most ``limit`` rows, each as :func:`_row`."""
    value = r.table.get(key)
    if not isinstance(value, list) or not value:
        raise r.fail(key, f"expected a non-empty list of rows, got {echo(value)}",
                     f"a list of rows of {len(powers)} numbers each")
    if len(value) > limit:
        raise r.fail(key, f"{len(value):,} rows", f"at most {limit:,}{why}")
    return np.array([_row(r, f"{key}[{i}]", row, powers) for i, row in enumerate(value)])


def _refuse_other_keys(r: TableReader, kind: str, others: tuple[str, ...], own: tuple[str, ...]) -> None:
    for key in others:
        if r.has(key):
            raise r.fail(key, f"is not a key of a {kind} function", f"{', '.join(own)} with function = {kind!r}")


def read_time_function(r: TableReader, powers: np.ndarray) -> TimeFunction:
    """The time function of table ``r``, len(powers) components, component i in kg m^powers[i] s^-2 (a force: 1, a
    torque: 2), scaled by the file's length unit."""
    kind = r.string("function", choices=FUNCTIONS)
    if kind == HELD:
        _refuse_other_keys(r, HELD, SMOOTH_KEYS, HELD_KEYS)
        period = r.number("period", positive=True)
        phase = r.number("phase", 0.0)
        if not 0 <= phase < period:
            raise r.fail("phase", f"{phase:g} s is not within the first control period",
                         f"a first sample instant in [0, {period:g}) s")
        samples = _rows(r, "samples", powers, r.limits.max_samples, SAMPLES_WHY)
        return HeldFunction(samples, period, phase)
    _refuse_other_keys(r, kind, HELD_KEYS, SMOOTH_KEYS)
    if not r.has("polynomial") and not r.has("sinusoid"):
        raise r.fail("function", "a smooth function with neither a polynomial nor a sinusoid",
                     "polynomial = [[...]] (a row per power of t), [[sinusoid]] entries, or both")
    polynomial = (_rows(r, "polynomial", powers, MAX_POLYNOMIAL_TERMS, " (powers t^0 to t^15)") if r.has("polynomial")
                  else np.zeros((0, len(powers))))
    sinusoids = []
    if r.has("sinusoid"):
        for s in r.array_of_tables("sinusoid", SINUSOID_KEYS, "max_samples"):
            amplitude = _row(s, "amplitude", s.table.get("amplitude"), powers)
            frequency = s.number("frequency_hz")
            if frequency < 0:
                raise s.fail("frequency_hz", f"{frequency:g} is negative", "a frequency >= 0 Hz")
            sinusoids.append(Sinusoid(amplitude, frequency, s.number("phase_rad", 0.0)))
    return SmoothFunction(polynomial, tuple(sinusoids))


def within_range_over(r: TableReader, key: str, function: TimeFunction, duration: float) -> TimeFunction:
    """``function`` if its largest magnitude over the run (:meth:`SmoothFunction.largest_magnitude`) stays within the
    range of a load's values: a polynomial of coefficients each in range can still reach 1e42 N at t = 100 s, which no
    engine steps (the tight solve never finishes)."""
    allowed = RANGES["amplitude"]
    bound = function.largest_magnitude(duration)
    if not (np.isfinite(bound) and bound <= allowed.high):
        raise r.fail(key, f"reaches {bound:.3g} over the run's {duration:g} s (sum |c_k| T^k + sum |A|)",
                     f"a load that stays within {allowed.text()} over the whole run")
    return function


def read_loads(r: TableReader, index: int, duration: float) -> list[TimedLoad]:
    """The ``[[body.load]]`` entries of body ``index``'s table ``r`` (none without the key), each within range over a
    run of ``duration`` [s]."""
    if not r.has("load"):
        return []
    loads = []
    for entry in r.array_of_tables("load", LOAD_KEYS, "max_bodies"):
        frame = entry.string("frame", WORLD, choices=LOAD_FRAMES)
        functions = {}
        for key, power in (("force", 1), ("torque", 2)):
            table = entry.optional_subtable(key, FUNCTION_KEYS)
            if table is not None:
                functions[key] = within_range_over(entry, key, read_time_function(table, np.full(3, power)),
                                                   duration)
        if not functions:
            raise entry.fail("force", "a load with neither a force nor a torque",
                             f"[{entry.path}.force], [{entry.path}.torque] or both, each a time function")
        loads.append(TimedLoad(index, frame, entry.vector("point_body", 3, [0.0] * 3, length=1), **functions))
    return loads
