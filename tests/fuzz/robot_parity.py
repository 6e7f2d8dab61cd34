"""An importer's model against the random robot's own truth (tests/fuzz/robot_importers.py,
tests/fuzz/robot_files.py): every quantity beyond its tolerance (:data:`TOLERANCE`, relative to the model's own scale,
:func:`scales`) is a :class:`Discrepancy`; structural differences (it does not load, joints missing or extra, a floating
base, a body or group missing) have no tolerance. Mimic joints: MuJoCo keeps an equality constraint, which leaves M
alone; Pinocchio with ``mimic=True`` a reduced model, compared with G^T M G and G^T h of the truth
(q_follower = multiplier q_leader + offset)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tests.fuzz.robot_files import GRAVITY, RandomRobot
from tests.fuzz.robot_importers import Measured, State

ROUNDING = 1e-10
"""Relative agreement of double-precision importers with the truth. Measured over the sweep's 300 models: MuJoCo from
either format, Pinocchio from either and core (both methods) agree to 7e-15 at most on every quantity (M 6e-15, h 7e-15,
frames 7e-15, masses and inertias 4e-16); thin rods and discs cost nothing extra, since every error is relative to the
model's scale (:func:`scales`), not to a small moment. PyBullet's URDF importer, double too, is within 3.5e-11 where
its Jacobi diagonalisation stays below this and a known class where it does not."""

TOLERANCE = {quantity: ROUNDING for quantity in (
    "total_mass", "link_mass", "link_com", "link_inertia", "group_mass", "group_com", "group_inertia", "joint_axis",
    "joint_anchor", "joint_limits", "joint_damping", "joint_friction", "joint_armature", "mimic", "mass_matrix",
    "bias_forces")}
"""Quantity -> relative tolerance. Structural quantities (load, dofs, fixed_base, *_present) have none: any
difference is a discrepancy."""


@dataclass(frozen=True)
class Discrepancy:
    """One quantity of one importer off the truth: ``item`` names the link, group, joint or state (``#k``);
    ``error`` is relative (:func:`scales`), inf for a structural difference."""

    seed: int
    importer: str
    quantity: str
    item: str
    error: float
    detail: str

    @property
    def key(self) -> tuple[str, str, str]:
        return self.importer, self.quantity, self.item

    def line(self) -> str:
        return (f"seed {self.seed} {self.importer} {self.quantity}[{self.item}]: error {self.error:.3g} "
                f"({self.detail})")


def scales(robot: RandomRobot) -> dict[str, float]:
    """The model's own scales: its mass, its size (1 m at least) and inertia mass x size^2. M is compared relative to
    its largest entry, h to the larger of its largest entry and the model's weight x size (h may vanish at a state,
    its rounding does not)."""
    size = max(1.0, max(float(np.abs(link.com).max()) for link in robot.links),
               max(float(np.abs(joint.anchor).max()) for joint in robot.joints) if robot.joints else 0.0)
    mass = robot.total_mass or 1.0  # a massless model (a minimiser's) is measured in kilograms
    return {"mass": mass, "length": size, "inertia": mass * size * size}


def _gap(a, b) -> float:
    """max |a - b| over entries, with equal infinities counted equal and unequal ones (or NaN) as inf."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if not a.size:
        return 0.0
    with np.errstate(invalid="ignore"):
        diff = np.abs(a - b)
    if np.isfinite(diff).all():
        return float(diff.max())
    same_inf = np.isinf(a) & np.isinf(b) & (np.sign(a) == np.sign(b))
    diff = np.where(same_inf, 0.0, diff)
    return float(np.nan_to_num(diff, nan=np.inf).max())


def compare(robot: RandomRobot, importer: str, measured: Measured, states: list[State],
            details: bool = True) -> list[Discrepancy]:
    """Every quantity of ``measured`` off the truth beyond :data:`TOLERANCE` (``details``: with its numbers in
    words; a counterfactual needs none)."""
    out: list[Discrepancy] = []
    scale = scales(robot)

    def check(quantity: str, item: str, error: float, detail: Callable[[], str] | str) -> None:
        """Record a discrepancy beyond the quantity's tolerance (``detail`` formatted only then: it is costly)."""
        if not error <= TOLERANCE.get(quantity, 0.0):
            text = detail() if callable(detail) and details else detail if details else ""
            out.append(Discrepancy(robot.seed, importer, quantity, item, error, text))

    if measured.refused:
        check("load", "", np.inf, measured.refused)
        return out
    engine, fmt = importer.split("/")
    core = engine.startswith("core")
    expected_dofs = set(robot.movable) if not core else set(measured.dofs)
    if engine == "pinocchio-mimic":
        expected_dofs -= {joint.name for joint in robot.spec.joints if joint.mimic}
    if set(measured.dofs) != expected_dofs:
        check("dofs", "", np.inf, f"missing {sorted(expected_dofs - set(measured.dofs))}, "
                                  f"extra {sorted(set(measured.dofs) - expected_dofs)}")
    if not measured.fixed_base:
        check("fixed_base", "", np.inf, "the base link floats")
    if measured.total_mass is not None:
        check("total_mass", "", abs(measured.total_mass - robot.total_mass) / scale["mass"],
              f"{measured.total_mass:.17g} vs {robot.total_mass:.17g} kg")
    truth_links = {link.name: link for link in robot.links}
    if measured.links is not None:
        for name, link in truth_links.items():
            if name not in measured.links:
                check("link_present", name, np.inf, "no body of that name")
                continue
            mass, com, inertia = measured.links[name]
            _mass_com_inertia(check, "link", name, (mass, com, inertia), (link.mass, link.com, link.inertia), scale)
    if measured.groups is not None:
        for name, truth in robot.groups().items():
            if name not in measured.groups:
                check("group_present", name, np.inf, "no rigid group of that name")
                continue
            _mass_com_inertia(check, "group", name, measured.groups[name], truth, scale)
    truth_joints = {joint.name: joint for joint in robot.joints}
    for name, seen in measured.joints.items():
        joint = truth_joints.get(name)
        if joint is None:
            continue
        if "axis" in seen:
            check("joint_axis", name, _gap(seen["axis"], joint.axis),
                  lambda: f"{np.round(seen['axis'], 6)} vs {np.round(joint.axis, 6)}")
            check("joint_anchor", name, _gap(seen["anchor"], joint.anchor) / scale["length"],
                  lambda: f"{np.round(seen['anchor'], 6)} vs {np.round(joint.anchor, 6)}")
        if "limits" in seen:
            size = max([1.0] + [abs(v) for v in (joint.lower, joint.upper) if np.isfinite(v)])
            check("joint_limits", name, _gap(seen["limits"], (joint.lower, joint.upper)) / size,
                  lambda: f"{seen['limits']} vs {(joint.lower, joint.upper)}")
        for attribute in ("damping", "friction", "armature"):
            if attribute in seen:
                expected = getattr(joint, attribute) if attribute != "armature" or fmt == "mjcf" else 0.0
                check(f"joint_{attribute}", name, abs(seen[attribute] - expected) / max(1.0, expected),
                      lambda: f"{seen[attribute]:.17g} vs {expected:.17g}")
    if measured.mimic is not None:
        for joint in robot.spec.joints:
            if joint.mimic is None:
                continue
            seen = measured.mimic.get(joint.name)
            truth = (joint.mimic.leader, joint.mimic.multiplier, joint.mimic.offset)
            if seen is None or seen[0] != truth[0]:
                check("mimic", joint.name, np.inf, f"{seen} vs {truth}")
            else:
                check("mimic", joint.name, _gap([v for v in seen[1:] if not np.isnan(v)],
                                                [t for v, t in zip(seen[1:], truth[1:]) if not np.isnan(v)]),
                      f"{seen} vs {truth}")
    _dynamics(check, robot, importer, measured, states)
    return out


def _mass_com_inertia(check, kind: str, name: str, seen, truth, scale: dict) -> None:
    mass, com, inertia = seen
    t_mass, t_com, t_inertia = truth
    check(f"{kind}_mass", name, abs(mass - t_mass) / scale["mass"], lambda: f"{mass:.17g} vs {t_mass:.17g} kg")
    if t_mass > 0 and mass > 0:
        check(f"{kind}_com", name, _gap(com, t_com) / scale["length"],
              lambda: f"{np.round(com, 6)} vs {np.round(t_com, 6)}")
    check(f"{kind}_inertia", name, _gap(inertia, t_inertia) / scale["inertia"],
          lambda: f"principal {np.round(np.linalg.eigvalsh(inertia), 9)} vs "
                  f"{np.round(np.linalg.eigvalsh(t_inertia), 9)}")


def _dynamics(check, robot: RandomRobot, importer: str, measured: Measured, states: list[State]) -> None:
    """M and h at each state on the joints the importer and the truth share (h: where computed)."""
    engine, fmt = importer.split("/")
    scale = scales(robot)
    scale_h = scale["mass"] * float(np.linalg.norm(GRAVITY)) * scale["length"]
    names = robot.movable
    common = [name for name in measured.dofs if name in names]
    if not common or measured.mass_matrices is None:
        return
    at = [measured.dofs.index(name) for name in common]
    for k, state in enumerate(states):
        q = np.array([state.q[n] for n in names])
        qdot = np.array([state.qdot[n] for n in names])
        m_full = robot.mass_matrix(q, armature=fmt == "mjcf" and engine != "core")
        h_full = robot.bias_forces(q, qdot)
        if engine == "pinocchio-mimic":
            g = _mimic_map(robot, common)
            m_truth, h_truth = g.T @ m_full @ g, g.T @ h_full
        else:
            idx = [names.index(n) for n in common]
            m_truth, h_truth = m_full[np.ix_(idx, idx)], h_full[idx]
        m_seen = measured.mass_matrices[k][np.ix_(at, at)]
        check("mass_matrix", f"#{k}", _gap(m_seen, m_truth) / (np.abs(m_truth).max() or 1.0),
              lambda: f"max |dM| {np.abs(m_seen - m_truth).max():.3g} of |M| {np.abs(m_truth).max():.3g} at "
                      f"{[common[i] for i in np.unravel_index(np.argmax(np.abs(m_seen - m_truth)), m_truth.shape)]}")
        if measured.bias is not None:
            h_seen = measured.bias[k][at]
            h_scale = max(np.abs(h_truth).max(), scale_h)
            check("bias_forces", f"#{k}", _gap(h_seen, h_truth) / h_scale,
                  lambda: f"max |dh| {np.abs(h_seen - h_truth).max():.3g} of |h| {np.abs(h_truth).max():.3g}")


def _mimic_map(robot: RandomRobot, reduced: list[str]) -> np.ndarray:
    """G (n, r): dq_full = G dq_reduced, followers moving at multiplier x their leader."""
    names = robot.movable
    g = np.zeros((len(names), len(reduced)))
    for col, name in enumerate(reduced):
        g[names.index(name), col] = 1.0
    for joint in robot.spec.joints:
        if joint.mimic and joint.mimic.leader in reduced:
            g[names.index(joint.name), reduced.index(joint.mimic.leader)] = joint.mimic.multiplier
    return g

