"""Mass properties: total mass, centre of mass and inertia tensors.

The lecture's "Center of Mass", "Inertia Tensor" and "Inertia Tensor of a Rotated
Object". Every function takes arrays with any number of leading batch axes (``...``),
works in float64 and SI units (kg, m, kg m^2).

Sign convention: the lecture's slide writes the products of inertia as
``I_xy = sum m x y`` without a minus sign. This module uses the physical tensor,
``I = sum m (|r|^2 E - r r^T)``, whose off-diagonal entries are ``-sum m x y``; that is
the tensor for which ``L = I omega`` and the one MuJoCo, PyBullet, Pinocchio and URDF
``<inertia ixy=...>`` use.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.errors import SceneError
from simparity.core.model.ranges import INERTIA_RTOL, RANGES

_SOURCE = "<scene>"


def _positive(value: np.ndarray, key: str) -> np.ndarray:
    value = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(value)) or np.any(value <= 0):
        raise SceneError(_SOURCE, key, f"must be finite and > 0, got {value.tolist()}", "> 0")
    return value


def mass_and_center_of_mass(masses: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Total mass M = sum m_i and centre of mass x = sum m_i q_i / M.

    Parameters
    ----------
    masses : (..., N) array_like
        Point masses [kg], each >= 0, with a positive sum.
    points : (..., N, 3) array_like
        Their positions [m].

    Returns
    -------
    mass : (...) ndarray
        [kg].
    com : (..., 3) ndarray
        [m], in the frame of ``points``.

    Raises
    ------
    SceneError
        If a mass is negative or not finite, or a total mass is not positive.
    """
    masses = np.asarray(masses, dtype=float)
    points = np.asarray(points, dtype=float)
    if not np.all(np.isfinite(masses)) or np.any(masses < 0):
        raise SceneError(_SOURCE, "masses", "point masses must be finite and >= 0", ">= 0 kg")
    mass = masses.sum(axis=-1)
    if np.any(mass <= 0):
        raise SceneError(_SOURCE, "masses", "total mass must be > 0", "at least one mass > 0")
    com = np.einsum("...n,...ni->...i", masses, points) / mass[..., None]
    return mass, com


def inertia_from_point_masses(masses: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Inertia tensor of point masses about their centre of mass, in the frame of ``points``.

    ``I = sum m_i (|r_i|^2 E - r_i r_i^T)``, ``r_i = q_i - com``: the diagonal is the
    lecture's ``I_xx = sum m (y^2 + z^2)`` etc.; the off-diagonal entries are the physical
    ``-sum m x y`` (the slide omits the minus sign; see the module docstring).

    Parameters
    ----------
    masses : (..., N) array_like
        [kg], as for :func:`mass_and_center_of_mass`.
    points : (..., N, 3) array_like
        [m].

    Returns
    -------
    (..., 3, 3) ndarray
        [kg m^2].
    """
    points = np.asarray(points, dtype=float)
    masses = np.asarray(masses, dtype=float)
    _, com = mass_and_center_of_mass(masses, points)
    r = points - com[..., None, :]
    r2 = np.einsum("...ni,...ni,...n->...", r, r, masses)
    return r2[..., None, None] * np.eye(3) - np.einsum("...n,...ni,...nj->...ij", masses, r, r)


def _diagonal(moments: np.ndarray) -> np.ndarray:
    """(..., 3) principal moments -> (..., 3, 3) diagonal tensors."""
    return moments[..., :, None] * np.eye(3)


def inertia_solid_sphere(mass: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Uniform solid sphere about its centre: 2/5 m r^2 E.

    Parameters
    ----------
    mass : (...) array_like
        [kg], > 0.
    radius : (...) array_like
        [m], > 0.

    Returns
    -------
    (..., 3, 3) ndarray
        [kg m^2].
    """
    moment = 0.4 * _positive(mass, "mass") * _positive(radius, "radius") ** 2
    return _diagonal(np.stack([moment] * 3, axis=-1))


def inertia_solid_box(mass: np.ndarray, size_xyz: np.ndarray) -> np.ndarray:
    """Uniform solid box about its centre, edges along the body axes.

    ``I_xx = m (b^2 + c^2) / 12`` etc. for full edge lengths ``(a, b, c)``.

    Parameters
    ----------
    mass : (...) array_like
        [kg], > 0.
    size_xyz : (..., 3) array_like
        Full edge lengths along x, y, z [m], > 0.

    Returns
    -------
    (..., 3, 3) ndarray
        [kg m^2].
    """
    mass = _positive(mass, "mass")
    sq = _positive(size_xyz, "size_xyz") ** 2
    moments = np.stack([sq[..., 1] + sq[..., 2], sq[..., 0] + sq[..., 2], sq[..., 0] + sq[..., 1]], axis=-1)
    return _diagonal(mass[..., None] / 12.0 * moments)


def inertia_solid_cylinder(mass: np.ndarray, radius: np.ndarray, length: np.ndarray) -> np.ndarray:
    """Uniform solid cylinder about its centre, axis along body z.

    ``I_xx = I_yy = m (3 r^2 + l^2) / 12``, ``I_zz = m r^2 / 2``.

    Parameters
    ----------
    mass : (...) array_like
        [kg], > 0.
    radius : (...) array_like
        [m], > 0.
    length : (...) array_like
        Full length along z [m], > 0.

    Returns
    -------
    (..., 3, 3) ndarray
        [kg m^2].
    """
    mass = _positive(mass, "mass")
    r2 = _positive(radius, "radius") ** 2
    l2 = _positive(length, "length") ** 2
    transverse = mass * (3 * r2 + l2) / 12.0
    return _diagonal(np.stack(np.broadcast_arrays(transverse, transverse, mass * r2 / 2.0), axis=-1))


def inertia_world(rotation_world: np.ndarray, inertia_body: np.ndarray) -> np.ndarray:
    """Inertia tensor of a rotated body in world axes, I = R I_body R^T.

    Parameters
    ----------
    rotation_world : (..., 3, 3) array_like
        Body-to-world rotation.
    inertia_body : (..., 3, 3) array_like
        [kg m^2] in body axes.

    Returns
    -------
    (..., 3, 3) ndarray
        [kg m^2] in world axes.
    """
    r = np.asarray(rotation_world, dtype=float)
    return r @ np.asarray(inertia_body, dtype=float) @ np.swapaxes(r, -1, -2)


def inertia_problem(inertia: np.ndarray, rtol: float = INERTIA_RTOL) -> str | None:
    """What is physically wrong with an inertia tensor, or None if nothing is.

    Safe for any finite entries (1e308, denormals): the checks run on the tensor divided by its
    largest entry, so nothing overflows to NaN and passes. Checks, in order: shape (3, 3) and
    finite entries; symmetry (``|I - I^T|`` at most
    ``rtol`` times the largest principal moment); positive definiteness (every principal
    moment > 0, no tolerance: a singular tensor cannot be inverted); the triangle
    inequality of the principal moments ``a + b >= c`` (up to ``rtol * c``), which every
    real mass distribution satisfies.

    Parameters
    ----------
    inertia : (3, 3) array_like
        [kg m^2].
    rtol : float
        Relative tolerance of the symmetry and triangle checks.

    Returns
    -------
    str or None
        A short sentence naming the problem, with the offending values.
    """
    inertia = np.asarray(inertia, dtype=float)
    if inertia.shape != (3, 3):
        return f"inertia has shape {inertia.shape}, expected (3, 3)"
    if not np.all(np.isfinite(inertia)):
        return "inertia has non-finite entries"
    # Work on I / max|I_ij|: entries of 1e308 or 1e-320 neither overflow nor lose their digits,
    # and the eigenvalues of a tensor of order one always converge.
    scale = float(np.max(np.abs(inertia)))
    if scale == 0.0:
        return "inertia is zero, not positive definite"
    unit = inertia / scale
    try:
        moments = np.linalg.eigvalsh(0.5 * (unit + unit.T))
    except np.linalg.LinAlgError as err:
        return f"inertia has no principal moments ({err})"
    asymmetry = np.max(np.abs(unit - unit.T))
    if asymmetry > rtol * np.max(np.abs(moments)):
        return f"inertia is not symmetric: max |I - I^T| = {_scaled(asymmetry, scale):.3g} kg m^2"
    if moments[0] <= 0:
        return f"inertia is not positive definite: eigenvalues {_fmt(moments, scale)} kg m^2"
    if moments[0] + moments[1] < moments[2] * (1 - rtol):
        a, b, c = (_scaled(m, scale) for m in moments)
        return (
            f"inertia violates the triangle inequality: principal moments {_fmt(moments, scale)} kg m^2 "
            f"have {a:.6g} + {b:.6g} < {c:.6g}"
        )
    return None


def _scaled(value: float, scale: float) -> float:
    """``value * scale`` for a message (inf rather than a warning where it overflows)."""
    with np.errstate(over="ignore"):
        return float(np.float64(value) * scale)


def _fmt(values: np.ndarray, scale: float = 1.0) -> str:
    return "(" + ", ".join(f"{_scaled(v, scale):.6g}" for v in values) + ")"


ROUNDING_ULPS = 64
"""Floating-point residue a link's inertia tensor may carry, in units of eps times the link's inertia scale about
its frame origin (c + m |d|^2: its largest centroidal moment plus the parallel-axis term). Exporters compute the
centroidal tensor by taking m (|d|^2 E - d d^T) off an inertia about the link origin, which leaves residues of a
few eps m |d|^2 whatever the tensor's own size: iCub's head (m = 1.34 kg, |d| = 0.11 m) is written as ixz =
2.4e-35 kg m^2 and nothing else, principal moments (-2.4e-35, 0, 2.4e-35), 1e-33 of its scale. 64 eps = 1.4e-14
of the scale covers a chain of such operations and is far below any physical violation (the smallest in the
installed robot files, pybullet_data's TwoJointRobot link_1, breaks a + b >= c by 0.8 % of c)."""

MOMENT_FLOOR = RANGES["inertia_moment"].low  # [kg m^2]
"""The smallest moment of inertia that is physical (1e-15 kg m^2, a microgram bead of 1 mm: the low end of
:data:`core.model.ranges.RANGES`' ``inertia_moment``): the floating-point scale of :func:`link_tensor_problem` never falls
below it, so a point mass at its link's origin written with a residue of 1e-35 is judged as the point mass it is."""


LINK_TENSOR_RULE = (f"a symmetric tensor with non-zero entries of at least {MOMENT_FLOOR:g} kg m^2 (smaller only as "
                    "rounding) and principal moments a <= b <= c with a + b >= c (a point mass or a thin rod is one)")
"""What :func:`link_tensor_problem` allows, for the allowed part of a refusal."""


def link_tensor_problem(inertia: np.ndarray, mass: float = 0.0, com_xyz: np.ndarray | None = None) -> str:
    """Why an inertia tensor is not a link's ("" if it is): it must be symmetric, each non-zero entry at least
    :data:`MOMENT_FLOOR` (the smallest physical moment), and its principal moments a <= b <= c must satisfy a + b >= c
    (every mass distribution does; it implies a >= 0). Unlike a free body's (:func:`inertia_problem`), a zero or
    singular tensor (a point mass, a thin rod) is a link's: its joint carries it.

    An asymmetry, a smaller entry or a violation is rounding, not physics, when it is within either of two
    tolerances: the written decimals' (:data:`INERTIA_RTOL` of c) or floating point's (:data:`ROUNDING_ULPS` eps of
    the link's inertia scale about its frame origin, c + ``mass`` |``com_xyz``|^2, at least :data:`MOMENT_FLOOR`):
    exporters write residues like iCub head's 2.4e-35 kg m^2.

    Parameters
    ----------
    inertia : (3, 3) ndarray
        About the centre of mass [kg m^2], finite entries of magnitude at most 1e12.
    mass : float
        [kg], >= 0.
    com_xyz : (3,) ndarray, optional
        The centre of mass in the link frame [m]; None: at its origin.

    Returns
    -------
    str
        "" or one sentence with the principal moments.
    """
    largest = float(np.max(np.abs(inertia)))
    if largest == 0.0:
        return ""
    unit = inertia / largest  # of order one: no lost digits, no overflow
    a, b, c = np.linalg.eigvalsh(0.5 * (unit + unit.T)) * largest
    offset = 0.0 if com_xyz is None else float(np.dot(com_xyz, com_xyz))
    scale = max(abs(c) + mass * offset, MOMENT_FLOOR)
    rounding = max(INERTIA_RTOL * abs(c), ROUNDING_ULPS * np.finfo(float).eps * scale)
    asymmetry = float(np.max(np.abs(unit - unit.T))) * largest
    if asymmetry > rounding:
        return f"not symmetric: max |I - I^T| = {asymmetry:.3g} kg m^2, more than rounding ({rounding:.3g})"
    magnitudes = np.abs(inertia)
    tiny = magnitudes[(magnitudes > 0) & (magnitudes < MOMENT_FLOOR)]
    if tiny.size and tiny.max() > rounding:
        return (f"an entry of {tiny.max():.3g} kg m^2 is below the smallest physical moment ({MOMENT_FLOOR:g}) "
                f"and more than rounding ({rounding:.3g})")
    if a + b >= c - rounding:
        return ""
    moments = ", ".join(f"{m:.6g}" for m in (a, b, c))
    if a < -rounding:
        return f"not positive semidefinite: principal moments ({moments}) kg m^2"
    return f"violates the triangle inequality: principal moments ({moments}) kg m^2 have a + b < c"
