"""Loads that change with time: :class:`SmoothFunction` (a polynomial in t plus sinusoids), :class:`HeldFunction`
(values sampled at a control period and held between samples, a zero-order hold) and :class:`TimedLoad` (a body's
force at a point and torque, each such a function, in world or body axes).

These are data only. Core evaluates them in :mod:`core.dynamics.time_loads`; every reference evaluates them with its
own code from these fields (:mod:`references.common.time_loads`).

A hold's sample instants are t_k = phase + k period, k = 0 .. m - 1; its value is 0 before t_0, ``samples[k]`` on
[t_k, t_k+1) and the last sample from t_m-1 on. Seen from inside a step [t, t + dt] an integrator evaluates it at a
stage's time s = t + c dt: the value at s itself for s = t (the step's start), the value just before s for s > t
(so a stage at the step's end, c = 1, sees the value the step began in, and a step whose ends are sample instants
sees one constant value: no order is lost). A step with an instant strictly inside (a *straddle*) sees the jump
between two of its stages: every scheme is then first order over that step, and so over the run.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simparity.core.model.arrays import readonly
from simparity.core.model.errors import SceneError

SMOOTH, HELD = "smooth", "held"
FUNCTIONS = (SMOOTH, HELD)
"""The kinds of time function a scene file's ``function`` key names."""

WORLD, BODY = "world", "body"
LOAD_FRAMES = (WORLD, BODY)
"""The axes a :class:`TimedLoad`'s force and torque are given in: the world's, or the body's (turning with it)."""


def _finite(values, shape: tuple[int, ...], what: str) -> np.ndarray:
    array = np.asarray(values, dtype=float)
    if array.shape != shape and not (len(shape) == 2 and shape[0] == -1 and array.ndim == 2
                                     and array.shape[1] == shape[1]):
        raise SceneError("<code>", what, f"shape {array.shape}", f"shape {shape} (-1: any count)")
    if not np.all(np.isfinite(array)):
        raise SceneError("<code>", what, "a value is not finite (NaN or infinite)", "finite numbers")
    return readonly(array)


@dataclass(frozen=True)
class Sinusoid:
    """One term A sin(2 pi f t + phi) of a :class:`SmoothFunction`.

    Attributes
    ----------
    amplitude : (d,) ndarray
        A, in the unit of the function's values.
    frequency_hz : float
        f [Hz], >= 0.
    phase_rad : float
        phi [rad].
    """

    amplitude: np.ndarray
    frequency_hz: float
    phase_rad: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "amplitude", _finite(self.amplitude, np.shape(self.amplitude), "sinusoid.amplitude"))
        if not (np.isfinite(self.frequency_hz) and self.frequency_hz >= 0):
            raise SceneError("<code>", "sinusoid.frequency_hz", f"{self.frequency_hz!r}", "a finite frequency >= 0 Hz")
        if not np.isfinite(self.phase_rad):
            raise SceneError("<code>", "sinusoid.phase_rad", f"{self.phase_rad!r}", "a finite phase [rad]")


@dataclass(frozen=True)
class SmoothFunction:
    """f(t) = sum_k c_k t^k + sum_s A_s sin(2 pi f_s t + phi_s), a (d,) vector at each time t [s].

    Attributes
    ----------
    polynomial : (K, d) ndarray
        c_k, the coefficient of t^k in row k (K = 0: no polynomial), in the values' unit per s^k.
    sinusoids : tuple of Sinusoid
        Each with a (d,) amplitude.
    """

    polynomial: np.ndarray
    sinusoids: tuple[Sinusoid, ...] = ()
    kind: str = field(default=SMOOTH, init=False)

    def __post_init__(self) -> None:
        polynomial = np.asarray(self.polynomial, dtype=float)
        if polynomial.ndim != 2:
            raise SceneError("<code>", "polynomial", f"shape {polynomial.shape}", "(terms, components)")
        object.__setattr__(self, "polynomial", _finite(polynomial, (-1, polynomial.shape[1]), "polynomial"))
        object.__setattr__(self, "sinusoids", tuple(self.sinusoids))
        if any(s.amplitude.shape != (self.size,) for s in self.sinusoids):
            raise SceneError("<code>", "sinusoid.amplitude", "amplitudes of another size than the polynomial's rows",
                             f"{self.size} components each")

    @property
    def size(self) -> int:
        """d, the components of each value."""
        return self.polynomial.shape[1]

    def largest_magnitude(self, duration: float) -> float:
        """An upper bound of |f(t)| over [0, ``duration``] [s]: sum_k |c_k| T^k + sum_s |A_s|."""
        powers = float(duration) ** np.arange(len(self.polynomial))
        with np.errstate(over="ignore", invalid="ignore"):
            bound = float(np.linalg.norm(self.polynomial, axis=1) @ powers) if len(self.polynomial) else 0.0
        return bound + sum(float(np.linalg.norm(s.amplitude)) for s in self.sinusoids)


@dataclass(frozen=True)
class HeldFunction:
    """A zero-order hold: ``samples[k]`` from t_k = phase + k period to t_k+1, 0 before t_0 (module docstring).

    Attributes
    ----------
    samples : (m, d) ndarray
        The sampled values, in their unit.
    period_s : float
        The control period [s], > 0.
    phase_s : float
        The first sample instant t_0 [s], 0 <= phase < period.
    """

    samples: np.ndarray
    period_s: float
    phase_s: float = 0.0
    kind: str = field(default=HELD, init=False)

    def __post_init__(self) -> None:
        samples = np.asarray(self.samples, dtype=float)
        if samples.ndim != 2 or len(samples) == 0:
            raise SceneError("<code>", "samples", f"shape {samples.shape}", "one or more samples of d components")
        object.__setattr__(self, "samples", _finite(samples, samples.shape, "samples"))
        if not (np.isfinite(self.period_s) and self.period_s > 0):
            raise SceneError("<code>", "period", f"{self.period_s!r}", "a finite control period > 0 s")
        if not (np.isfinite(self.phase_s) and 0 <= self.phase_s < self.period_s):
            raise SceneError("<code>", "phase", f"{self.phase_s!r}", f"a first sample instant in [0, {self.period_s:g}) s")

    @property
    def size(self) -> int:
        """d, the components of each value."""
        return self.samples.shape[1]

    def largest_magnitude(self, duration: float) -> float:
        """|f(t)| at most over any run: the largest sample's norm."""
        return float(np.max(np.linalg.norm(self.samples, axis=1)))

    def instants(self) -> np.ndarray:
        """(m,) the sample instants t_k [s], where the held value may jump."""
        return self.phase_s + self.period_s * np.arange(len(self.samples))


TimeFunction = SmoothFunction | HeldFunction


@dataclass(frozen=True)
class TimedLoad:
    """A force at a point fixed in a body and a torque, each a function of time (either may be absent).

    Attributes
    ----------
    body : int
        Index of the body in the scene.
    frame : str
        ``"world"`` or ``"body"`` (:data:`LOAD_FRAMES`): the axes both functions' values are in; body axes turn with
        the body (R f is the world force).
    point_body : (3,) ndarray
        Where the force acts, from the COM in body axes [m]; its torque about the COM is (R point) x F_world.
    force : TimeFunction or None
        [N], 3 components.
    torque : TimeFunction or None
        [N m] about the COM, 3 components.
    """

    body: int
    frame: str
    point_body: np.ndarray
    force: TimeFunction | None = None
    torque: TimeFunction | None = None

    def __post_init__(self) -> None:
        if self.frame not in LOAD_FRAMES:
            raise SceneError("<code>", "load.frame", f"{self.frame!r}", " or ".join(LOAD_FRAMES))
        object.__setattr__(self, "point_body", _finite(self.point_body, (3,), "load.point_body"))
        if self.force is None and self.torque is None:
            raise SceneError("<code>", "load", "neither a force nor a torque", "a force, a torque or both")
        for name in ("force", "torque"):
            function = getattr(self, name)
            if function is not None and function.size != 3:
                raise SceneError("<code>", f"load.{name}", f"{function.size} components", "3 (x, y, z)")

    def functions(self) -> tuple[TimeFunction, ...]:
        """The load's time functions (force first)."""
        return tuple(f for f in (self.force, self.torque) if f is not None)
