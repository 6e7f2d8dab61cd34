"""The ``simparity`` command: list, engines, run, check, history, export, show, report, bench.

User mistakes (bad scene or tolerances files, unknown names, missing runs, a folder that already
holds a run) print one line ``simparity: error: ...`` and exit with code 2; tracebacks are kept
for real bugs. ``run`` exits 1 when some engine failed (raised), and with ``--check`` when a
metric is outside its bound; ``check`` exits 0 when every checked metric is inside its bound and
nothing moved since the baseline, else 1. Results computed before an error are kept either way.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import time
from pathlib import Path

from simparity.comparisons import library
from simparity.comparisons.check import (
    BASELINE_RELATIVE,
    CheckResult,
    check_table,
    compare_with_baseline,
    explain,
    explain_lines,
)
from simparity.comparisons.check_output import junit_xml, summary_markdown
from simparity.comparisons.describe import describe
from simparity.comparisons.console import EXIT_INTERRUPTED
from simparity.comparisons.engines import (
    DEFAULT_ENGINES,
    ENGINE_NAMES,
    allowed_engines,
    check_engine_names,
    describe_engines,
    make_engine,
    use_engines,
)
from simparity.comparisons.history import history_path, latest_before, metric_history, record_run, run_table
from simparity.comparisons.invariance_run import invariance_rows
from simparity.comparisons.execution import count_cases, default_jobs, run_scenes
from simparity.comparisons.isolation import DEFAULT_CASE_SECONDS, GIB, CaseLimits, IsolatedPool
from simparity.comparisons.journal import CASES_FOLDER, Journal, read_request, run_lock, write_request
from simparity.comparisons.placeholder_engines import BrokenEngine, UnavailableEngine
from simparity.comparisons.profiles import (QUICK_CONTACT_STEPS, QUICK_LADDER, QUICK_MAX_STEPS, QUICK_TARGETS,
                                             apply_profile)
from simparity.comparisons.progress import ProgressBar
from simparity.comparisons.runner import DEFAULT_REPEATS
from simparity.comparisons.scene_limits import DEFAULT_LIMITS, Limits
from simparity.comparisons.store import DEFAULT_OUT_ROOT, RunWriter, default_out_dir
from simparity.comparisons.timing import resource_line
from simparity.comparisons.tolerances import DEFAULT_TOLERANCES, load_tolerances
from simparity.comparisons.transforms import TRANSFORM_NAMES, fixed_transforms
from simparity.core.errors import HistoryError, SimparityError, UsageError, one_line
from simparity.core.ranges import RANGES
from simparity.core.results import FAILED, RESULTS_FILE, RUN_INFO_FILE, case_counts
from simparity.core.scene import SUITES, DynamicsScene, IKScene, KinematicsScene
from simparity.reports.content import ToleranceVerdict
from simparity.reports.render import write_report
from simparity.reports.store import read_run

EXIT_OK, EXIT_FAILED_CASES, EXIT_USAGE = 0, 1, 2
EXPORTABLE = ("mujoco", "pybullet", "pinocchio")
EXECUTORS = ("local", "dask")
MAX_JOBS = 256
"""Worker processes at most: each is a Python process of ~250 MiB with the engines loaded."""
MEMORY_HELP = ("80%% of the memory of the machine a case runs on, shared between its workers (on Dask: a worker's own "
               "memory limit shared between its threads, if it has one), at least 1 GiB")
RESUMED_OPTIONS = ("scenes", "suite", "engines", "out", "force", "quick", "repeats", "max_steps", "max_samples",
                   "max_joints", "transform")
"""What a resumed run takes from the run it resumes (``resume.json``), never from the command line."""
MESSAGE_LIMIT = 1000
"""Characters of an error message printed: one line, whatever the input echoed into it."""


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are one line and exit 2 like every other bad input (no usage block)."""

    def error(self, message: str):
        raise UsageError(f"{self.prog}: {message} (allowed: see '{self.prog} --help')")


def _engine_list(text: str) -> tuple[str, ...]:
    return tuple(n.strip() for n in text.split(",") if n.strip())


def _add_check_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--tolerances", type=Path, default=None, metavar="FILE",
                        help=f"bounds to hold the run to (default: the shipped {DEFAULT_TOLERANCES.name})")
    parser.add_argument("--baseline", default=None, metavar="DIR|latest",
                        help="also flag every metric that moved since this run ('latest': the run before, from the "
                        "history)")
    parser.add_argument("--baseline-rel", type=float, default=BASELINE_RELATIVE, metavar="X",
                        help=f"relative change that counts as a move (default: {BASELINE_RELATIVE:g}); timing "
                        "changes are listed apart and never fail the check")
    parser.add_argument("--junit", type=Path, default=None, metavar="FILE",
                        help="write JUnit XML: one test case per scene x engine x integrator x dt")
    parser.add_argument("--summary", type=Path, default=None, metavar="FILE",
                        help="write a Markdown summary (e.g. $GITHUB_STEP_SUMMARY)")


def _add_history_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--history", default=None, metavar="PATH",
                        help=f"run history database (default: $SIMPARITY_HISTORY or {DEFAULT_OUT_ROOT}/history.sqlite)")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="simparity",
        description="Run textbook IK and rigid-body methods beside MuJoCo, PyBullet and Pinocchio "
        "on identical scenes; report error, drift and speed, and check them against tolerances.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    listing = sub.add_parser("list", help="list the built-in scenes",
                             description="List the built-in scenes, one per line, with the suites they are in.")
    listing.add_argument("--suite", default=None, choices=SUITES, help="only the scenes of this suite")

    sub.add_parser(
        "engines", help="list the engines: built-in and installed plugins, with what each supports",
        description="List every engine, one per line: its name (what --engines takes), where it comes from (built-in, "
        "or the installed package and entry point of a plugin in the group 'simparity.engines'), its version, its "
        "dynamics integrators, IK solvers and whether it does kinematics; an engine that cannot run says why, a "
        "plugin shadowed by a built-in of the same name says so. Code that is not packaged runs as "
        "--engines module:Class. Writing one: docs/plugins.md.")

    run = sub.add_parser(
        "run", help="run scenes on engines and write results.csv and report.md",
        description="Run scenes on engines; write results.csv, run.json and report.md into a new output folder, "
        "and record the run in the history database.",
    )
    run.add_argument("scenes", nargs="*", metavar="SCENE|FILE",
                     help="built-in scene names or scene files (default: the scenes of --suite)")
    run.add_argument("--suite", default=None, choices=SUITES,
                     help="run a built-in suite: default (what 'simparity run' runs), contact (every scene with "
                     "planes), hard (the numerical-stability cases, each with the verdict it must earn) or bench (the "
                     "arms 'simparity bench' times, 10,000 IK targets each)")
    run.add_argument("--engines", type=_engine_list, default=DEFAULT_ENGINES, metavar="A,B,...",
                     help=f"comma-separated engines to run (default: {','.join(DEFAULT_ENGINES)}; "
                     f"known: {allowed_engines()}; 'simparity engines' lists them)")
    run.add_argument("--out", type=Path, default=None, metavar="DIR",
                     help=f"output folder; must not hold a run yet (default: a new {DEFAULT_OUT_ROOT}/<UTC date-time>/)")
    run.add_argument("--force", action="store_true", help="overwrite the run already in --out")
    run.add_argument("--repeats", type=int, default=None, metavar="N",
                     help=f"timed repeats per case, the best is kept (default: {DEFAULT_REPEATS}; --quick: 0, one "
                     "cold timing)")
    run.add_argument("--quick", action="store_true",
                     help=f"the CI profile: every scene shortened (<= {QUICK_MAX_STEPS} steps; a contact scene its "
                     f"{QUICK_LADDER} coarsest time steps, <= {QUICK_CONTACT_STEPS} steps; {QUICK_TARGETS} IK targets), "
                     "a few minutes on 2 cores")
    run.add_argument("--jobs", type=int, default=None, metavar="N",
                     help=f"worker processes (with --executor dask and no --scheduler: the local cluster's workers; "
                     f"default: one per CPU, here {default_jobs()})")
    run.add_argument("--executor", choices=EXECUTORS, default="local",
                     help="where cases run: local worker processes (default), or a Dask distributed cluster (a "
                     "LocalCluster on this machine unless --scheduler is given; needs pip install 'simparity[dask]')")
    run.add_argument("--scheduler", default=None, metavar="ADDRESS",
                     help="with --executor dask: the scheduler of a running cluster, e.g. tcp://10.0.0.5:8786")
    run.add_argument("--case-timeout", type=float, default=DEFAULT_CASE_SECONDS, metavar="SECONDS",
                     help="a case still running after this long is killed and becomes a failed row (default: "
                     f"{DEFAULT_CASE_SECONDS:g})")
    run.add_argument("--case-memory", type=float, default=None, metavar="GIB",
                     help="a case whose worker's resident memory passes this is killed and becomes a failed row "
                     f"(default: {MEMORY_HELP})")
    run.add_argument("--resume", type=Path, default=None, metavar="DIR",
                     help="finish the interrupted run in DIR: its finished cases are kept, the rest run; give no "
                     "scenes, --suite, --engines, --out, --quick, --repeats or --max-* (the run's own are used)")
    run.add_argument("--max-steps", type=int, default=DEFAULT_LIMITS.max_steps, metavar="N",
                     help="refuse a case of more than N body-steps per time step, or IK targets x max_iterations "
                     f"(default: {DEFAULT_LIMITS.max_steps:,})")
    run.add_argument("--max-samples", type=int, default=DEFAULT_LIMITS.max_samples, metavar="N",
                     help=f"refuse more than N configurations or IK targets (default: {DEFAULT_LIMITS.max_samples:,})")
    run.add_argument("--max-joints", type=int, default=DEFAULT_LIMITS.max_joints, metavar="N",
                     help=f"refuse a chain or URDF file of more than N movable joints (default: "
                     f"{DEFAULT_LIMITS.max_joints:,})")
    run.add_argument("--transform", type=_engine_list, default=(), metavar="NAME[,NAME]",
                     help="also run every scene transformed (" + ", ".join(TRANSFORM_NAMES) + ": 2 km from the "
                     "origin, turned with its gravity, its bodies reordered, its units rescaled, time in ms) and add "
                     "each engine's invariance rows (invariance_ratio_NAME <= 1, invariance_status_changes_NAME = 0; "
                     "docs/invariance.md); costs about two more runs per transform")
    run.add_argument("--check", action="store_true",
                     help="check the run against tolerances when it is done (exit 1 on a violation)")
    _add_check_options(run)
    _add_history_option(run)

    check = sub.add_parser(
        "check", help="hold a stored run to tolerances (exit 1 on a violation)",
        description="Hold every metric of a stored run to its bound; print each violation on one line. Exit 0 "
        "when all are inside, 1 when any is not (or, with --baseline, when numerics moved), 2 on bad input.",
    )
    check.add_argument("run_dir", nargs="?", type=Path, default=None, metavar="RUN_DIR",
                       help="a folder written by 'simparity run' (default: the latest run in the history)")
    check.add_argument("--explain", default=None, metavar="ENGINE",
                       help="print, per scene, every bound that holds ENGINE's rows (which rows, to what, and why) "
                       "instead of checking; your engine is held to the bounds of its schemes' kinds")
    _add_check_options(check)
    _add_history_option(check)

    history = sub.add_parser("history", help="how metrics moved across recorded runs",
                             description="Show one metric (or all) across the runs recorded in the history database.")
    history.add_argument("scene", nargs="?", default=None, metavar="SCENE")
    history.add_argument("--engine", default=None)
    history.add_argument("--metric", default=None)
    _add_history_option(history)

    export = sub.add_parser(
        "export", help="print the model an adapter builds for a scene",
        description="Print the model (MJCF, URDF or Pinocchio's model) an engine is given for a scene.",
    )
    export.add_argument("scene", metavar="SCENE|FILE")
    export.add_argument("--engine", required=True, choices=EXPORTABLE)
    export.add_argument("--integrator", default=None, help="dynamics only (default: the engine's first)")
    export.add_argument("--dt", type=float, default=None, help="dynamics only, [s] (default: the scene's first)")

    show = sub.add_parser(
        "show", help="print a scene as the loader understood it",
        description="Print a scene in SI units as loaded: bodies (mass, COM and inertia tensor, computed for a body "
        "built from point masses), forces, planes (normalised), shapes and every body-plane material.")
    show.add_argument("scene", metavar="SCENE|FILE")

    bench = sub.add_parser(
        "bench", help="measure speed with accuracy, core against the engines; write BENCHMARKS.md",
        description="Time rigid-body stepping (B = 1, 100, 10,000 bodies), FK + Jacobian and IK (the bench suite's "
        "arms, 10,000 targets each) for core and every engine in one run, each time with the error it reaches; "
        "write BENCHMARKS.md and benchmarks.csv with the ratios and the targets met or missed. About 5 minutes "
        "(--quick: about 1).")
    bench.add_argument("--out", type=Path, default=Path("."), metavar="DIR",
                       help="folder for BENCHMARKS.md and benchmarks.csv (default: the current folder)")
    bench.add_argument("--quick", action="store_true", help="B = 1 and 100 only, 300 IK targets per arm")

    report = sub.add_parser(
        "report", help="re-render report.md, report.html and figures/ of a stored run",
        description="Re-render report.md, report.html and the figures (SVG, PNG) from a stored run's results.csv, "
        "series.csv.gz and run.json; runs no engine. Flagged findings hold the run to --tolerances.")
    report.add_argument("run_dir", type=Path, metavar="DIR")
    report.add_argument("--tolerances", type=Path, default=None, metavar="FILE",
                        help=f"bounds for the flagged findings (default: the shipped {DEFAULT_TOLERANCES.name})")
    return parser


def cmd_list(args, out) -> int:
    scenes = library.suite(args.suite) if args.suite else library.load(list(library.builtin_paths().values()))
    for scene in scenes:
        print(f"{scene.name:<28} {scene.kind:<11} reference={scene.reference:<10} {','.join(scene.suites):<14} "
              f"{scene.description}", file=out)
    return EXIT_OK


def cmd_engines(args, out) -> int:
    from simparity.comparisons.engine_listing import engine_lines  # builds every engine: only when asked

    for line in engine_lines():
        print(line, file=out)
    return EXIT_OK


def _out_dir(args) -> Path:
    """The run's folder: --out (refused when it holds a run, unless --force), else a new one."""
    if args.out is None:
        return default_out_dir()
    try:
        return _checked_out_dir(args.out, args.force)
    except (OSError, ValueError) as err:  # a name the OS rejects: too long, a NUL byte
        raise SimparityError(f"--out {one_line(args.out)}: {getattr(err, 'strerror', None) or err} (allowed: a "
                             "folder path the system accepts)") from None


def _checked_out_dir(out_dir: Path, force: bool) -> Path:
    if out_dir.exists() and not out_dir.is_dir():
        raise SimparityError(f"--out {one_line(out_dir)}: exists and is not a folder (allowed: a new or empty folder)")
    held = [name for name in (RESULTS_FILE, RUN_INFO_FILE) if (out_dir / name).exists()]
    if held and not force:
        raise SimparityError(f"--out {one_line(out_dir)}: already holds a run ({', '.join(held)}); nothing was "
                             "overwritten (allowed: a new folder, no --out for a new timestamped one, or --force)")
    return out_dir


def _resumed(args) -> None:
    """Fill ``args`` with what the run in ``--resume DIR`` was asked to do; refuse options that would change it."""
    defaults = build_parser().parse_args(["run"])
    given = [name for name in RESUMED_OPTIONS if getattr(args, name) != getattr(defaults, name)]
    if given:
        flags = ", ".join("SCENE" if name == "scenes" else "--" + name.replace("_", "-") for name in given)
        raise SimparityError(f"--resume {one_line(args.resume)} with {flags}: a resumed run does what it was asked to "
                             "(allowed with --resume: --jobs, --executor, --scheduler, --case-timeout, --case-memory, "
                             "--check and its options, --history)")
    request = read_request(args.resume)
    if not (args.resume / CASES_FOLDER).is_dir():
        raise SimparityError(f"--resume {one_line(args.resume)}: that run finished (every case is in its "
                             f"{RESULTS_FILE}); nothing to resume (allowed: the folder of a run that did not finish; "
                             "'simparity report DIR' re-renders a finished one)")
    try:
        for name in RESUMED_OPTIONS:
            if name == "transform":  # runs requested before --transform existed had none
                args.transform = tuple(request.get(name, ()))
            elif name not in ("out", "force"):
                setattr(args, name, request[name] if name != "engines" else tuple(request[name]))
    except (KeyError, TypeError) as err:
        raise SimparityError(f"--resume {one_line(args.resume)}: its request lacks {one_line(err)} (allowed: the "
                             "file a run wrote)") from None
    args.out, args.force = args.resume, True


def _request(args, names: tuple[str, ...], repeats: int) -> dict:
    """What this run is asked to do, for ``--resume``: scene files by absolute path, everything else as given."""
    scenes = [str(Path(a).resolve()) if Path(a).is_file() else a for a in args.scenes]
    return {"scenes": scenes, "suite": args.suite, "engines": list(names), "repeats": repeats, "quick": args.quick,
            "max_steps": args.max_steps, "max_samples": args.max_samples, "max_joints": args.max_joints,
            "transform": list(args.transform)}


def _limits(args, jobs: int) -> CaseLimits:
    """The per-case limits from --case-timeout and --case-memory (default: a share of the machine a case runs on)."""
    if not (math.isfinite(args.case_timeout) and args.case_timeout > 0):
        raise SimparityError(f"--case-timeout {args.case_timeout}: out of range (allowed: a number of seconds > 0)")
    if args.case_memory is None:  # on Dask, each node's own default
        return CaseLimits(args.case_timeout, CaseLimits.default(jobs).memory_bytes if args.executor == "local" else None)
    if not (math.isfinite(args.case_memory) and 0 < args.case_memory <= 1e6):
        raise SimparityError(f"--case-memory {args.case_memory}: out of range (allowed: GiB > 0, up to 1e6)")
    return CaseLimits(args.case_timeout, int(args.case_memory * GIB))


def cmd_run(args, out) -> int:
    start = time.perf_counter()
    if args.resume is not None:
        _resumed(args)
    repeats = (0 if args.quick else DEFAULT_REPEATS) if args.repeats is None else args.repeats
    if repeats < 0 or repeats > 100:
        raise SimparityError(f"--repeats {args.repeats}: out of range (allowed: 0 to 100; 0 times one cold call)")
    jobs = default_jobs() if args.jobs is None else args.jobs
    for flag, value in (("--max-steps", args.max_steps), ("--max-samples", args.max_samples),
                        ("--max-joints", args.max_joints), ("--jobs", jobs)):
        if value < 1:
            raise SimparityError(f"{flag} {value}: out of range (allowed: a whole number >= 1)")
    if jobs > MAX_JOBS:
        raise SimparityError(f"--jobs {jobs}: out of range (allowed: 1 to {MAX_JOBS})")
    if args.scheduler is not None and args.executor != "dask":
        raise SimparityError(f"--scheduler {one_line(args.scheduler)} without --executor dask (allowed: add --executor "
                             "dask, or drop --scheduler)")
    limits = _limits(args, jobs)
    transforms = fixed_transforms(args.transform) if args.transform else ()
    names = check_engine_names(args.engines)
    use_engines(names)
    run_limits = Limits(max_steps=args.max_steps, max_samples=args.max_samples, max_joints=args.max_joints)
    if args.scenes and args.suite:
        raise SimparityError(f"--suite {args.suite} with scenes named: give one (allowed: scene names or files, "
                             "or --suite)")
    chosen = library.load(args.scenes, run_limits) if args.scenes else library.suite(args.suite or "default", run_limits)
    scenes = apply_profile(chosen, "quick" if args.quick else "full")
    bounds = load_tolerances(args.tolerances or DEFAULT_TOLERANCES) if args.check else None
    engines = describe_engines(names, scenes)
    _check_distinct(engines, names, scenes)
    if args.resume is not None:
        stand_ins = [n for n, e in zip(names, engines) if isinstance(e, (UnavailableEngine, BrokenEngine))]
        if stand_ins:  # its kept cases would be replaced by n/a or failed rows
            raise SimparityError(f"--resume {one_line(args.resume)}: engine(s) {one_line(', '.join(stand_ins))} of "
                                 "that run cannot be built here (allowed: resume where the run's engines import, e.g. "
                                 "from the folder a module:Class engine was found in)")
    out_dir = _out_dir(args)
    executor = _executor(args, jobs, limits)  # an unreachable scheduler is an error before a folder is made
    with contextlib.closing(executor), run_lock(_made(out_dir)):
        if args.resume is None:  # a new run: nothing of a run --force replaces is reused
            write_request(out_dir, _request(args, names, repeats))
            Journal(out_dir).clear()
        where = (f"{jobs} worker processes" if args.executor == "local" else
                 f"Dask at {args.scheduler}" if args.scheduler else f"a local Dask cluster of {jobs} workers")
        print(f"{_cost(scenes)}; {len(names)} engines; {where}" + (" (quick profile)" if args.quick else "")
              + (f"; resuming {len(Journal(out_dir))} finished cases" if args.resume else ""), file=out, flush=True)
        try:
            return _run(args, out, scenes, engines, repeats, executor, bounds, out_dir,
                        dict(zip((e.name for e in engines), names)), transforms)
        finally:  # what the run cost, also when it was interrupted or stopped by an error
            print(resource_line(time.perf_counter() - start), file=out, flush=True)


def _made(out_dir: Path) -> Path:
    """``out_dir``, created if it is not there."""
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except (OSError, ValueError) as err:  # ValueError: a NUL byte in the name
        raise SimparityError(f"--out {one_line(out_dir)}: cannot create the folder: {getattr(err, 'strerror', None) or err} "
                             "(allowed: a folder you can write)") from None
    return out_dir


def _check_distinct(engines, names: tuple[str, ...], scenes) -> None:
    """Refuse two engines or two scenes of one name: their rows would be indistinguishable."""
    seen: dict[str, str] = {}
    for engine, name in zip(engines, names):
        if engine.name in seen:
            raise SimparityError(f"--engines: {one_line(seen[engine.name])} and {one_line(name)} are both named "
                                 f"{one_line(engine.name)} (allowed: engines of distinct names)")
        seen[engine.name] = name
    files: dict[str, str] = {}
    sweeps: dict[str, str] = {}
    for scene in scenes:
        if scene.name in files:
            raise SimparityError(f"{one_line(scene.source or scene.name)}: a second scene named {one_line(scene.name)} "
                                 f"(the first from {one_line(files[scene.name])}) (allowed: scenes of distinct names)")
        files[scene.name] = scene.source or scene.name
        if scene.sweep is not None and sweeps.setdefault(scene.sweep.base, scene.source) != scene.source:
            raise SimparityError(f"{one_line(scene.source)}: a second sweep named {one_line(scene.sweep.base)} (the "
                                 f"first from {one_line(sweeps[scene.sweep.base])}): the results and the report group a "
                                 "sweep's variants by that name (allowed: sweeps of distinct [scene] names)")


def _executor(args, jobs: int, limits: CaseLimits):
    if args.executor == "dask":
        from simparity.comparisons.dask_executor import DaskExecutor  # imports Dask: only when asked

        return DaskExecutor(args.scheduler, jobs, limits)
    return IsolatedPool(jobs, limits)


def _cost(scenes) -> str:
    """What the run will do, counted before it starts."""
    steps = sum(s.n_steps(dt) * len(s.bodies) for s in scenes if isinstance(s, DynamicsScene) for dt in s.dts)
    samples = sum(s.n_configurations for s in scenes if isinstance(s, KinematicsScene))
    targets = sum(s.n_targets + len(s.hard_targets) for s in scenes if isinstance(s, IKScene))
    return (f"{len(scenes)} scenes: {steps:,} body-steps per integrator, {samples:,} configurations, "
            f"{targets:,} IK targets per solver")


def _run(args, out, scenes, engines, repeats: int, executor, bounds, out_dir: Path, specs: dict[str, str],
         transforms=()) -> int:
    writer = RunWriter(out_dir, engines, " ".join(["simparity"] + sys.argv[1:]), scenes)
    sizes = count_cases(scenes, engines, make_engine)
    bar = ProgressBar(sum(sizes), sys.stderr)
    failed = 0
    journal = Journal(out_dir)
    try:
        with contextlib.closing(executor):  # the workers stop as soon as the cases do, before the report
            results = run_scenes(scenes, engines, make_engine, repeats, executor, journal,
                                 bar.case_done if bar.active else None, specs)
            base_rows = []
            for k, (scene, rows, series) in enumerate(results):
                writer.append(rows, series)
                counts = case_counts(rows)
                failed += counts[FAILED]
                bar.scene_done(sum(sizes[:k + 1]))
                print(f"{scene.name}: {sum(counts.values())} cases ("
                      + ", ".join(f"{s} {c}" for s, c in counts.items() if c) + ")", file=out, flush=True)
                base_rows.append(rows)
            if transforms:
                bar.clear()
                for rows in invariance_rows(scenes, base_rows, transforms, engines, executor, journal, specs,
                                            lambda line: print(line, file=out, flush=True)):
                    writer.append(rows)
                    failed += sum(1 for r in rows if r.status == FAILED)
    except KeyboardInterrupt:
        bar.clear()
        print(f"interrupted; results so far are in {writer.results_path}; finish the run with: simparity run "
              f"--resume {out_dir}", file=out)
        _write_report(out_dir, out, bounds)
        return EXIT_INTERRUPTED
    except SimparityError:
        _write_report(out_dir, out, bounds)  # keep what was computed, then report the error
        raise
    if journal.unfinished:
        print(f"{journal.unfinished} cases did not finish (crashed, hung or out of memory): 'simparity run --resume "
              f"{out_dir}' tries them again", file=out)
    else:
        journal.remove()
    checked = _write_report(out_dir, out, bounds)
    _record(out_dir, args.history)
    code = EXIT_FAILED_CASES if failed else EXIT_OK
    if bounds is not None:
        code = max(code, _check(out_dir, bounds, args, out, checked))
    return code


def _record(out_dir: Path, history_option: str | None) -> None:
    """Copy the run into the history database; a database problem is one line, never a lost run."""
    table, info = read_run(out_dir)
    try:
        record_run(history_path(history_option), out_dir.resolve(), info, table)
    except HistoryError as err:
        print(f"simparity: history not updated: {one_line(err, MESSAGE_LIMIT)}; the run is in {out_dir}",
              file=sys.stderr)


def _write_report(out_dir: Path, out, bounds=None) -> CheckResult:
    """report.md, report.html and figures/ of the run; its metrics are held to ``bounds`` (default: the
    shipped tolerances) for the report's flagged findings, which never changes an exit code. Returns
    that verdict, for ``--check`` to print."""
    table, _ = read_run(out_dir)
    result = check_table(table, bounds if bounds is not None else load_tolerances(DEFAULT_TOLERANCES))
    verdict = ToleranceVerdict(result.checked, result.unchecked, tuple(v.line() for v in result.violations))
    markdown, page = write_report(out_dir, verdict)
    print(f"results: {Path(out_dir) / RESULTS_FILE}\nreport:  {markdown}\n         {page}", file=out)
    return result


def _baseline_table(option: str, run_dir: Path, history_option: str | None):
    if option == "latest":
        path = history_path(history_option)
        run_id, _ = latest_before(path, run_dir.resolve())
        return run_table(path, run_id)
    return read_run(Path(option))[0]


def _check(run_dir: Path, bounds, args, out, result: CheckResult | None = None) -> int:
    """Print the verdict on a stored run (and the moves since the baseline); 0 passed, 1 not.
    ``result``: the run already held to ``bounds``."""
    table, _ = read_run(run_dir)
    result = check_table(table, bounds) if result is None else result
    diff = None
    if args.baseline:
        if not math.isfinite(args.baseline_rel) or args.baseline_rel < 0:
            raise SimparityError(f"--baseline-rel {args.baseline_rel}: out of range (allowed: a number >= 0)")
        diff = compare_with_baseline(table, _baseline_table(args.baseline, run_dir, args.history), args.baseline_rel)
    for violation in result.violations:
        print(f"violation: {one_line(violation.line(), MESSAGE_LIMIT)}", file=out)
    if diff is not None:
        for label, items in (("moved", diff.moved), ("missing", diff.missing), ("new", diff.new),
                             ("timing (not blocking)", diff.timing)):
            for item in items:
                print(f"{label}: {one_line(item, MESSAGE_LIMIT)}", file=out)
    if args.junit:
        args.junit.write_text(junit_xml(result, diff), encoding="utf-8")
    if args.summary:
        with open(args.summary, "a", encoding="utf-8") as handle:
            handle.write(summary_markdown(result, diff))
    passed = result.passed and not (diff and diff.blocking)
    moved = "" if diff is None else (f"; since the baseline {len(diff.moved)} moved, {len(diff.missing)} missing, "
                                     f"{len(diff.new)} new")
    print(f"check {'passed' if passed else 'FAILED'}: {result.checked} metrics checked, {len(result.violations)} "
          f"outside their bounds, {result.unchecked} without a bound{moved}", file=out)
    return EXIT_OK if passed else EXIT_FAILED_CASES


def cmd_check(args, out) -> int:
    bounds = load_tolerances(args.tolerances or DEFAULT_TOLERANCES)
    run_dir = args.run_dir
    if run_dir is None:
        _, latest = latest_before(history_path(args.history))
        run_dir = Path(latest)
    if args.explain is not None:
        return _explain(run_dir, bounds, args.explain, out)
    return _check(run_dir, bounds, args, out)


def _explain(run_dir: Path, bounds, engine: str, out) -> int:
    """What the gate holds ``engine`` to in the run of ``run_dir``: one line per scene and bound."""
    table, _ = read_run(run_dir)
    engines = sorted(set(table["engine"]))
    if engine not in engines:
        raise SimparityError(f"--explain {one_line(engine)}: no rows of that engine in {one_line(run_dir)} (allowed: "
                             f"{', '.join(engines)})")
    lines = explain_lines(explain(table, bounds, engine), engine in ENGINE_NAMES)
    print("\n".join(lines) if lines else f"no bound holds {engine}'s rows", file=out)
    return EXIT_OK


def cmd_history(args, out) -> int:
    table = metric_history(history_path(args.history), args.scene, args.engine, args.metric)
    if table.empty:
        print("no recorded values match", file=out)
    else:
        print(table.to_string(index=False), file=out)
    return EXIT_OK


def cmd_export(args, out) -> int:
    if args.dt is not None and not (args.dt > 0 and RANGES["dt"].allows(args.dt)):
        raise SimparityError(f"--dt {args.dt}: not a time step (allowed: a finite number of seconds > 0, "
                             f"{RANGES['dt'].text()})")
    scenes = library.load([args.scene])
    if len(scenes) > 1:
        raise SimparityError(f"{one_line(args.scene)}: a sweep of {len(scenes)} variants; export takes one (allowed: a "
                             f"variant's name as 'simparity list' prints it, e.g. {scenes[0].name}, or a file without "
                             "[sweep])")
    scene = scenes[0]
    engine = make_engine(args.engine)
    print(engine.export(scene, args.integrator, args.dt), file=out, end="")
    return EXIT_OK


def cmd_show(args, out) -> int:
    print("\n".join(describe(scene) for scene in library.load([args.scene])), file=out, end="")
    return EXIT_OK


def cmd_bench(args, out) -> int:
    from simparity.comparisons.bench import run_bench  # imports every engine: only when asked

    def say(line: str) -> None:
        print(line, file=out, flush=True)

    path = run_bench(args.out, args.quick, " ".join(["simparity"] + sys.argv[1:]), say)
    say(f"wrote {path} and {path.with_name('benchmarks.csv')}")
    return EXIT_OK


def cmd_report(args, out) -> int:
    _write_report(args.run_dir, out, load_tolerances(args.tolerances) if args.tolerances else None)
    return EXIT_OK


_COMMANDS = {"list": cmd_list, "engines": cmd_engines, "run": cmd_run, "check": cmd_check, "history": cmd_history, "export": cmd_export,
             "show": cmd_show, "report": cmd_report, "bench": cmd_bench}


def main(argv: list[str] | None = None, out=None) -> int:
    """Entry point of the ``simparity`` console script; returns the exit code."""
    out = out or sys.stdout
    try:
        args = build_parser().parse_args(argv)
        return _COMMANDS[args.command](args, out)
    except SimparityError as err:
        print(f"simparity: error: {one_line(err, MESSAGE_LIMIT)}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:  # Ctrl-C outside a run's cases (start-up, a report): one line, not a traceback
        print("simparity: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader went away (`simparity list | head`): stop quietly, like Unix tools
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    finally:
        use_engines(())  # the command's engines end with it: none reaches the next command or a run_scene call


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
