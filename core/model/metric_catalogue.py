"""The metric catalogue: every metric a run can write, with its unit and what kind of quantity it is.

One place for what the measuring code, the tolerances, the gate, the report and the figures say about a
metric: its name (the ``metric`` column), its unit (the ``unit`` column), its kind (an error against the
reference, a drift, an observed order, a wall time, a contact or IK quantity, a state's validity), whether a
report ranks schemes by it (headline), the quantity whose own scale saturates it, and the theory it is held
to. Code refers to a metric by the constants below, never by spelling its name again, so a rename is one edit
and a typo an import error. The definitions with their reasons: ``docs/metrics.md``.

Families of metrics named after something a scene chooses (an IK scene's hard targets, a metamorphic
transform) are :class:`MetricFamily` entries: ``hard_<target>_solved``, ``invariance_ratio_<transform>``.
"""

from __future__ import annotations

from dataclasses import dataclass

from simparity.core.model.results import DIMENSIONLESS

ERROR, DRIFT, ORDER, TIMING, COST, CONTACT, IK, VALIDITY, STABILITY, INVARIANCE, PREDICTABILITY, PROBE = (
    "error", "drift", "order", "timing", "cost", "contact", "ik", "validity", "stability", "invariance",
    "predictability", "probe")
KINDS = (ERROR, DRIFT, ORDER, TIMING, COST, CONTACT, IK, VALIDITY, STABILITY, INVARIANCE, PREDICTABILITY, PROBE)
"""What a metric measures: an error against the reference; a relative drift of a conserved quantity; an observed
order of convergence; a wall time (never compared between runs); a hardware-neutral cost (exact, from what the
engine declares: the same on every machine, and no measure of its numerics); a contact event's quantity; an IK
solver's outcome; a reported state's validity (unit quaternion, orthonormal matrix); a measured stability limit; a
metamorphic invariance check; a chaotic motion's predictability (when two runs part); a probe of an engine's
floating-point behaviour (the finite-difference step sweep's best steps and the error there: where its rounding meets
a truncation, which moves with the rounding of the coordinates it computes in, so never held invariant under a change
of frame or units)."""


@dataclass(frozen=True)
class Metric:
    """One metric of the catalogue.

    ``scale``: the quantity whose own scale saturates it (``position``, ``velocity``, ``orientation``,
    ``angular_velocity``, ``energy``; "" when none); ``theory``: the rule it is held to in theory ("" when
    none), e.g. an order's scheme order; ``source``: for an order, the error it is the slope of; ``signed``: a value
    below 0 is a measurement (not an error's magnitude: M's smallest scaled eigenvalue)."""

    name: str
    unit: str
    kind: str
    headline: bool = False
    scale: str = ""
    theory: str = ""
    source: str = ""
    signed: bool = False

    @property
    def is_timing(self) -> bool:
        return self.kind == TIMING

    @property
    def non_negative(self) -> bool:
        """Whether no value of it is below 0: errors, drifts, residuals, times, rates and counts are magnitudes; an
        observed order (an error growing as dt falls has a negative slope) and a ``signed`` quantity are not."""
        return not self.signed and self.kind != ORDER


@dataclass(frozen=True)
class MetricFamily:
    """Metrics named ``prefix + <member> + suffix`` (an IK scene's hard target, a transform's name)."""

    prefix: str
    suffix: str
    unit: str
    kind: str

    def name(self, member: str) -> str:
        return f"{self.prefix}{member}{self.suffix}"

    def matches(self, name: str) -> bool:
        middle = name[len(self.prefix):len(name) - len(self.suffix)] if self.suffix else name[len(self.prefix):]
        return name.startswith(self.prefix) and name.endswith(self.suffix) and bool(middle) and "." not in middle


# Dynamics: errors against the reference trajectory (maxima over bodies and samples; final at the last one).
POSITION_ERROR_MAX = "position_error_max"
POSITION_ERROR_FINAL = "position_error_final"
ORIENTATION_ERROR_MAX = "orientation_error_max"
VELOCITY_ERROR_MAX = "velocity_error_max"
ANGULAR_VELOCITY_ERROR_MAX = "angular_velocity_error_max"
QUATERNION_NORM_DEVIATION_MAX = "quaternion_norm_deviation_max"
TIME_PER_STEP = "time_per_step"
TIME_PER_STEP_BATCHED = "time_per_step_batched"
EVALUATIONS_PER_SECOND = "evaluations_per_second"
ENERGY_DRIFT_MAX = "energy_drift_max"
ANGULAR_MOMENTUM_DRIFT_MAX = "angular_momentum_drift_max"
ORDER_POSITION = "order_position"
ORDER_ORIENTATION = "order_orientation"
ORDER_VELOCITY = "order_velocity"
ORDER_ANGULAR_VELOCITY = "order_angular_velocity"
STABLE_DT_MAX = "stable_dt_max"
# Kinematics: frames and Jacobians against the reference.
JACOBIAN_ERROR_MAX = "jacobian_error_max"
ROTATION_ORTHONORMALITY_DEVIATION_MAX = "rotation_orthonormality_deviation_max"
TIME_PER_FK = "time_per_fk"
TIME_PER_JACOBIAN = "time_per_jacobian"
# Joint-space dynamics: relative errors against the reference at the scene's states, identities of the engine's own.
MASS_MATRIX_ERROR_MAX = "mass_matrix_error_max"
BIAS_FORCE_ERROR_MAX = "bias_force_error_max"
INVERSE_DYNAMICS_ERROR_MAX = "inverse_dynamics_error_max"
FORWARD_DYNAMICS_ERROR_MAX = "forward_dynamics_error_max"
GRAVITY_IDENTITY_RESIDUAL = "gravity_identity_residual"
MASS_COLUMN_RESIDUAL = "mass_column_residual"
ROUND_TRIP_RESIDUAL = "round_trip_residual"
MASS_MATRIX_ASYMMETRY = "mass_matrix_asymmetry"
MASS_MATRIX_DEFINITENESS_MIN = "mass_matrix_definiteness_min"
KINETIC_ENERGY_RESIDUAL = "kinetic_energy_residual"
CORIOLIS_SKEW_RESIDUAL = "coriolis_skew_residual"
GRAVITY_EQUIVALENCE_RESIDUAL = "gravity_equivalence_residual"
BASE_MOMENTUM_RESIDUAL = "base_momentum_residual"
# Derivatives of the dynamics against the complex-step truth (issue #44).
RNEA_DERIVATIVE_ERROR_MAX = "rnea_derivative_error_max"
ABA_DERIVATIVE_ERROR_MAX = "aba_derivative_error_max"
DERIVATIVE_IDENTITY_RESIDUAL = "derivative_identity_residual"
DERIVATIVE_STEP_EXCESS = "derivative_step_excess"
STEP_JACOBIAN_ERROR_MAX = "step_jacobian_error_max"
STEP_JACOBIAN_STEP_EXCESS = "step_jacobian_step_excess"
FORWARD_DIFFERENCE_BEST_STEP = "forward_difference_best_step"
FORWARD_DIFFERENCE_FLOOR = "forward_difference_floor"
CENTRAL_DIFFERENCE_BEST_STEP = "central_difference_best_step"
CENTRAL_DIFFERENCE_FLOOR = "central_difference_floor"
TIME_PER_MASS_MATRIX = "time_per_mass_matrix"
TIME_PER_INVERSE_DYNAMICS = "time_per_inverse_dynamics"
TIME_PER_FORWARD_DYNAMICS = "time_per_forward_dynamics"
# Model-level parity: what each engine compiled from the robot file, rigid group by rigid group, against the reference.
MODEL_MASS_ERROR_MAX = "model_mass_error_max"
MODEL_COM_ERROR_MAX = "model_com_error_max"
MODEL_INERTIA_ERROR_MAX = "model_inertia_error_max"
MODEL_AXIS_ERROR_MAX = "model_axis_error_max"
MODEL_ORIGIN_ERROR_MAX = "model_origin_error_max"
MODEL_JOINT_TYPE_MISMATCHES = "model_joint_type_mismatches"
MODEL_LIMIT_MISMATCHES = "model_limit_mismatches"
# Joint motion: unitless errors of a chain's motion against the reference, each engine's own energy balance.
JOINT_ANGLE_ERROR_MAX = "joint_angle_error_max"
JOINT_VELOCITY_ERROR_MAX = "joint_velocity_error_max"
END_EFFECTOR_ERROR_MAX = "end_effector_error_max"
POWER_BALANCE_RESIDUAL_MAX = "power_balance_residual_max"
ORDER_JOINT_ANGLE = "order_joint_angle"
ORDER_JOINT_VELOCITY = "order_joint_velocity"
SEGMENT_REFERENCE_ERROR_MAX = "segment_reference_error_max"
LINEAR_MOMENTUM_DRIFT_MAX = "linear_momentum_drift_max"
CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX = "chain_angular_momentum_drift_max"
SELF_PARTING_TIME = "self_parting_time"
REFERENCE_PARTING_TIME = "reference_parting_time"
# Contact: events against the exact bounce sequence, slide and rest.
IMPACT_TIME_ERROR = "impact_time_error"
REBOUND_VELOCITY_ERROR = "rebound_velocity_error"
APEX_HEIGHT_ERROR = "apex_height_error"
RESTITUTION_MEASURED = "restitution_measured"
RESTITUTION_ERROR = "restitution_error"
RESTITUTION_MIN = "restitution_min"
RESTITUTION_MEDIAN = "restitution_median"
RESTITUTION_MAX = "restitution_max"
ENERGY_LOSS_ERROR = "energy_loss_error"
ENERGY_KEPT_MIN = "energy_kept_min"
ENERGY_KEPT_MEDIAN = "energy_kept_median"
ENERGY_KEPT_MAX = "energy_kept_max"
PENETRATION_MAX = "penetration_max"
TUNNELLED = "tunnelled"
IMPACTS_MISSED = "impacts_missed"
ENERGY_GAIN_MAX = "energy_gain_max"
REST_TIME_ERROR = "rest_time_error"
REST_JITTER = "rest_jitter"
STOPPING_DISTANCE = "stopping_distance"
STOPPING_DISTANCE_ERROR = "stopping_distance_error"
# A chain's contact spheres on a plane (issue #46): truths that need no engine.
TOUCHDOWN_TIME_ERROR = "touchdown_time_error"
TOUCHDOWN_TIME_STEPS = "touchdown_time_steps"
CONTACT_PENETRATION_MAX = "contact_penetration_max"
SIGNORINI_VIOLATION_MAX = "signorini_violation_max"
FRICTION_CONE_VIOLATION_MAX = "friction_cone_violation_max"
SLIDING_FRICTION_ERROR = "sliding_friction_error"
CONTACT_CENTRE_ERROR = "contact_centre_error"
SLIDING_FRICTION_ANGLE_MAX = "sliding_friction_angle_max"
FRICTION_IMPULSE_ERROR = "friction_impulse_error"
CONTACT_ENERGY_GAIN_MAX = "contact_energy_gain_max"
REST_WEIGHT_ERROR = "rest_weight_error"
REST_EQUILIBRIUM_ERROR = "rest_equilibrium_error"
REST_ACCELERATION_MAX = "rest_acceleration_max"
# IK: a solver's outcome on its targets, judged by the harness.
SOLVE_RATE = "solve_rate"
SOLVE_RATE_OWN_STOP = "solve_rate_own_stop"
OWN_STOP_POSITION_TOLERANCE = "own_stop_position_tolerance"
CROSS_EVAL_SOLVE_RATE_MIN = "cross_eval_solve_rate_min"
CROSS_EVAL_DISAGREEMENT_MAX = "cross_eval_disagreement_max"
POSITION_RESIDUAL_MEDIAN = "position_residual_median"
POSITION_RESIDUAL_MAX = "position_residual_max"
ORIENTATION_RESIDUAL_MEDIAN = "orientation_residual_median"
ORIENTATION_RESIDUAL_MAX = "orientation_residual_max"
ITERATIONS_MEDIAN = "iterations_median"
LIMIT_VIOLATIONS = "limit_violations"
UNCONFIRMED_CLAIMS = "unconfirmed_claims"
REST_DISTANCE_MEDIAN = "rest_distance_median"
START_RANK_DEFICIENCY = "start_rank_deficiency"
FK_DEPARTURE_MAX = "fk_departure_max"
JACOBIAN_DEPARTURE_MAX = "jacobian_departure_max"
TIME_PER_SOLVE = "time_per_solve"

_ANGLE_OR_LENGTH = "rad or m"
_JACOBIAN_UNIT = "m/rad or 1"

CATALOGUE: dict[str, Metric] = {m.name: m for m in (
    Metric(POSITION_ERROR_MAX, "m", ERROR, headline=True, scale="position"),
    Metric(POSITION_ERROR_FINAL, "m", ERROR, scale="position"),
    Metric(ORIENTATION_ERROR_MAX, "rad", ERROR, headline=True, scale="orientation"),
    Metric(VELOCITY_ERROR_MAX, "m/s", ERROR, scale="velocity"),
    Metric(ANGULAR_VELOCITY_ERROR_MAX, "rad/s", ERROR, scale="angular_velocity"),
    Metric(QUATERNION_NORM_DEVIATION_MAX, DIMENSIONLESS, VALIDITY, theory="0 up to rounding"),
    Metric(TIME_PER_STEP, "s", TIMING),
    Metric(TIME_PER_STEP_BATCHED, "s", TIMING),
    Metric(EVALUATIONS_PER_SECOND, "1/s", COST, theory="the integrator's stages / dt"),
    Metric(ENERGY_DRIFT_MAX, DIMENSIONLESS, DRIFT, scale="energy", theory="0 for a conservative scene"),
    Metric(ANGULAR_MOMENTUM_DRIFT_MAX, DIMENSIONLESS, DRIFT, theory="0 without torque"),
    Metric(ORDER_POSITION, DIMENSIONLESS, ORDER, theory="the scheme's order", source=POSITION_ERROR_MAX),
    Metric(ORDER_ORIENTATION, DIMENSIONLESS, ORDER, theory="the scheme's order", source=ORIENTATION_ERROR_MAX),
    Metric(ORDER_VELOCITY, DIMENSIONLESS, ORDER, theory="the scheme's order", source=VELOCITY_ERROR_MAX),
    Metric(ORDER_ANGULAR_VELOCITY, DIMENSIONLESS, ORDER, theory="the scheme's order",
           source=ANGULAR_VELOCITY_ERROR_MAX),
    Metric(STABLE_DT_MAX, "s", STABILITY),
    Metric(JACOBIAN_ERROR_MAX, _JACOBIAN_UNIT, ERROR),
    Metric(ROTATION_ORTHONORMALITY_DEVIATION_MAX, DIMENSIONLESS, VALIDITY, theory="0 up to rounding"),
    Metric(TIME_PER_FK, "s", TIMING),
    Metric(TIME_PER_JACOBIAN, "s", TIMING),
    Metric(MASS_MATRIX_ERROR_MAX, DIMENSIONLESS, ERROR),
    Metric(BIAS_FORCE_ERROR_MAX, DIMENSIONLESS, ERROR),
    Metric(INVERSE_DYNAMICS_ERROR_MAX, DIMENSIONLESS, ERROR),
    Metric(FORWARD_DYNAMICS_ERROR_MAX, DIMENSIONLESS, ERROR),
    Metric(GRAVITY_IDENTITY_RESIDUAL, DIMENSIONLESS, VALIDITY, theory="RNEA(q, 0, 0) = g(q): 0 up to rounding"),
    Metric(MASS_COLUMN_RESIDUAL, DIMENSIONLESS, VALIDITY, theory="RNEA(q, 0, e_i) - g(q) = M e_i: 0 up to rounding"),
    Metric(ROUND_TRIP_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="ABA(q, qdot, RNEA(q, qdot, qddot)) = qddot (in torque space): 0 up to rounding"),
    Metric(MASS_MATRIX_ASYMMETRY, DIMENSIONLESS, VALIDITY, theory="M = M^T: 0 up to rounding"),
    Metric(MASS_MATRIX_DEFINITENESS_MIN, DIMENSIONLESS, VALIDITY, signed=True,
           theory="> 0: M (scaled by its diagonal) is positive definite"),
    Metric(KINETIC_ENERGY_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="1/2 qdot^T M qdot = the links' kinetic energy: 0 up to rounding"),
    Metric(CORIOLIS_SKEW_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="qdot^T (Mdot - 2 C) qdot = 0: 0 up to finite differences"),
    Metric(GRAVITY_EQUIVALENCE_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="a floating base: h(q, 0) = -M(q)[:, base linear] g, gravity a uniform acceleration of the base: 0 up "
                  "to rounding"),
    Metric(RNEA_DERIVATIVE_ERROR_MAX, DIMENSIONLESS, ERROR,
           theory="dtau/dq and dtau/dqdot against the complex-step truth: rounding for analytic derivatives, the "
                  "truncation of a finite difference's step"),
    Metric(ABA_DERIVATIVE_ERROR_MAX, DIMENSIONLESS, ERROR,
           theory="dqddot/dq, dqddot/dqdot, dqddot/dtau against the complex-step truth, in torque space: rounding for "
                  "analytic derivatives"),
    Metric(DERIVATIVE_IDENTITY_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="dqddot/dtau M = I with the engine's own M: 0 up to rounding"),
    Metric(DERIVATIVE_STEP_EXCESS, DIMENSIONLESS, ERROR,
           theory="a differenced partial's error over that of the scheme it declares at its steps (the truth's own "
                  "inverse dynamics differenced alike): ~1"),
    Metric(STEP_JACOBIAN_ERROR_MAX, DIMENSIONLESS, ERROR,
           theory="dx'/d(x, tau) of one step against the complex-step truth through the scheme's formula, over kappa_1(M): "
                  "rounding for an analytic Jacobian"),
    Metric(STEP_JACOBIAN_STEP_EXCESS, DIMENSIONLESS, ERROR,
           theory="a differenced step Jacobian's error over that of the truth's own step differenced alike: ~1"),
    Metric(FORWARD_DIFFERENCE_BEST_STEP, DIMENSIONLESS, PROBE,
           theory="the step [rad or m] where forward differences of the engine's inverse dynamics err least: "
                  "~sqrt(eps) ~ 1e-8 where truncation meets rounding"),
    Metric(FORWARD_DIFFERENCE_FLOOR, DIMENSIONLESS, PROBE,
           theory="dtau/dq by forward differences at the best step, against the complex-step truth: ~sqrt(eps)"),
    Metric(CENTRAL_DIFFERENCE_BEST_STEP, DIMENSIONLESS, PROBE,
           theory="the step [rad or m] where centred differences err least: ~eps^(1/3) ~ 6e-6"),
    Metric(CENTRAL_DIFFERENCE_FLOOR, DIMENSIONLESS, PROBE,
           theory="dtau/dq by centred differences at the best step, against the complex-step truth: ~eps^(2/3)"),
    Metric(BASE_MOMENTUM_RESIDUAL, DIMENSIONLESS, VALIDITY,
           theory="a floating base: M's base rows times qdot = the robot's momentum (linear, angular about the base "
                  "origin) summed from the engine's own link velocities: 0 up to rounding"),
    Metric(TIME_PER_MASS_MATRIX, "s", TIMING),
    Metric(TIME_PER_INVERSE_DYNAMICS, "s", TIMING),
    Metric(TIME_PER_FORWARD_DYNAMICS, "s", TIMING),
    Metric(MODEL_MASS_ERROR_MAX, DIMENSIONLESS, ERROR, theory="the same file read alike: 0 up to rounding"),
    Metric(MODEL_COM_ERROR_MAX, DIMENSIONLESS, ERROR, theory="the same file read alike: 0 up to rounding"),
    Metric(MODEL_INERTIA_ERROR_MAX, DIMENSIONLESS, ERROR, theory="the same file read alike: 0 up to rounding"),
    Metric(MODEL_AXIS_ERROR_MAX, "rad", ERROR, theory="the same file read alike: 0 up to rounding"),
    Metric(MODEL_ORIGIN_ERROR_MAX, DIMENSIONLESS, ERROR, theory="the same file read alike: 0 up to rounding"),
    Metric(MODEL_JOINT_TYPE_MISMATCHES, DIMENSIONLESS, ERROR,
           theory="the same file read alike: 0 joints revolute in one engine and prismatic in the other"),
    Metric(MODEL_LIMIT_MISMATCHES, DIMENSIONLESS, ERROR,
           theory="the same file read alike: 0 joints whose limits differ (limited in one engine only, or apart by "
                  "more than rounding)"),
    Metric(JOINT_ANGLE_ERROR_MAX, DIMENSIONLESS, ERROR, headline=True, scale="joint_angle"),
    Metric(JOINT_VELOCITY_ERROR_MAX, DIMENSIONLESS, ERROR, scale="joint_velocity"),
    Metric(END_EFFECTOR_ERROR_MAX, DIMENSIONLESS, ERROR, scale="reach"),
    Metric(POWER_BALANCE_RESIDUAL_MAX, DIMENSIONLESS, DRIFT, scale="energy",
           theory="E(t) - E(0) = the work of the applied forces less the damping's: 0 up to the scheme's error"),
    Metric(ORDER_JOINT_ANGLE, DIMENSIONLESS, ORDER, theory="the scheme's order", source=JOINT_ANGLE_ERROR_MAX),
    Metric(ORDER_JOINT_VELOCITY, DIMENSIONLESS, ORDER, theory="the scheme's order", source=JOINT_VELOCITY_ERROR_MAX),
    Metric(SEGMENT_REFERENCE_ERROR_MAX, DIMENSIONLESS, ERROR, scale="joint_angle",
           theory="the model against the reference's: the scheme's error at dt / 16 and nothing else"),
    Metric(LINEAR_MOMENTUM_DRIFT_MAX, DIMENSIONLESS, DRIFT, scale="momentum",
           theory="a floating base under joint forces only: the robot's momentum P(t) = P(0) + m g t (the centre of "
                  "mass falls as a particle): 0 up to the scheme's error"),
    Metric(CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, DIMENSIONLESS, DRIFT, scale="momentum",
           theory="a floating base under joint forces only: the robot's angular momentum about its centre of mass "
                  "conserved (gravity has no moment about it): 0 up to the scheme's error"),
    Metric(SELF_PARTING_TIME, "s", PREDICTABILITY,
           theory="when the engine's runs from two starts a perturbation apart part: the chain's own horizon"),
    Metric(REFERENCE_PARTING_TIME, "s", PREDICTABILITY, theory="not before the self-parting time, for a sound engine"),
    Metric(TOUCHDOWN_TIME_ERROR, DIMENSIONLESS, CONTACT,
           theory="a robot falling at rest as one body touches down at the closed-form time: 0 up to the scheme's "
                  "error"),
    Metric(TOUCHDOWN_TIME_STEPS, DIMENSIONLESS, CONTACT,
           theory="the touchdown's error in the fall's first-order shift (dt a t_c / v_c): semi-implicit Euler "
                  "touches down half of it early and explicit Euler half late in any scene; RK4 and the midpoint "
                  "rule: 0"),
    Metric(CONTACT_CENTRE_ERROR, DIMENSIONLESS, CONTACT,
           theory="the engine's spheres where the robot file puts them (an independent model's kinematics): 0 up to "
                  "rounding"),
    Metric(CONTACT_PENETRATION_MAX, DIMENSIONLESS, CONTACT,
           theory="soft contact penetrates: each engine's own stiffness; past 1 a sphere has sunk through its radius"),
    Metric(SIGNORINI_VIOLATION_MAX, DIMENSIONLESS, CONTACT,
           theory="a plane pushes only on a touching sphere and never pulls: 0"),
    Metric(FRICTION_CONE_VIOLATION_MAX, DIMENSIONLESS, CONTACT, theory="inside the Coulomb cone: 0"),
    Metric(SLIDING_FRICTION_ERROR, DIMENSIONLESS, CONTACT,
           theory="a sliding contact's friction is on its cone, |f_t| = mu f_n: 0"),
    Metric(SLIDING_FRICTION_ANGLE_MAX, "rad", CONTACT,
           theory="Coulomb's friction opposes the slip (maximal dissipation): 0; friction that only takes energy: "
                  "below pi / 2"),
    Metric(FRICTION_IMPULSE_ERROR, DIMENSIONLESS, CONTACT,
           theory="a floating base's momentum along the plane changes by gravity's and the reported contact forces' "
                  "impulse: 0 up to the scheme's and the samples' quadrature"),
    Metric(CONTACT_ENERGY_GAIN_MAX, DIMENSIONLESS, CONTACT,
           theory="contact and damping only take energy: 0 up to the scheme's error"),
    Metric(REST_WEIGHT_ERROR, DIMENSIONLESS, CONTACT, theory="at rest the plane carries the weight: 0"),
    Metric(REST_EQUILIBRIUM_ERROR, DIMENSIONLESS, CONTACT,
           theory="at rest the contact forces, gravity and the joint forces balance on every joint and the base: 0"),
    Metric(REST_ACCELERATION_MAX, DIMENSIONLESS, CONTACT,
           theory="from the time the scene says its robot rests, nothing accelerates: 0"),
    Metric(IMPACT_TIME_ERROR, "s", CONTACT),
    Metric(REBOUND_VELOCITY_ERROR, "m/s", CONTACT),
    Metric(APEX_HEIGHT_ERROR, "m", CONTACT),
    Metric(RESTITUTION_MEASURED, DIMENSIONLESS, CONTACT, theory="the requested restitution"),
    Metric(RESTITUTION_ERROR, DIMENSIONLESS, CONTACT),
    Metric(RESTITUTION_MIN, DIMENSIONLESS, CONTACT),
    Metric(RESTITUTION_MEDIAN, DIMENSIONLESS, CONTACT),
    Metric(RESTITUTION_MAX, DIMENSIONLESS, CONTACT),
    Metric(ENERGY_LOSS_ERROR, DIMENSIONLESS, CONTACT),
    Metric(ENERGY_KEPT_MIN, DIMENSIONLESS, CONTACT),
    Metric(ENERGY_KEPT_MEDIAN, DIMENSIONLESS, CONTACT),
    Metric(ENERGY_KEPT_MAX, DIMENSIONLESS, CONTACT),
    Metric(PENETRATION_MAX, "m", CONTACT),
    Metric(TUNNELLED, DIMENSIONLESS, CONTACT, theory="0: a body never passes through a plane"),
    Metric(IMPACTS_MISSED, DIMENSIONLESS, CONTACT),
    Metric(ENERGY_GAIN_MAX, DIMENSIONLESS, CONTACT, theory="at most 1: contact only takes energy away"),
    Metric(REST_TIME_ERROR, "s", CONTACT),
    Metric(REST_JITTER, "m", CONTACT),
    Metric(STOPPING_DISTANCE, "m", CONTACT),
    Metric(STOPPING_DISTANCE_ERROR, "m", CONTACT),
    Metric(SOLVE_RATE, DIMENSIONLESS, IK, headline=True),
    Metric(SOLVE_RATE_OWN_STOP, DIMENSIONLESS, IK,
           theory="solve_rate where the solver stops at the scene's tolerances"),
    Metric(OWN_STOP_POSITION_TOLERANCE, "m", IK,
           theory="the scene's position tolerance unless the solver declares its own"),
    Metric(CROSS_EVAL_SOLVE_RATE_MIN, DIMENSIONLESS, IK),
    Metric(CROSS_EVAL_DISAGREEMENT_MAX, "m", IK),
    Metric(POSITION_RESIDUAL_MEDIAN, "m", IK),
    Metric(POSITION_RESIDUAL_MAX, "m", IK),
    Metric(ORIENTATION_RESIDUAL_MEDIAN, "rad", IK),
    Metric(ORIENTATION_RESIDUAL_MAX, "rad", IK),
    Metric(ITERATIONS_MEDIAN, DIMENSIONLESS, IK),
    Metric(LIMIT_VIOLATIONS, DIMENSIONLESS, IK),
    Metric(UNCONFIRMED_CLAIMS, DIMENSIONLESS, IK, theory="0: a solver's success is the harness's"),
    Metric(REST_DISTANCE_MEDIAN, _ANGLE_OR_LENGTH, IK),
    Metric(START_RANK_DEFICIENCY, DIMENSIONLESS, IK),
    Metric(FK_DEPARTURE_MAX, "m", IK),
    Metric(JACOBIAN_DEPARTURE_MAX, _JACOBIAN_UNIT, IK),
    Metric(TIME_PER_SOLVE, "s", TIMING),
)}

HARD_TARGET_ERROR = MetricFamily("hard_", "", "m", IK)
"""The position residual on one hard IK target (``hard_<target>``)."""
HARD_TARGET_SOLVED = MetricFamily("hard_", "_solved", DIMENSIONLESS, IK)
HARD_TARGET_UNREACHABLE = MetricFamily("hard_", "_unreachable", DIMENSIONLESS, IK)
HARD_TARGET_LIMIT_VIOLATION = MetricFamily("hard_", "_limit_violation", _ANGLE_OR_LENGTH, IK)
INVARIANCE_RATIO = MetricFamily("invariance_ratio_", "", DIMENSIONLESS, INVARIANCE)
INVARIANCE_STATUS_CHANGES = MetricFamily("invariance_status_changes_", "", DIMENSIONLESS, INVARIANCE)
FAMILIES = (HARD_TARGET_SOLVED, HARD_TARGET_UNREACHABLE, HARD_TARGET_LIMIT_VIOLATION, HARD_TARGET_ERROR,
            INVARIANCE_RATIO, INVARIANCE_STATUS_CHANGES)
"""Most specific first: ``hard_x_solved`` is a solved flag, not the residual of a target named ``x_solved``."""


def family_of(name: str) -> MetricFamily | None:
    """The family a metric not in :data:`CATALOGUE` belongs to, or None."""
    return next((f for f in FAMILIES if f.matches(name)), None)


def is_non_negative(name: str) -> bool:
    """Whether every value of the metric ``name`` is >= 0 (:attr:`Metric.non_negative`; a family's members are
    residuals, flags, counts and ratios: all are); False for a name the catalogue does not know."""
    if name in CATALOGUE:
        return CATALOGUE[name].non_negative
    return family_of(name) is not None


def unit_of(name: str) -> str:
    """The unit of any metric a run writes; raises KeyError for a name the catalogue does not know."""
    if name in CATALOGUE:
        return CATALOGUE[name].unit
    family = family_of(name)
    if family is None:
        raise KeyError(f"{name}: not a metric of the catalogue")
    return family.unit


def units(*names: str) -> dict[str, str]:
    """``{name: unit}`` of catalogued metrics, in the order given (raises KeyError for an unknown name)."""
    return {name: CATALOGUE[name].unit for name in names}


def is_timing(name: str) -> bool:
    """Whether a metric measures wall time: never compared between runs, never a numerics change."""
    return name in CATALOGUE and CATALOGUE[name].is_timing


def is_probe(name: str) -> bool:
    """Whether a metric probes an engine's floating-point behaviour (kind ``probe``): never held invariant under a
    change of frame or units."""
    return name in CATALOGUE and CATALOGUE[name].kind == PROBE


def is_cost(name: str) -> bool:
    """Whether a metric is a hardware-neutral cost: exact, from what the engine declares (its stage count), no
    measure of its numerics."""
    return name in CATALOGUE and CATALOGUE[name].kind == COST


def headline_metrics() -> tuple[str, ...]:
    """The metrics a report ranks by (a dynamics scene's position or orientation error, an IK solver's rate)."""
    return tuple(m.name for m in CATALOGUE.values() if m.headline)


def order_source(order: str) -> str:
    """The error an observed order is the slope of (``order_position`` -> ``position_error_max``)."""
    return CATALOGUE[order].source
