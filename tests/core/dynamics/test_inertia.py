"""Mass properties (core.dynamics.inertia) against hand-checkable cases, Pinocchio and MuJoCo."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from simparity.core.model.errors import SceneError
from simparity.core.dynamics.inertia import (
    inertia_from_point_masses,
    inertia_problem,
    inertia_solid_box,
    inertia_solid_cylinder,
    inertia_solid_sphere,
    inertia_world,
    mass_and_center_of_mass,
)
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix
from simparity.references.common.conventions import fmt

# Sums of a few dozen float64 products of O(1) numbers: rounding is ~1e-15 relative to
# the largest entry; 1e-13 leaves margin without hiding any modelling difference.
ROUNDING_RTOL = 1e-13

# MuJoCo stores principal moments and a principal-axes quaternion from its own 3x3
# eigensolver; measured agreement is ~1e-15 relative, 1e-12 leaves margin for other seeds.
MUJOCO_RTOL = 1e-12

# Radius [m] of the sphere geom standing in for each point mass. MuJoCo rejects spheres
# below ~1e-5 m (their volume falls under mjMINVAL); each contributes its own 2/5 m r^2
# (~4e-9 kg m^2 per kg here), far above MUJOCO_RTOL, so the tests add it explicitly.
MUJOCO_SPHERE_RADIUS = 1e-4


def _random_cloud(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n random masses [kg] at anisotropic random points [m] away from the origin."""
    masses = rng.uniform(0.1, 2.0, n)
    points = rng.normal(size=(n, 3)) * rng.uniform(0.1, 1.0, 3) + rng.normal(size=3)
    return masses, points


def _random_rotations(rng: np.random.Generator, batch: int) -> np.ndarray:
    return quat_wxyz_to_matrix(quat_wxyz_normalize(rng.normal(size=(batch, 4))))


def test_two_masses_give_reduced_mass_moment():
    """Two masses d apart on x: COM by the lever rule, I_yy = I_zz = m1 m2 / (m1 + m2) d^2, I_xx = 0."""
    m1, m2, x1, x2 = 2.0, 3.0, -1.0, 4.0
    mass, com = mass_and_center_of_mass([m1, m2], [[x1, 0, 0], [x2, 0, 0]])
    inertia = inertia_from_point_masses([m1, m2], [[x1, 0, 0], [x2, 0, 0]])
    moment = m1 * m2 / (m1 + m2) * (x2 - x1) ** 2
    assert mass == pytest.approx(5.0, rel=ROUNDING_RTOL)
    np.testing.assert_allclose(com, [(m1 * x1 + m2 * x2) / 5.0, 0, 0], rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(inertia, np.diag([0.0, moment, moment]), atol=ROUNDING_RTOL * moment)


def test_products_of_inertia_are_negative_sums():
    """Masses at (a, a, 0) and (-a, -a, 0): I_xy = -2 m a^2 (physical sign), I_zz = 4 m a^2."""
    m, a = 1.5, 0.3
    inertia = inertia_from_point_masses([m, m], [[a, a, 0.0], [-a, -a, 0.0]])
    k = m * a * a
    expected = np.array([[2 * k, -2 * k, 0.0], [-2 * k, 2 * k, 0.0], [0.0, 0.0, 4 * k]])
    np.testing.assert_allclose(inertia, expected, atol=ROUNDING_RTOL * k)


def test_grid_of_cell_centres_matches_box_with_shrunk_edges():
    """n^3 equal masses at a box's cell centres: the box formula with each edge^2 times (1 - 1/n^2)."""
    n, mass, size = 5, 7.0, np.array([0.1, 0.4, 0.9])
    axes = [((np.arange(n) + 0.5) / n - 0.5) * s for s in size]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3) + [1.0, -2.0, 3.0]
    grid = inertia_from_point_masses(np.full(n**3, mass / n**3), points)
    expected = inertia_solid_box(mass, size * np.sqrt(1 - 1 / n**2))
    np.testing.assert_allclose(grid, expected, atol=ROUNDING_RTOL * np.abs(expected).max())


def test_parallel_axis_theorem_for_a_union_of_clouds():
    """I of two clouds together = sum of each cloud's I_com + M_k (|d_k|^2 E - d_k d_k^T)."""
    rng = np.random.default_rng(1)
    (ma, pa), (mb, pb) = _random_cloud(rng, 6), _random_cloud(rng, 9)
    whole = inertia_from_point_masses(np.concatenate([ma, mb]), np.concatenate([pa, pb]))
    _, com = mass_and_center_of_mass(np.concatenate([ma, mb]), np.concatenate([pa, pb]))
    total = np.zeros((3, 3))
    for m, p in ((ma, pa), (mb, pb)):
        mk, ck = mass_and_center_of_mass(m, p)
        d = ck - com
        total += inertia_from_point_masses(m, p) + mk * (d @ d * np.eye(3) - np.outer(d, d))
    np.testing.assert_allclose(whole, total, atol=ROUNDING_RTOL * np.abs(whole).max())


def test_rotated_cloud_has_world_inertia_r_i_rt():
    """Rotating the points by R (batched) gives inertia_world(R, I) = R I R^T."""
    rng = np.random.default_rng(2)
    masses, points = _random_cloud(rng, 10)
    rotations = _random_rotations(rng, 4)
    rotated = np.einsum("bij,nj->bni", rotations, points)
    direct = inertia_from_point_masses(np.broadcast_to(masses, (4, 10)), rotated)
    body = inertia_from_point_masses(masses, points)
    np.testing.assert_allclose(
        inertia_world(rotations, body), direct, atol=ROUNDING_RTOL * np.abs(body).max()
    )
    assert not np.allclose(direct[0], body, atol=1e-3 * np.abs(body).max())


def test_primitive_closed_forms():
    """Sphere 2/5 m r^2, box m (b^2 + c^2) / 12, cylinder m (3 r^2 + l^2) / 12 and m r^2 / 2, batched."""
    np.testing.assert_allclose(inertia_solid_sphere(2.5, 0.2), 0.04 * np.eye(3), rtol=ROUNDING_RTOL)
    np.testing.assert_allclose(
        inertia_solid_box(12.0, [1.0, 2.0, 3.0]), np.diag([13.0, 10.0, 5.0]), rtol=ROUNDING_RTOL
    )
    np.testing.assert_allclose(
        inertia_solid_cylinder(3.0, 0.1, 0.2), np.diag([0.0175, 0.0175, 0.015]), rtol=ROUNDING_RTOL
    )
    batch = inertia_solid_cylinder(np.array([1.0, 2.0]), 0.5, np.array([1.0, 3.0]))
    assert batch.shape == (2, 3, 3)
    np.testing.assert_allclose(batch[1], inertia_solid_cylinder(2.0, 0.5, 3.0), rtol=ROUNDING_RTOL)


@pytest.mark.parametrize(
    "call",
    [
        lambda: inertia_solid_sphere(-1.0, 0.1),
        lambda: inertia_solid_box(1.0, [0.1, 0.0, 0.2]),
        lambda: inertia_solid_cylinder(1.0, 0.1, np.nan),
        lambda: mass_and_center_of_mass([1.0, -0.5], np.zeros((2, 3))),
        lambda: mass_and_center_of_mass([0.0, 0.0], np.zeros((2, 3))),
    ],
)
def test_bad_mass_or_size_raises_scene_error(call):
    """A non-positive mass or size, or a zero total mass, raises SceneError."""
    with pytest.raises(SceneError):
        call()


def test_inertia_problem_accepts_real_bodies():
    """Primitives, a rotated point cloud and an exact thin plate (a + b = c) have no problem."""
    rng = np.random.default_rng(3)
    masses, points = _random_cloud(rng, 7)
    rotated = inertia_world(_random_rotations(rng, 1)[0], inertia_from_point_masses(masses, points))
    for inertia in (
        inertia_solid_sphere(1.0, 0.3),
        inertia_solid_box(10.0, [0.1, 0.4, 0.9]),
        inertia_solid_cylinder(2.0, 0.05, 1.0),
        rotated,
        np.diag([1.0, 2.0, 3.0]),
        np.diag([0.083333, 0.333333, 0.416667]),  # a 1 x 2 plate quoted to 6 digits
    ):
        assert inertia_problem(inertia) is None


@pytest.mark.parametrize(
    "inertia, words",
    [
        (np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), "not symmetric"),
        (np.diag([-0.5, 2.0, 2.0]), "not positive definite: eigenvalues (-0.5, 2, 2)"),
        (inertia_from_point_masses([1.0, 1.0], [[0, 0, -1.0], [0, 0, 1.0]]), "not positive definite"),
        (np.diag([1.0, 1.0, 3.0]), "triangle inequality: principal moments (1, 1, 3)"),
        (np.diag([1.0, 2.0, 3.0 + 1e-4]), "triangle inequality"),
        (np.eye(2), "shape (2, 2)"),
        (np.diag([1.0, np.inf, 1.0]), "non-finite"),
    ],
)
def test_inertia_problem_names_what_is_wrong(inertia, words):
    """Asymmetric, indefinite, singular, triangle-violating and malformed tensors are named."""
    problem = inertia_problem(inertia)
    assert problem is not None and words in problem


def test_point_masses_match_pinocchio():
    """Mass, COM and inertia about the COM equal a sum of Pinocchio point inertias."""
    rng = np.random.default_rng(4)
    masses, points = _random_cloud(rng, 12)
    total = pin.Inertia.Zero()
    for m, p in zip(masses, points):
        total += pin.Inertia(float(m), p, np.zeros((3, 3)))
    mass, com = mass_and_center_of_mass(masses, points)
    inertia = inertia_from_point_masses(masses, points)
    assert mass == pytest.approx(total.mass, rel=ROUNDING_RTOL)
    np.testing.assert_allclose(com, total.lever, atol=ROUNDING_RTOL * np.abs(points).max())
    np.testing.assert_allclose(inertia, total.inertia, atol=ROUNDING_RTOL * np.abs(inertia).max())


def _mujoco_body(masses: np.ndarray, points: np.ndarray) -> mujoco.MjModel:
    """A free body with one small sphere geom per point mass."""
    geoms = "".join(
        f'<geom type="sphere" size="{fmt(MUJOCO_SPHERE_RADIUS)}" mass="{fmt(m)}" pos="{fmt(p)}"/>'
        for m, p in zip(masses, points)
    )
    xml = f'<mujoco><worldbody><body name="cloud"><freejoint/>{geoms}</body></worldbody></mujoco>'
    return mujoco.MjModel.from_xml_string(xml)


@pytest.mark.parametrize("seed", [5, 6, 7])
def test_point_masses_match_mujoco(seed):
    """MuJoCo's body_ipos, principal moments and iquat tensor equal ours plus the spheres' 2/5 m r^2."""
    rng = np.random.default_rng(seed)
    masses, points = _random_cloud(rng, 10)
    model = _mujoco_body(masses, points)
    mass, com = mass_and_center_of_mass(masses, points)
    expected = inertia_from_point_masses(masses, points) + 0.4 * mass * MUJOCO_SPHERE_RADIUS**2 * np.eye(3)
    scale = np.abs(expected).max()
    rotation = quat_wxyz_to_matrix(model.body_iquat[1])
    rebuilt = rotation @ np.diag(model.body_inertia[1]) @ rotation.T
    assert model.body_mass[1] == pytest.approx(mass, rel=MUJOCO_RTOL)
    np.testing.assert_allclose(model.body_ipos[1], com, atol=MUJOCO_RTOL * np.abs(points).max())
    np.testing.assert_allclose(
        np.sort(model.body_inertia[1]), np.linalg.eigvalsh(expected), atol=MUJOCO_RTOL * scale
    )
    np.testing.assert_allclose(rebuilt, expected, atol=MUJOCO_RTOL * scale)


@pytest.mark.parametrize("inertia, words", [
    ([[1e308, 1e308, 0], [1e308, 1e308, 0], [0, 0, 1]], "not positive definite"),  # its check used to overflow to NaN
    ([[1e300, -1e300, 0], [1e300, 1e300, 0], [0, 0, 1]], "not symmetric"),
    (np.zeros((3, 3)), "zero"),
])
def test_inertia_problem_is_safe_at_extreme_magnitudes(inertia, words):
    """Entries of 1e308 neither overflow to NaN (and pass) nor stop the eigenvalues converging; no warnings."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        problem = inertia_problem(np.array(inertia, dtype=float))
    assert problem is not None and words in problem


@pytest.mark.parametrize("scale", [1e-320, 1e-300, 1e300, 5e307])
def test_inertia_problem_judges_the_shape_not_the_size(scale):
    """A valid tensor stays valid and an invalid one invalid at any finite scale (the range is the loader's)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert inertia_problem(np.diag([1.0, 2.0, 2.5]) * scale) is None
        assert "triangle" in inertia_problem(np.diag([1.0, 1.0, 3.0]) * scale)
