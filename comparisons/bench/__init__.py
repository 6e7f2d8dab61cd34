"""``simparity bench``: speed with its accuracy, core against the engines, measured in one run.

Six workloads, one module each, every time the median of repeats after a warm-up call
(:func:`comparisons.bench.rows.median_time`) on one BLAS thread (:mod:`comparisons.bench.blas`), with the machine's
load average around it and its CPU and wall time (:class:`comparisons.bench.rows.Meter`), every ratio core / engine
computed from the same run:

1. rigid-body stepping of B identical boxes (torque-free tumbling; falling with drag), time per body-step of each
   engine's ``run`` next to the error each reaches at that dt against the tight reference
   (:mod:`comparisons.bench.stepping`);
2. forward kinematics + end-effector Jacobian of the iiwa and the UR5, time per configuration, with the largest
   difference to Pinocchio (:mod:`comparisons.bench.kinematics`);
3. IK on the ``bench`` suite's arms (TRAC-IK protocol), solve rate and time per solve, failures inside the time,
   limit violations (:mod:`comparisons.bench.ik`);
4. joint-space dynamics (M + h, RNEA, ABA) of the ``articulated`` suite's real arms, time per state with the largest
   relative difference to Pinocchio (:mod:`comparisons.bench.joint_dynamics`);
5. joint motion of the falling arms, time per copy-step of each engine's RK4 at equal accuracy (the error against
   DOP853 and the difference to Pinocchio's RK4) (:mod:`comparisons.bench.joint_motion`);
6. core at B = 1 and B = 3 against MuJoCo's integrator of the same scheme, time per step and the ratio
   (:mod:`comparisons.bench.small_batch`).

Beside them, the peak memory of ``simparity run`` against the steps (:mod:`comparisons.bench.memory`) and its wall
time and client memory against a sweep's variants (:mod:`comparisons.bench.sweep`), the wall time of the default
suite and of the quick CI gate as a user runs them (:mod:`comparisons.bench.suites`, a full bench only), and a
profile of core (:mod:`comparisons.bench.profiling`). :func:`comparisons.bench.run.run_bench` measures them all.

Results go to ``benchmarks.csv`` (one tidy row per measurement) and ``BENCHMARKS.md``
(:mod:`comparisons.bench.report`), with a verdict on each of the issue's targets that says what it compared
(:mod:`comparisons.bench.targets`). The targets are set for the full sizes (:mod:`comparisons.bench.verdict`); measured
at other sizes (``--quick``), a target is "not comparable", never met or missed. IK speed is compared only among
solvers that solve at least :data:`comparisons.bench.targets.COMPARABLE_SOLVE_RATE` times as often as core at the
harness's tolerance. An absolute target (a rate, not a ratio to a row of the same run) measured on a loaded machine
is "not judged", saying the load (:func:`comparisons.bench.verdict.machine_loaded`).
"""
