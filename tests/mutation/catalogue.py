"""The planted bugs: realistic mistakes in core's methods, each of which the CI gate must catch.

Each is one textual change to one file of core (:class:`~tests.mutation.mutation.Mutation`), applied to a copy
(:mod:`tests.mutation.copy_of_core`). They were written from the code, never from the gate's bounds: a bound
tuned to one of them would say nothing of the bugs someone else plants. ``suites`` lists every quick suite whose
scenes run the changed code (the contact methods fly with RK4 and integrate the penalty force with core's
schemes, so an integrator's bug also lives in the contact suite); ``witness`` is a built-in scene on which the
copy's results differ from core's.
"""

from __future__ import annotations

from tests.mutation.mutation import Mutation

DYNAMICS = ("default", "hard")
"""Free rigid bodies: the default suite's dynamics scenes and the hard suite's stability cases."""

FLIGHT = ("default", "hard", "contact")
"""Code the contact methods share with free flight (RK4 flights, penalty integrators, quaternion rates)."""

CONTACT = ("default", "contact")
"""Contact responses: five contact scenes are in the default suite, all of them in the contact suite."""

CONTACT_HARD = ("default", "hard", "contact")
"""Contact code the hard suite's impacts also run (hard-fast-impact, hard-penalty-stiff, hard-zeno)."""

KINEMATICS = ("default", "hard")
"""FK and Jacobians: the kinematics and IK scenes (the hard suite's IK scenes use them too)."""

IK = ("default", "hard")
"""The iterative IK solvers: the default suite's IK scenes and the hard suite's hard targets."""

ARTICULATED = ("default", "articulated")
"""Joint-space dynamics: the default suite's planar 2-link arm and 3-D oblique arm, and the articulated suite's 3-D
arms."""

ARTICULATED_3D = ("articulated",)
"""Joint-space dynamics that only the articulated suite's arms show (armature, which no URDF carries)."""

JOINT_MOTION = ("default", "hard", "articulated")
"""Joint-space time stepping: the default suite's pendulum, damped joint and oblique arm, the hard suite's stiff
damping and the articulated suite's chains and falling arms."""

FORCED = ("default", "articulated")
"""Loads that change with time: the default suite's forced bodies and driven joints, the articulated suite's driven
joints."""

MUTANTS: tuple[Mutation, ...] = (
    # --- Dynamics: integrators ------------------------------------------------------------------------------
    Mutation(
        "rk4_weights", "integrator weights", "dynamics/tableau.py",
        "b=(1 / 6, 1 / 3, 1 / 3, 1 / 6), c=(0.0, 0.5, 0.5, 1.0), order=4)",
        "b=(1 / 4, 1 / 4, 1 / 4, 1 / 4), c=(0.0, 0.5, 0.5, 1.0), order=4)",
        "RK4's four slopes averaged with equal weights 1/4 instead of 1/6, 1/3, 1/3, 1/6 (second order)",
        FLIGHT, "wind"),
    Mutation(
        "rk4_last_stage", "integrator stages", "dynamics/tableau.py",
        "(0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0)),",
        "(0.0, 0.5, 0.0, 0.0), (0.0, 0.0, 0.5, 0.0)),",
        "RK4's fourth stage taken half a step along k3 instead of a whole step (first order)",
        FLIGHT, "wind"),
    Mutation(
        "midpoint_full_step", "integrator stages", "dynamics/tableau.py",
        "MIDPOINT = Tableau(a=((0.0, 0.0), (0.5, 0.0)),",
        "MIDPOINT = Tableau(a=((0.0, 0.0), (1.0, 0.0)),",
        "the midpoint rule's second stage evaluated a whole step ahead instead of half a step (first order)",
        FLIGHT, "wind"),
    Mutation(
        "semi_implicit_old_momentum", "integrator stages", "dynamics/quaternion_integrators.py",
        "new[X] = s[X] + dt * new[P] * bodies.inverse_mass",
        "new[X] = s[X] + dt * s[P] * bodies.inverse_mass",
        "semi-implicit Euler moves the position with the momentum from before the kick (explicit Euler, still "
        "first order)",
        FLIGHT, "falling-linear-drag"),
    Mutation(
        "taylor_no_half", "integrator weights", "dynamics/point_mass.py",
        "return x + v * dt + a * dt * dt / 2, v + a * dt",
        "return x + v * dt + a * dt * dt, v + a * dt",
        "the lecture's Taylor rule with a dt^2 term missing its 1/2",
        DYNAMICS, "lecture-projectile"),
    Mutation(
        "samples_lag_one_step", "time bookkeeping", "inhouse.py",
        "if i:\n                    state = self._packed_step((i - 1) * dt, state, dt)\n                record[j] = state",
        "record[j] = state\n                if i:\n                    state = self._packed_step((i - 1) * dt, state, dt)",
        "each sample records the state from before its step: the trajectory lags one step behind its times",
        DYNAMICS, "lecture-projectile"),
    # --- Dynamics: rotation, inertia, forces -----------------------------------------------------------------
    Mutation(
        "gyroscopic_sign", "gyroscopic term", "dynamics/quaternion_integrators.py",
        "bodies.apply_inverse_inertia_body(_tmatvec(rotation, torque) - gyro)",
        "bodies.apply_inverse_inertia_body(_tmatvec(rotation, torque) + gyro)",
        "the engines' Euler step adds the gyroscopic term omega x I omega instead of subtracting it",
        DYNAMICS, "tumbling-box-stable"),
    Mutation(
        "inertia_wrong_frame", "inertia frame", "dynamics/quaternion_integrators.py",
        "return _matvec(rotation, self.apply_inverse_inertia_body(_tmatvec(rotation, angular_momentum)))",
        "return _tmatvec(rotation, self.apply_inverse_inertia_body(_matvec(rotation, angular_momentum)))",
        "omega = R^T I_body^-1 R L: the inverse inertia rotated the wrong way round (body and world swapped)",
        FLIGHT, "tumbling-box-stable"),
    Mutation(
        "quaternion_rate_body_frame", "frames and conventions", "dynamics/quaternion_integrators.py",
        "    out[0], out[1] = -ox * x - oy * y - oz * z, ox * w + oy * z - oz * y\n"
        "    out[2], out[3] = oy * w - ox * z + oz * x, oz * w + ox * y - oy * x\n",
        "    out[0], out[1] = -ox * x - oy * y - oz * z, ox * w - oy * z + oz * y\n"
        "    out[2], out[3] = oy * w + ox * z - oz * x, oz * w - ox * y + oy * x\n",
        "dq/dt = 1/2 q (0, omega): the world angular velocity multiplied on the body side of the quaternion",
        FLIGHT, "tumbling-box-stable"),
    Mutation(
        "torque_cross_order", "torque sign", "dynamics/forces.py",
        "np.add.at(torque, applied_body, np.cross(lever, applied_force))",
        "np.add.at(torque, applied_body, np.cross(applied_force, lever))",
        "the torque of a force at a body point written f x r instead of r x f",
        ("default",), "point-force-torque"),
    Mutation(
        "force_point_not_rotated", "force application point", "dynamics/forces.py",
        'lever = np.einsum("aij,aj->ai", rotation[applied_body], applied_point)',
        "lever = applied_point",
        "a force's body-fixed point used as a world offset: the lever does not turn with the body",
        ("default",), "point-force-torque"),
    Mutation(
        "drag_applied_twice", "damping", "dynamics/forces.py",
        "force -= b[:, None] * relative",
        "force -= b[:, None] * (relative + v)",
        "linear drag applied twice: against the velocity relative to the air, and again against the ground "
        "velocity",
        DYNAMICS, "wind"),
    # --- Contact ---------------------------------------------------------------------------------------------
    Mutation(
        "restitution_squared", "contact response", "contact/bodies.py",
        "j_n = np.where(speed_n < 0.0, -(1.0 + restitution) * speed_n, 0.0)",
        "j_n = np.where(speed_n < 0.0, -(1.0 + restitution**2) * speed_n, 0.0)",
        "restitution applied twice: a body rebounds at k^2 times its approach speed",
        CONTACT_HARD, "ball-bounce-k05"),
    Mutation(
        "friction_static_kinetic_swapped", "friction coefficient", "contact/backup.py",
        "for table in (model.friction_static, model.friction_kinetic))",
        "for table in (model.friction_kinetic, model.friction_static))",
        "a body resting on a plane gets the kinetic coefficient where the static one belongs and vice versa",
        CONTACT, "block-slide"),
    Mutation(
        "angular_impulse_sign", "contact torque", "contact/bodies.py",
        "return p + impulse, l + cross(lever, impulse)",
        "return p + impulse, l + cross(impulse, lever)",
        "the angular impulse of a contact written j x r instead of r x j",
        CONTACT, "box-edge-drop"),
    Mutation(
        "penalty_damping_sign", "contact coefficient sign", "contact/particle.py",
        "push = -stiffness * depth - damping * (velocity_world @ plane.normal_world)",
        "push = -stiffness * depth + damping * (velocity_world @ plane.normal_world)",
        "the penalty damper pushes with the approach speed instead of against it: energy enters at every contact",
        CONTACT_HARD, "lecture-bouncing-particle"),
    Mutation(
        "backup_time_full_gravity", "back-up time", "contact/roots.py",
        "hit, s = entry_time(e0, u, a / 2.0, horizon[:, None])",
        "hit, s = entry_time(e0, u, a, horizon[:, None])",
        "the exact entry time solved with a s^2 where a s^2 / 2 belongs: impacts timed early, above the plane",
        CONTACT_HARD, "ball-bounce-k05"),
    Mutation(
        "push_out_sign", "contact response", "contact/act_after.py",
        "x = x - np.minimum(depth, 0.0)[:, None] * normal",
        "x = x + np.minimum(depth, 0.0)[:, None] * normal",
        "act_after's push-out moves a penetrating body further into the plane instead of out of it",
        CONTACT_HARD, "lecture-bouncing-particle"),
    # --- Kinematics ------------------------------------------------------------------------------------------
    Mutation(
        "joint_axis_sign", "joint axis sign", "kinematics.py",
        "r = r + np.sin(angle) * _times_constant(r, joint.k)",
        "r = r - np.sin(angle) * _times_constant(r, joint.k)",
        "FK turns each revolute joint about minus its axis (Rodrigues' sine term with the wrong sign)",
        KINEMATICS, "lecture-planar-arm"),
    Mutation(
        "jacobian_next_frame", "Jacobian", "kinematics.py",
        "lever = frames.positions[-1] - frames.positions[:-1]",
        "lever = frames.positions[-1] - frames.positions[1:]",
        "Jacobian column i measured from the next joint's origin P_(i+1) (the child frame) instead of P_i",
        KINEMATICS, "lecture-planar-arm"),
    Mutation(
        "origin_offset_after_rotation", "forward kinematics", "kinematics.py",
        "        p = p + _apply_constant(r, joint.origin_xyz)\n"
        "        if joint.origin_rotation is not None:\n"
        "            r = _times_constant(r, joint.origin_rotation)\n",
        "        if joint.origin_rotation is not None:\n"
        "            r = _times_constant(r, joint.origin_rotation)\n"
        "        p = p + _apply_constant(r, joint.origin_xyz)\n",
        "a joint's origin offset expressed in its already rotated frame (the URDF origin's rpy applied before "
        "its xyz)",
        KINEMATICS, "ur5-kinematics"),
    # --- Inverse kinematics ----------------------------------------------------------------------------------
    Mutation(
        "ik_orientation_error_sign", "IK error sign", "ik/jacobian_solvers.py",
        "rot_err = so3_log(target_rotation @ np.swapaxes(end_rotation, 1, 2))",
        "rot_err = so3_log(end_rotation @ np.swapaxes(target_rotation, 1, 2))",
        "the orientation error taken from the target to the end effector: the rotation rows push away from it",
        IK, "ur5-ik"),
    Mutation(
        "ik_success_tolerance_1000x", "success criterion", "ik/jacobian_solvers.py",
        "solved = (pos_res <= options.position_tolerance) & (rot_res <= options.orientation_tolerance)",
        "solved = (pos_res <= 1e3 * options.position_tolerance) & (rot_res <= 1e3 * options.orientation_tolerance)",
        "a target counts as solved within 1000 times the tolerances (a millimetre instead of a micrometre)",
        IK, "iiwa-ik"),
    Mutation(
        "ik_step_scaled_up", "IK step", "ik/jacobian_solvers.py",
        "scale = np.minimum(1.0, options.max_step / np.where(largest > 0, largest, 1.0))",
        "scale = np.maximum(1.0, options.max_step / np.where(largest > 0, largest, 1.0))",
        "min and max confused in the step limit: every update is stretched to max_step, none is capped",
        IK, "iiwa-ik"),
    Mutation(
        "nullspace_sign", "null-space term", "ik/nullspace.py",
        "return row_space - z",
        "return z - row_space",
        "the null-space term (I - J+ J) grad H instead of (J+ J - I) grad H: it climbs the rest-pose penalty",
        IK, "iiwa-ik"),
    Mutation(
        "dls_constant_damping", "IK damping", "ik/steps.py",
        "lam2 = np.where(smin < threshold, damping_max**2 * (1 - (smin / threshold) ** 2), 0.0)",
        "lam2 = np.full(len(gram), 0.5**2)",
        "damped least squares with a constant lambda = 0.5 everywhere, not only near singularities: over-damped",
        IK, "iiwa-ik"),
    Mutation(
        "ik_limits_not_clamped", "joint limits", "ik/jacobian_solvers.py",
        "stepped = np.clip(wrap_into_limits(qa[step] + dq[step], revolute, lower, upper), lower, upper)",
        "stepped = wrap_into_limits(qa[step] + dq[step], revolute, lower, upper)",
        "each iterate is wrapped into the limits by 2 pi but never clipped: joints leave their limits",
        IK, "iiwa-ik"),
    Mutation(
        "nullspace_projector_transpose", "null-space term", "ik/nullspace.py",
        'row_space = np.einsum("bkn,bk,bk->bn", vt, kept, np.einsum("bkn,bn->bk", vt, z))',
        'row_space = np.einsum("bmn,bm->bn", jacobian, np.einsum("bmn,bn->bm", jacobian, z))',
        "the null-space projector built with J^T J for J+ J (the same only when J's rows are orthonormal): the "
        "secondary term moves the end effector and no longer descends the rest-pose penalty",
        IK, "iiwa-ik"),
    # --- Joint-space dynamics -------------------------------------------------------------------------------
    Mutation(
        "jacobian_sum_no_gyroscopic", "joint-space bias forces", "articulated/jacobian_sum.py",
        'moment = (inertia @ (k["djw"] @ qdot[:, None, :, None]))[..., 0] + np.cross(w, spin)',
        'moment = (inertia @ (k["djw"] @ qdot[:, None, :, None]))[..., 0]',
        "the lecture's bias forces without the gyroscopic moment w x I w of each link (zero on a planar arm)",
        ARTICULATED, "oblique-arm-dynamics"),
    Mutation(
        "jacobian_sum_lever_rate_sign", "joint-space bias forces", "articulated/jacobian_sum.py",
        "lever_rate = v_com[..., 0][:, :, None, :] - v_origin[:, None, :, :]",
        "lever_rate = v_origin[:, None, :, :] - v_com[..., 0][:, :, None, :]",
        "Jdot's lever-arm rate taken with the wrong sign (d(p_i - P_j)/dt as v_j - v_i): Coriolis forces wrong",
        ARTICULATED, "lecture-2link-dynamics"),
    Mutation(
        "rnea_no_velocity_product", "joint-space bias forces", "articulated/recursive.py",
        "forces.append(inertia @ acceleration + cross_force(v, inertia @ v))",
        "forces.append(inertia @ acceleration)",
        "RNEA's body force without v x* I v (the velocity-product term): centrifugal and gyroscopic forces lost",
        ARTICULATED, "lecture-2link-dynamics"),
    Mutation(
        "rnea_no_armature", "joint armature", "articulated/recursive.py",
        "tau[i] = forces[i][arrays.subspace[i]] + arrays.armature[i] * qddot[i]",
        "tau[i] = forces[i][arrays.subspace[i]]",
        "RNEA without the joint's rotor inertia (armature): tau misses a_i qddot_i (no URDF carries armature)",
        ARTICULATED_3D, "armature-arm-dynamics"),
    Mutation(
        "rnea_tip_velocity_product", "joint-space bias forces", "articulated/recursive.py",
        "forces.append(inertia @ acceleration + cross_force(v, inertia @ v))",
        "forces.append(inertia @ acceleration + (cross_force(v, inertia @ v) if i < arrays.n - 1 else 0.0))",
        "RNEA's velocity-product term v x* I v skipped for the last body (an off-by-one bound): only the light last "
        "link's Coriolis and centrifugal force is lost, on a chain whose bias forces are small (issue #38)",
        ARTICULATED, "scara-slow-dynamics"),
    Mutation(
        "link_inertia_transposed_alignment", "inertia frame", "articulated/chain_arrays.py",
        "inertia_com.append(align.T @ np.asarray(link.inertia_com) @ align)",
        "inertia_com.append(align @ np.asarray(link.inertia_com) @ align.T)",
        "each link's inertia turned into its joint frame by the transposed rotation (A I A^T for A^T I A): the "
        "same on an axis along z, wrong on any other with products of inertia",
        ARTICULATED, "oblique-arm-dynamics"),
    # --- Joint-space time stepping --------------------------------------------------------------------------
    Mutation(
        "joint_rk4_stage_typo", "integrator weights", "articulated/stepping.py",
        "qdot + scale * _weighted(tableau, accelerations)",
        "qdot + scale * _weighted(tableau, accelerations[:2] + accelerations[1:2] + accelerations[3:])",
        "the joints' RK4 velocity update sums k2 twice instead of k2 and k3 (a copy-and-paste slip: third order)",
        JOINT_MOTION, "pendulum-large-amplitude"),
    Mutation(
        "joint_semi_implicit_old_velocity", "integrator stages", "articulated/stepping.py",
        "                qdot = qdot + dt * accelerations(q, qdot, t, t)\n"
        "                return project(q + dt * rate(q, qdot)), qdot\n            return semi_implicit",
        "                new = qdot + dt * accelerations(q, qdot, t, t)\n"
        "                return project(q + dt * rate(q, qdot)), new\n            return semi_implicit",
        "semi-implicit Euler moving the joints with the old velocity: explicit Euler under the semi-implicit name",
        JOINT_MOTION, "pendulum-large-amplitude"),
    Mutation(
        "joint_implicit_damping_without_dt", "joint damping", "articulated/stepping.py",
        "replace(j, armature=j.armature + dt * j.damping)",
        "replace(j, armature=j.armature + j.damping)",
        "implicit damping with M + D instead of M + dt D (the step forgotten in the linearisation)",
        JOINT_MOTION, "damped-joint"),
    Mutation(
        "joint_torque_dropped", "applied forces", "articulated/stepping.py",
        "constant, timed = scene.torque[:, None], scene.timed_torque",
        "constant, timed = 0.0 * scene.torque[:, None], scene.timed_torque",
        "the scene's applied joint torques never reach the steps",
        JOINT_MOTION, "damped-joint"),
    # --- Loads that change with time (issue #42) ----------------------------------------------------------------
    Mutation(
        "stage_time_at_step_start", "time-varying loads", "dynamics/quaternion_integrators.py",
        "ks.append(_derivative(bodies, wrench, t + c[i] * dt, stage, t))",
        "ks.append(_derivative(bodies, wrench, t, stage, t))",
        "every Runge-Kutta stage evaluates the loads at the step's start time instead of its own t + c dt (first "
        "order under a time-varying load)",
        ("default",), "forced-particle"),
    Mutation(
        "joint_stage_time_at_step_start", "time-varying loads", "articulated/stepping.py",
        "accelerations.append(qddot(q_i, qdot_i, t + c * dt, t))",
        "accelerations.append(qddot(q_i, qdot_i, t, t))",
        "a chain's Runge-Kutta stages evaluate the timed joint torque at the step's start time",
        FORCED, "driven-damped-joint"),
    Mutation(
        "hold_one_period_late", "time-varying loads", "dynamics/time_loads.py",
        "index = np.where(times > np.asarray(step_start, dtype=float), left, right).astype(int)",
        "index = np.where(times > np.asarray(step_start, dtype=float), left, right).astype(int) - 1",
        "a zero-order hold sampled one control period late (the sample before the one in force)",
        FORCED, "torque-pulse"),
    Mutation(
        "sinusoid_phase_in_degrees", "time-varying loads", "dynamics/time_loads.py",
        "np.sin(2 * np.pi * sinusoid.frequency_hz * times + sinusoid.phase_rad)",
        "np.sin(2 * np.pi * sinusoid.frequency_hz * times + np.deg2rad(sinusoid.phase_rad))",
        "a sinusoid's phase read as degrees (the scene gives radians)",
        FORCED, "forced-particle"),
)
"""The catalogue (issue #23 asks for at least a dozen, of the kinds listed there)."""

JUDGE_FILES = ("kinematics.py", "rotations.py")
"""Files whose mutants change the FK that judges other engines (every engine's FK cross-evaluates every IK
solution): such a mutant runs alone beside core, so a violation naming core is its doing."""


def judges_others(mutation: Mutation) -> bool:
    """True when the mutant's bug reaches the rows of other engines (:data:`JUDGE_FILES`)."""
    return mutation.file in JUDGE_FILES


def by_id(mutant_id: str) -> Mutation:
    """The mutant of that id; KeyError naming the known ones."""
    for mutation in MUTANTS:
        if mutation.id == mutant_id:
            return mutation
    raise KeyError(f"no mutant {mutant_id!r} (known: {', '.join(m.id for m in MUTANTS)})")
