"""The ``simparity`` command: list, engines, run, check, history, export, show, report, bench.

User mistakes (bad scene or tolerances files, unknown names, missing runs, a folder that already
holds a run) print one line ``simparity: error: ...`` and exit with code 2; tracebacks are kept
for real bugs. ``run`` exits 1 when some engine failed (raised), and with ``--check`` when a
metric is outside its bound; ``check`` exits 0 when every checked metric is inside its bound and
nothing moved since the baseline, else 1. Results computed before an error are kept either way.
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from simparity.comparisons.cli.console import EXIT_INTERRUPTED
from simparity.comparisons.cli.parser import build_parser
from simparity.core.model.errors import SimparityError, one_line

if TYPE_CHECKING:
    import pandas as pd

    from simparity.comparisons.execute.isolation import CaseLimits
    from simparity.comparisons.gate.check import CheckResult
    from simparity.comparisons.gate.tolerances import EngineNames, Gate

EXIT_OK, EXIT_FAILED_CASES, EXIT_USAGE = 0, 1, 2
MAX_JOBS = 256
"""Worker processes at most: each is a Python process of ~250 MiB with the engines loaded."""
RESUMED_OPTIONS = ("scenes", "suite", "engines", "out", "force", "quick", "repeats", "max_steps", "max_samples",
                   "max_joints", "transform")
"""What a resumed run takes from the run it resumes (``resume.json``), never from the command line."""
MESSAGE_LIMIT = 1000
"""Characters of an error message printed: one line, whatever the input echoed into it."""


def cmd_list(args, out) -> int:
    from simparity.comparisons.scenes import library

    scenes = library.suite(args.suite) if args.suite else library.load(list(library.builtin_paths().values()))
    for scene in scenes:
        print(f"{scene.name:<28} {scene.kind:<11} reference={scene.reference:<10} {','.join(scene.suites):<14} "
              f"{scene.description}", file=out)
    return EXIT_OK


def cmd_engines(args, out) -> int:
    from simparity.comparisons.engines.listing import engine_lines  # builds every engine: only when asked

    for line in engine_lines():
        print(line, file=out)
    return EXIT_OK


def _out_dir(args) -> Path:
    """The run's folder, created and probed for writing before the run: --out (refused when it holds a run, unless
    --force), else a new one."""
    from simparity.comparisons.cli.destinations import writable_folder
    from simparity.comparisons.common.out_folder import default_out_dir

    if args.out is None:
        return writable_folder("--out (default)", default_out_dir())
    try:
        return writable_folder("--out", _checked_out_dir(args.out, args.force))
    except (OSError, ValueError) as err:  # a name the OS rejects: too long, a NUL byte
        raise SimparityError(f"--out {one_line(args.out)}: {getattr(err, 'strerror', None) or err} (allowed: a "
                             "folder path the system accepts)") from None


def _checked_out_dir(out_dir: Path, force: bool) -> Path:
    from simparity.core.model.results import RESULTS_FILE, RUN_INFO_FILE

    held = [name for name in (RESULTS_FILE, RUN_INFO_FILE) if (out_dir / name).exists()]
    if held and not force:
        raise SimparityError(f"--out {one_line(out_dir)}: already holds a run ({', '.join(held)}); nothing was "
                             "overwritten (allowed: a new folder, no --out for a new timestamped one, or --force)")
    return out_dir


def _resumed(args) -> None:
    """Fill ``args`` with what the run in ``--resume DIR`` was asked to do; refuse options that would change it."""
    from simparity.comparisons.execute.journal import CASES_FOLDER, read_request
    from simparity.core.model.results import RESULTS_FILE

    defaults = build_parser().parse_args(["run"])
    given = [name for name in RESUMED_OPTIONS if getattr(args, name) != getattr(defaults, name)]
    if given:
        flags = ", ".join("SCENE" if name == "scenes" else "--" + name.replace("_", "-") for name in given)
        raise SimparityError(f"--resume {one_line(args.resume)} with {flags}: a resumed run does what it was asked to "
                             "(allowed with --resume: --jobs, --executor, --scheduler, --case-timeout, --case-memory, "
                             "--no-report, --check and its options, --history)")
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
    from simparity.comparisons.execute.isolation import (
        GIB,
        MAX_CASE_SECONDS,
        MIN_CASE_MEMORY_BYTES,
        MIN_CASE_SECONDS,
        CaseLimits,
    )

    if not MIN_CASE_SECONDS <= args.case_timeout <= MAX_CASE_SECONDS:  # False for nan
        raise SimparityError(f"--case-timeout {args.case_timeout:g}: out of range (allowed: seconds from "
                             f"{MIN_CASE_SECONDS:g}, a case's fixed cost with room, to {MAX_CASE_SECONDS:g})")
    if args.case_memory is None:  # on Dask, each node's own default
        return CaseLimits(args.case_timeout, CaseLimits.default(jobs).memory_bytes if args.executor == "local" else None)
    floor = MIN_CASE_MEMORY_BYTES / GIB
    if not (math.isfinite(args.case_memory) and floor <= args.case_memory <= 1e6):
        raise SimparityError(f"--case-memory {args.case_memory:g}: out of range: below {floor:.3g} GiB (an idle worker "
                             f"with the engines imported) every case would be killed (allowed: GiB from {floor:.3g} "
                             "up to 1e6)")
    return CaseLimits(args.case_timeout, int(args.case_memory * GIB))


def cmd_run(args, out) -> int:
    from simparity.comparisons.cli.check_options import (
        CHECK_OPTIONS,
        baseline_run,
        checked_check_options,
        refuse_check_options,
    )
    from simparity.comparisons.engines.placeholders import BrokenEngine, UnavailableEngine
    from simparity.comparisons.engines.registry import EngineSet, check_engine_names
    from simparity.comparisons.execute.execution import default_jobs
    from simparity.comparisons.execute.journal import Journal
    from simparity.comparisons.execute.runner import DEFAULT_REPEATS
    from simparity.comparisons.execute.timing import record_peak_memory, resource_line
    from simparity.comparisons.gate.check import refuse_strangers
    from simparity.comparisons.gate.history import check_usable, history_path
    from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, load_gate
    from simparity.comparisons.invariance.transforms import fixed_transforms
    from simparity.comparisons.pipeline.session import Execution, Session
    from simparity.comparisons.scenes import library
    from simparity.comparisons.scenes.limits import Limits
    from simparity.core.model.results import RUN_INFO_FILE

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
    execution = Execution(args.executor, jobs, _limits(args, jobs), args.scheduler)
    transforms = fixed_transforms(args.transform) if args.transform else ()
    engines = EngineSet(check_engine_names(args.engines))
    engines.refuse_non_engines()
    run_limits = Limits(max_steps=args.max_steps, max_samples=args.max_samples, max_joints=args.max_joints)
    if args.scenes and args.suite:
        raise SimparityError(f"--suite {args.suite} with scenes named: give one (allowed: scene names or files, "
                             "or --suite)")
    chosen = (library.load(args.scenes, run_limits, engines) if args.scenes
              else library.suite(args.suite or "default", run_limits, engines))
    gate = load_gate(args.tolerances or DEFAULT_TOLERANCES) if args.check else None
    if gate is None:
        refuse_check_options(args, CHECK_OPTIONS, "without --check", "add --check, or drop them")
    else:
        checked_check_options(args)
        if args.baseline not in (None, "latest"):  # read now: a baseline that is no run must not cost the run
            baseline_run(args.baseline)
    held = _engine_names(gate, args)[0] if gate is not None else None
    out_dir = _out_dir(args)
    check_usable(history_path(args.history))  # the run is recorded there: a database it cannot record in, said now

    def say(line: str) -> None:
        print(line, file=out, flush=True)

    session = Session(chosen, engines, profile="quick" if args.quick else "full", repeats=repeats,
                      execution=execution, out_dir=out_dir, history=history_path(args.history),
                      bounds=gate.bounds if gate is not None else None, held=held.names if held else None,
                      transforms=transforms, command=" ".join(["simparity"] + sys.argv[1:]),
                      report=not args.no_report, request=_request(args, engines.names, repeats),
                      resume=args.resume is not None, say=say,
                      warn=lambda line: print(line, file=sys.stderr), progress=sys.stderr)
    if args.resume is not None:
        stand_ins = [n for n, e in zip(session.names, session.engines) if isinstance(e, (UnavailableEngine, BrokenEngine))]
        if stand_ins:  # its kept cases would be replaced by n/a or failed rows
            raise SimparityError(f"--resume {one_line(args.resume)}: engine(s) {one_line(', '.join(stand_ins))} of "
                                 "that run cannot be built here (allowed: resume where the run's engines import, e.g. "
                                 "from the folder a module:Class engine was found in)")
    if held is not None:  # before the run: a name no engine of it has would hold nothing
        refuse_strangers(held, tuple(session.specs))
    where = (f"{jobs} worker processes" if args.executor == "local" else
             f"Dask at {args.scheduler}" if args.scheduler else f"a local Dask cluster of {jobs} workers")

    def start_line() -> str:
        return (f"{_cost(session.scenes)}; {len(session.names)} engines; {where}" + (" (quick profile)" if args.quick
                else "") + (f"; resuming {len(Journal(out_dir))} finished cases" if args.resume else ""))

    result = None
    try:
        result = session.run(start_line)
        if result.interrupted:
            return EXIT_INTERRUPTED
        code = EXIT_FAILED_CASES if result.failed_cases else EXIT_OK
        if result.check is not None and gate is not None:
            try:
                code = max(code, _check(out_dir, gate, args, out, result.check, result.table))
            except SimparityError as err:  # after the run (a full device, the history): the run itself is whole
                raise SimparityError(f"the run's results are kept in {one_line(out_dir)} ('simparity check "
                                     f"{one_line(out_dir)}' checks them again), its check stopped: {err}") from None
        return code
    finally:  # what the run cost, also when it was interrupted or stopped by an error
        total = time.perf_counter() - start
        if result is not None:  # where it went, then what it cost on the last line
            print(result.wall.line(total), file=out, flush=True)
        print(resource_line(total), file=out, flush=True)
        if (out_dir / RUN_INFO_FILE).is_file():  # for the bench: the peaks by name, never parsed from the line
            try:
                record_peak_memory(out_dir)
            except (SimparityError, OSError) as err:
                print(f"simparity: peak memory not recorded in run.json: {one_line(err)}", file=sys.stderr)


def _cost(scenes) -> str:
    """What the run will do, counted before it starts."""
    from simparity.core.model.scenes.dynamics import DynamicsScene
    from simparity.core.model.scenes.ik import IKScene
    from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
    from simparity.core.model.scenes.joint_motion import JointMotionScene
    from simparity.core.model.scenes.kinematics import KinematicsScene

    steps = sum(s.n_steps(dt) * len(s.bodies) for s in scenes if isinstance(s, DynamicsScene) for dt in s.dts)
    samples = sum(s.n_configurations for s in scenes if isinstance(s, KinematicsScene))
    targets = sum(s.n_targets + len(s.hard_targets) for s in scenes if isinstance(s, IKScene))
    states = sum(s.n_states for s in scenes if isinstance(s, JointDynamicsScene))
    joint_steps = sum(s.n_steps(dt) * s.copies for s in scenes if isinstance(s, JointMotionScene) for dt in s.dts)
    return (f"{len(scenes)} scenes: {steps:,} body-steps per integrator, {samples:,} configurations, "
            f"{targets:,} IK targets per solver" + (f", {states:,} joint-dynamics states" if states else "")
            + (f", {joint_steps:,} chain steps per integrator" if joint_steps else ""))


def _engine_names(gate: Gate, args) -> tuple[EngineNames | None, EngineNames | None]:
    """The engines the gate holds and requires: the command line's, else the tolerances file's (None: not named)."""
    from simparity.comparisons.gate.tolerances import EngineNames

    check = EngineNames(args.check_engines, "--check-engines") if args.check_engines else gate.check_engines
    require = EngineNames(args.require_engines, "--require-engines") if args.require_engines else gate.require_engines
    return check, require


LINES_SHOWN = 20
"""Non-blocking lines of one kind the check prints at most (findings about engines the gate does not hold, one per
case and reason; a user's bounds that matched no row, which a blessed file checked on part of its run has by the
thousand); the rest counted (--verbose: every one)."""


def _say_some(label: str, lines: list[str], verbose: bool, out) -> None:
    """``label: line`` for each of ``lines``, at most :data:`LINES_SHOWN` unless ``verbose``, the rest counted."""
    for line in lines if verbose else lines[:LINES_SHOWN]:
        print(f"{label}: {one_line(line, MESSAGE_LIMIT)}", file=out)
    if len(lines) > LINES_SHOWN and not verbose:
        print(f"{label}: ... and {len(lines) - LINES_SHOWN} more (--verbose for each)", file=out)


def _check(run_dir: Path, gate: Gate, args, out, result: CheckResult | None = None,
           table: pd.DataFrame | None = None) -> int:
    """Print the verdict on a stored run (and the moves since the baseline); 0 passed, 1 not.
    ``result``: the run already held to ``gate``'s bounds; ``table``: its rows, as the run's writer handed them back
    (None: read from ``run_dir``)."""
    from simparity.comparisons.cli.check_options import baseline_table
    from simparity.comparisons.cli.destinations import write_file
    from simparity.comparisons.gate.check import BASELINE_RELATIVE, check_table, compare_with_baseline, held_to
    from simparity.comparisons.gate.check_output import held_line, junit_xml, summary_markdown
    from simparity.comparisons.gate.violation import grouped
    from simparity.reports.store import read_info, read_run

    table, info = read_run(run_dir) if table is None else (table, read_info(run_dir))
    result = held_to(check_table(table, gate.bounds) if result is None else result, *_engine_names(gate, args))
    diff = None
    if args.baseline is not None:
        relative = BASELINE_RELATIVE if args.baseline_rel is None else args.baseline_rel
        diff = compare_with_baseline(table, baseline_table(args.baseline, run_dir, info.profile, args.history),
                                     relative)
    shown = result.violations if args.verbose else grouped(result.violations)
    for violation in shown:
        print(f"violation: {one_line(violation.line(), MESSAGE_LIMIT)}", file=out)
    findings = result.findings if args.verbose else grouped(result.findings)
    _say_some("finding (not held)", [finding.line() for finding in findings], args.verbose, out)
    _say_some("tolerances", result.unmatched, args.verbose, out)
    for line in result.absent:
        print(f"required: {one_line(line, MESSAGE_LIMIT)}", file=out)
    if diff is not None:
        for label, items in (("moved", diff.moved), ("missing", diff.missing), ("new", diff.new),
                             ("timing (not blocking)", diff.timing)):
            for item in items:
                print(f"{label}: {one_line(item, MESSAGE_LIMIT)}", file=out)
    for line in filter(None, (result.nothing_checked, diff.nothing_compared if diff is not None else "")):
        print(f"nothing checked: {line}", file=out)
    unbounded = "" if args.allow_unbounded else result.too_unbounded()
    if unbounded:
        print(f"unbounded: {unbounded}", file=out)
    passed = result.passed and not (diff and diff.blocking) and not unbounded
    moved = "" if diff is None else (f"; since the baseline {len(diff.moved)} moved, {len(diff.missing)} missing, "
                                     f"{len(diff.new)} new" + (f" ({diff.scope_line()})" if diff.scope_line() else ""))
    cases = "" if args.verbose or len(shown) == len(result.violations) else f" ({len(shown)} lines: --verbose for each)"
    print(f"check {'passed' if passed else 'FAILED'}: {held_line(result)}, {len(result.violations)} "
          f"outside their bounds{cases}, {result.unchecked} without a bound, {result.value_bounded} held to a value or "
          f"verdict; {len(result.unbounded_series)} of {len(result.series)} series without a value bound{moved}",
          file=out, flush=True)
    if args.junit:  # after the verdict: a file that cannot be written loses nothing printed
        write_file("--junit", args.junit, junit_xml(result, diff, unbounded))
    if args.summary:
        write_file("--summary", args.summary, summary_markdown(result, diff, unbounded), append=True)
    return EXIT_OK if passed else EXIT_FAILED_CASES


def cmd_check(args, out) -> int:
    from simparity.comparisons.cli.check_options import CHECK_OPTIONS, checked_check_options, refuse_check_options
    from simparity.comparisons.cli.destinations import writable_file
    from simparity.comparisons.gate.history import history_path, latest_before
    from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, load_gate

    gate = load_gate(args.tolerances or DEFAULT_TOLERANCES)
    bounds = gate.bounds
    run_dir = args.run_dir
    if run_dir is None:
        _, latest = latest_before(history_path(args.history))
        run_dir = Path(latest)
    narrowed = {key: getattr(args, key) for key in ("scene", "integrator", "metric") if getattr(args, key)}
    if narrowed and args.explain is None:
        raise SimparityError(f"--{next(iter(narrowed))} without --explain (allowed: --explain ENGINE with --scene, "
                             "--integrator, --metric)")
    if args.spread is not None and args.bless is None:
        raise SimparityError("--spread without --bless (allowed: --bless FILE --spread RUN_DIR)")
    if args.explain is not None or args.bless is not None:
        refuse_check_options(args, tuple(n for n in CHECK_OPTIONS if n != "tolerances"),
                              f"with --{'explain' if args.explain is not None else 'bless'}",
                              "drop them, or check the run without --bless and --explain")
    checked_check_options(args)
    if args.explain is not None:
        return _explain(run_dir, bounds, args.explain, narrowed, out)
    if args.bless is not None:
        return _bless(run_dir, writable_file("--bless", args.bless), args.spread, args.tolerances, out)
    return _check(run_dir, gate, args, out)


def _bless(run_dir: Path, path: Path, spread: Path | None, tolerances: Path | None, out) -> int:
    """Write the tolerances file blessed from the run in ``run_dir`` (:mod:`comparisons.gate.bless`), extending
    ``tolerances`` (default: the shipped ones); a ``spread`` run of another profile is refused."""
    from simparity.comparisons.gate.bless import bless, write_blessed
    from simparity.comparisons.gate.tolerances import load_tolerances
    from simparity.reports.store import read_run

    table, info = read_run(run_dir)
    other = read_run(spread) if spread is not None else None
    if other is not None and info.profile and other[1].profile and other[1].profile != info.profile:
        raise SimparityError(f"--spread {one_line(spread)}: a {other[1].profile}-profile run, this one is "
                             f"{info.profile} (allowed: a second run of the same scenes and profile)")
    extended = load_tolerances(tolerances) if tolerances else None
    extends = str(tolerances.resolve()) if tolerances else "default"
    text, count = bless(table, info, run_dir, other[0] if other else None, extended, extends)
    write_blessed(path, text)
    print(f"blessed {count} bounds from {run_dir} into {path} (extends the shipped tolerances; review the diverged "
          "and n/a ones before committing)", file=out)
    return EXIT_OK


def _explain(run_dir: Path, bounds, engine: str, narrowed: dict[str, str], out) -> int:
    """What the gate holds ``engine`` to in the run of ``run_dir``: one line per scene and bound, or (``narrowed``
    to rows by scene, integrator or metric patterns) every bound that matched each row and which decided."""
    from simparity.comparisons.engines.registry import ENGINE_NAMES
    from simparity.comparisons.gate.check import explain, explain_lines, explain_rows
    from simparity.reports.store import read_run

    table, _ = read_run(run_dir)
    engines = sorted(set(table["engine"]))
    if engine not in engines:
        raise SimparityError(f"--explain {one_line(engine)}: no rows of that engine in {one_line(run_dir)} (allowed: "
                             f"{', '.join(engines)})")
    if narrowed:
        lines = explain_rows(table, bounds, engine, **narrowed)
        print("\n".join(lines) if lines else f"no row of {engine} matches {narrowed}", file=out)
        return EXIT_OK
    lines = explain_lines(explain(table, bounds, engine), engine in ENGINE_NAMES)
    print("\n".join(lines) if lines else f"no bound holds {engine}'s rows", file=out)
    return EXIT_OK


def cmd_history(args, out) -> int:
    from simparity.comparisons.gate.history import history_path, metric_history, recorded_scenes

    path = history_path(args.history)
    table = metric_history(path, args.scene, args.engine, args.metric)
    if table.empty:
        asked = ", ".join(f"{key} {value}" for key, value in (("scene", args.scene), ("engine", args.engine),
                                                                ("metric", args.metric)) if value)
        known = recorded_scenes(path)
        print(f"no recorded values match {asked or 'anything'} in {path} (scenes recorded: "
              f"{', '.join(known) if known else 'none'})", file=out)
        return EXIT_FAILED_CASES
    print(table.to_string(index=False), file=out)
    return EXIT_OK


def cmd_export(args, out) -> int:
    from simparity.comparisons.engines.registry import make_engine
    from simparity.comparisons.scenes import library
    from simparity.core.model.ranges import RANGES

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
    from simparity.comparisons.scenes import library
    from simparity.comparisons.scenes.describe import describe

    print("\n".join(describe(scene) for scene in library.load([args.scene])), file=out, end="")
    return EXIT_OK


def cmd_import(args, out) -> int:
    from simparity.comparisons.cli.importers import verdicts  # imports every engine: only when asked

    kind, said = verdicts(args.file)
    for verdict in said:
        print(f"{verdict.reader}: {verdict.said}", file=out)
    if not any(verdict.loads for verdict in said):
        raise SimparityError(f"{one_line(args.file)}: no reader reads this {kind.upper()} file (allowed: a file one of "
                             "core, MuJoCo, Pinocchio or PyBullet reads)")
    return EXIT_OK


def cmd_bench(args, out) -> int:
    from simparity.comparisons.bench.run import run_bench  # imports every engine: only when asked
    from simparity.comparisons.cli.destinations import writable_folder

    def say(line: str) -> None:
        print(line, file=out, flush=True)

    path = run_bench(writable_folder("--out", args.out), args.quick, " ".join(["simparity"] + sys.argv[1:]), say)
    say(f"wrote {path} and {path.with_name('benchmarks.csv')}")
    return EXIT_OK


def cmd_report(args, out) -> int:
    from simparity.comparisons.gate.tolerances import load_gate
    from simparity.comparisons.pipeline.session import write_run_report

    gate = load_gate(args.tolerances) if args.tolerances else None
    held = gate.check_engines.names if gate is not None and gate.check_engines is not None else None
    write_run_report(args.run_dir, lambda line: print(line, file=out), gate.bounds if gate else None, held)
    return EXIT_OK


_COMMANDS = {"list": cmd_list, "engines": cmd_engines, "run": cmd_run, "check": cmd_check, "history": cmd_history, "export": cmd_export,
             "show": cmd_show, "report": cmd_report, "bench": cmd_bench, "import": cmd_import}


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


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
