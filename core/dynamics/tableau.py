"""Butcher tableaux of the explicit Runge-Kutta schemes, one per scheme, serving free bodies and chains.

An explicit s-stage scheme for dy/dt = f(t, y) is the data (a, b, c) (scipy's ``scipy/integrate/_ivp/rk.py`` holds
the same as ``A``, ``B``, ``C``):

    k_i = f(t + c_i dt, y + dt sum_{j<i} a_ij k_j),   y' = y + dt sum_i b_i k_i,

with ``a`` strictly lower triangular and c_i = sum_j a_ij. :class:`Tableau` carries them with the scheme's
order of global accuracy; a scheme's stage count (evaluations of f per step) is ``len(b)``. The steppers of
:mod:`core.dynamics.integrators`, :mod:`core.dynamics.quaternion_integrators` and
:mod:`core.articulated.stepping` read every coefficient from here; each keeps the floating-point order of its
sums (documented where it sums), so a tableau's weights b are also given over a common denominator
(:attr:`Tableau.weight_numerators`, :attr:`Tableau.weight_denominator`) for the stepping that sums
dt / 6 (k1 + 2 k2 + 2 k3 + k4).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from math import lcm

MAX_WEIGHT_DENOMINATOR = 1000
"""Largest denominator looked for when the weights b are written as fractions (RK4's is 6)."""


@dataclass(frozen=True)
class Tableau:
    """An explicit Runge-Kutta scheme's Butcher tableau and its order.

    Attributes
    ----------
    a : tuple of s tuples of s floats
        The stage coefficients a_ij, strictly lower triangular (a_ij = 0 for j >= i).
    b : tuple of s floats
        The weights of the stages in the step.
    c : tuple of s floats
        The stages' times as fractions of dt, c_i = sum_j a_ij.
    order : int
        The order of global accuracy the scheme claims (every order condition up to it holds).
    """

    a: tuple[tuple[float, ...], ...]
    b: tuple[float, ...]
    c: tuple[float, ...]
    order: int

    def __post_init__(self) -> None:
        s = len(self.b)
        if len(self.c) != s or len(self.a) != s or any(len(row) != s for row in self.a):
            raise ValueError(f"a tableau of {s} stages needs a ({s} x {s}) and c ({s})")
        if any(self.a[i][j] for i in range(s) for j in range(i, s)):
            raise ValueError("an explicit tableau's a is strictly lower triangular")

    @property
    def stages(self) -> int:
        """Evaluations of the right-hand side per step."""
        return len(self.b)

    @cached_property  # read at every step of a stepper that sums over it: computed once per tableau
    def weight_denominator(self) -> float:
        """The least common denominator of the weights b (6.0 for RK4, 1.0 for midpoint)."""
        return float(lcm(*(_fraction(w).denominator for w in self.b)))

    @cached_property
    def weight_numerators(self) -> tuple[float, ...]:
        """The weights b times :attr:`weight_denominator` (1, 2, 2, 1 for RK4)."""
        denominator = lcm(*(_fraction(w).denominator for w in self.b))
        return tuple(float(_fraction(w) * denominator) for w in self.b)


def _fraction(weight: float) -> Fraction:
    return Fraction(weight).limit_denominator(MAX_WEIGHT_DENOMINATOR)


EXPLICIT_EULER = Tableau(a=((0.0,),), b=(1.0,), c=(0.0,), order=1)
AVERAGE_VELOCITY = Tableau(a=((0.0, 0.0), (1.0, 0.0)), b=(0.5, 0.5), c=(0.0, 1.0), order=2)
"""Heun's method (the trapezoid): the lecture's average of the beginning and ending velocities."""
MIDPOINT = Tableau(a=((0.0, 0.0), (0.5, 0.0)), b=(0.0, 1.0), c=(0.0, 0.5), order=2)
RK4 = Tableau(a=((0.0, 0.0, 0.0, 0.0), (0.5, 0.0, 0.0, 0.0), (0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0)),
              b=(1 / 6, 1 / 3, 1 / 3, 1 / 6), c=(0.0, 0.5, 0.5, 1.0), order=4)
"""The classical Runge-Kutta method."""

TABLEAUX: dict[str, Tableau] = {
    "explicit_euler": EXPLICIT_EULER,
    "average_velocity": AVERAGE_VELOCITY,
    "midpoint": MIDPOINT,
    "rk4": RK4,
}
"""The explicit Runge-Kutta schemes by name (the names of :data:`core.dynamics.integrators.SCHEMES`)."""
