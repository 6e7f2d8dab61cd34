"""The dimensions of the results' unit strings, so a value can be carried between unit systems.

A metric's unit (``core.results``: the ``unit`` column) is written in SI symbols: ``m``, ``m/s``, ``rad/s``,
``s``, ``1`` (dimensionless, SI's way), and two mixed units whose rows hold entries of different dimensions
(``m/rad or 1``: a Jacobian's linear entries [m/rad] and angular ones [1]; ``rad or m``: joint values of
revolute and prismatic joints). :func:`unit_dimensions` reads such a string into its dimensions, each the
exponents (length, mass, time) of L^a M^b T^c; radians are dimensionless. A unit it does not know is a
:class:`~simparity.core.model.errors.UnitError`, never a silent factor of 1.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from simparity.core.model.errors import UnitError, one_line


@dataclass(frozen=True)
class Dimension:
    """L^length M^mass T^time: how a quantity scales when the units of length, mass and time change.

    Attributes
    ----------
    length, mass, time : int
        Exponents of the length, mass and time units.
    """

    length: int = 0
    mass: int = 0
    time: int = 0

    def __mul__(self, other: "Dimension") -> "Dimension":
        return Dimension(self.length + other.length, self.mass + other.mass, self.time + other.time)

    def __pow__(self, power: int) -> "Dimension":
        return Dimension(self.length * power, self.mass * power, self.time * power)

    def factor(self, length_scale: float, mass_scale: float, time_scale: float) -> float:
        """The number a value of this dimension is multiplied by when one unit of length becomes
        ``length_scale`` units (and likewise mass and time)."""
        return length_scale ** self.length * mass_scale ** self.mass * time_scale ** self.time


SYMBOLS = {
    "1": Dimension(),
    "rad": Dimension(),
    "m": Dimension(length=1),
    "kg": Dimension(mass=1),
    "s": Dimension(time=1),
    "N": Dimension(length=1, mass=1, time=-2),
    "J": Dimension(length=2, mass=1, time=-2),
}
"""The unit symbols a result's unit is written with, and their dimensions (radians are a ratio of lengths)."""

ALTERNATIVES = " or "
"""Separates the units of a mixed unit (``m/rad or 1``)."""

_FACTOR = re.compile(r"^(?P<symbol>[A-Za-z1]+)(?:\^(?P<power>-?\d+))?$")


def _product(text: str, unit: str) -> Dimension:
    """The dimension of a product of symbols (``kg m^2``, ``m``, ``1``)."""
    dimension = Dimension()
    factors = text.replace("*", " ").split()
    if not factors:
        raise UnitError(f"unit {one_line(unit)!r}: an empty factor (allowed: products of {', '.join(SYMBOLS)}, "
                        "at most one '/')")
    for factor in factors:
        match = _FACTOR.match(factor)
        if match is None or match["symbol"] not in SYMBOLS:
            raise UnitError(f"unit {one_line(unit)!r}: unknown symbol {one_line(factor)!r} (allowed: "
                            f"{', '.join(SYMBOLS)}, with an optional integer power ^n)")
        dimension = dimension * SYMBOLS[match["symbol"]] ** int(match["power"] or 1)
    return dimension


def unit_dimensions(unit: str) -> tuple[Dimension, ...]:
    """The dimension of each alternative of ``unit`` (one for a plain unit, two for ``m/rad or 1``).

    Raises
    ------
    UnitError
        For a unit written with a symbol not in :data:`SYMBOLS`, more than one ``/``, or nothing.
    """
    alternatives = []
    for part in str(unit).split(ALTERNATIVES):
        pieces = part.split("/")
        if len(pieces) > 2:
            raise UnitError(f"unit {one_line(unit)!r}: more than one '/' (allowed: numerator/denominator)")
        dimension = _product(pieces[0], unit)
        if len(pieces) == 2:
            dimension = dimension * _product(pieces[1], unit) ** -1
        alternatives.append(dimension)
    return tuple(alternatives)


def unit_factor(unit: str, length_scale: float, mass_scale: float, time_scale: float) -> float:
    """The number a value in ``unit`` is multiplied by under the given changes of units.

    Raises
    ------
    UnitError
        For an unknown unit, or a mixed unit whose alternatives scale differently (``m/rad or 1`` under a
        change of the length unit): its rows mix entries the change scales by different factors, and no one
        factor carries their maximum over.
    """
    factors = {dimension.factor(length_scale, mass_scale, time_scale) for dimension in unit_dimensions(unit)}
    if len(factors) > 1:
        raise UnitError(f"unit {one_line(unit)!r} mixes dimensions that this change of units scales differently "
                        f"(by {', '.join(f'{f:.6g}' for f in sorted(factors))}): a maximum over its entries has no "
                        "one factor")
    return factors.pop()
