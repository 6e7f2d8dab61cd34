"""The ``simparity`` command line: its commands, options and help text (parsing only; :mod:`.main` runs them)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable, cast

from simparity.comparisons.common.out_folder import DEFAULT_OUT_ROOT
from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES
from simparity.core.model.errors import UsageError, echo, one_line
from simparity.core.model.scenes.suites import SUITES

EXPORTABLE = ("mujoco", "pybullet", "pinocchio")
EXECUTORS = ("local", "dask")
MEMORY_HELP = ("80%% of the memory of the machine a case runs on, shared between its workers (on Dask: a worker's own "
               "memory limit shared between its threads, if it has one), at least 1 GiB")


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are one line and exit 2 like every other bad input (no usage block)."""

    def error(self, message: str):
        allowed = "" if "(allowed: " in message else f" (allowed: see '{self.prog} --help')"
        raise UsageError(f"{self.prog}: {message}{allowed}")


class _Commands(argparse._SubParsersAction):
    """The subcommands, each given its options when it is the command parsed: their help quotes defaults of the
    execution stack, the engines and the gate, which a command that needs none of them (``simparity list``,
    ``--help``) never imports."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._options: dict[str, Callable[[argparse.ArgumentParser], None]] = {}

    def add_command(self, name: str, options: Callable[[argparse.ArgumentParser], None], **kwargs) -> None:
        """Command ``name`` (``kwargs``: its help and description); ``options(parser)`` adds its arguments."""
        self.add_parser(name, **kwargs)
        self._options[name] = options

    def __call__(self, parser, namespace, values, option_string=None):
        options = self._options.pop(values[0], None)  # argparse checked the name against the commands
        if options is not None:
            options(self._name_parser_map[values[0]])
        super().__call__(parser, namespace, values, option_string)


def name_list(known: tuple[str, ...] = (), kind: str = "name"):
    """An argparse type: comma-separated names, each given once, none empty (``''``, ``','`` and ``'a,'`` name
    nothing or an empty name: refused, never read as fewer names); ``known``: the only names allowed, each a
    ``kind`` (empty: any name, checked later against what exists)."""
    allowed = f"allowed: {', '.join(known)}, comma-separated, each once" if known else (
        "allowed: comma-separated names, each once, none empty")

    def parse(text: str) -> tuple[str, ...]:
        names = [n.strip() for n in text.split(",")]
        if not any(names):
            raise argparse.ArgumentTypeError(f"{echo(text)} names nothing ({allowed})")
        if "" in names:
            raise argparse.ArgumentTypeError(f"{echo(text)}: an empty name between or after commas ({allowed})")
        repeated = [n for n in dict.fromkeys(names) if names.count(n) > 1]
        if repeated:
            raise argparse.ArgumentTypeError(f"{echo(text)}: {one_line(repeated[0])} named twice ({allowed})")
        unknown = [n for n in names if known and n not in known]
        if unknown:
            raise argparse.ArgumentTypeError(f"{one_line(unknown[0])}: no such {kind} ({allowed})")
        return tuple(names)

    return parse


def name_argument(text: str) -> str:
    """An argparse type: a name or pattern, never the empty string (which would read as the option not given)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{echo(text)} names nothing (allowed: a non-empty name)")
    return text


def path_argument(text: str) -> Path:
    """An argparse type: a path, never the empty string (which ``Path`` would read as the current folder) nor one
    holding a NUL byte."""
    if not text.strip() or "\0" in text:  # no system takes a NUL byte in a path
        raise argparse.ArgumentTypeError(f"{echo(text)} is no path (allowed: a file or folder path, no NUL byte)")
    return Path(text)


def _add_check_options(parser: argparse.ArgumentParser) -> None:
    from simparity.comparisons.gate.check import BASELINE_RELATIVE, UNBOUNDED_SHARE_MAX  # pandas: only when parsed

    parser.add_argument("--tolerances", type=path_argument, default=None, metavar="FILE",
                        help=f"bounds to hold the run to: your file extends the shipped {DEFAULT_TOLERANCES.name} "
                        "(extends = \"none\" in it starts empty) and its bounds win where they match")
    parser.add_argument("--check-engines", type=name_list(), default=None, metavar="A,B,...",
                        help="the engines the gate holds (default: every engine of the run, or the tolerances file's "
                        "check_engines): the others' violations are printed as findings and never fail the check")
    parser.add_argument("--require-engines", type=name_list(), default=None, metavar="A,B,...",
                        help="fail the check when one of these engines measured nothing: not in the run, or every "
                        "row n/a or failed (default: the tolerances file's require_engines, else none)")
    parser.add_argument("--allow-unbounded", action="store_true",
                        help=f"pass although more than {UNBOUNDED_SHARE_MAX * 100:.0f}%% of the series (scene x engine x "
                        "integrator) have no bound on any value, only on their status")
    parser.add_argument("--verbose", action="store_true",
                        help="one line per metric outside its bound (default: one per case and reason, with the "
                        "count of metrics it covers)")
    parser.add_argument("--baseline", default=None, metavar="DIR|latest",
                        help="also flag every metric that moved since this run, among the scenes x engines both runs "
                        "ran ('latest': the latest earlier run of the same profile, from the history)")
    parser.add_argument("--baseline-rel", type=float, default=None, metavar="X",
                        help=f"relative change that counts as a move (default: {BASELINE_RELATIVE:g}); timing "
                        "changes are listed apart and never fail the check")
    parser.add_argument("--junit", type=path_argument, default=None, metavar="FILE",
                        help="write JUnit XML: one test case per scene x engine x integrator x dt")
    parser.add_argument("--summary", type=path_argument, default=None, metavar="FILE",
                        help="write a Markdown summary (e.g. $GITHUB_STEP_SUMMARY)")


def _add_history_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--history", type=path_argument, default=None, metavar="PATH",
                        help=f"run history database (default: $SIMPARITY_HISTORY or {DEFAULT_OUT_ROOT}/history.sqlite)")


def _add_run_arguments(run: argparse.ArgumentParser) -> None:
    """The options of ``simparity run``: their help quotes the defaults of the engines and the execution stack."""
    from simparity.comparisons.engines.registry import DEFAULT_ENGINES, allowed_engines
    from simparity.comparisons.execute.execution import default_jobs
    from simparity.comparisons.execute.isolation import (
        DEFAULT_CASE_SECONDS,
        GIB,
        MAX_CASE_SECONDS,
        MIN_CASE_MEMORY_BYTES,
        MIN_CASE_SECONDS,
    )
    from simparity.comparisons.execute.runner import DEFAULT_REPEATS
    from simparity.comparisons.invariance.transforms import TRANSFORM_NAMES
    from simparity.comparisons.scenes.limits import DEFAULT_LIMITS
    from simparity.comparisons.scenes.profiles import QUICK_CONTACT_STEPS, QUICK_LADDER, QUICK_MAX_STEPS, QUICK_TARGETS

    run.add_argument("scenes", nargs="*", metavar="SCENE|FILE",
                     help="built-in scene names or scene files (default: the scenes of --suite)")
    run.add_argument("--suite", default=None, choices=SUITES,
                     help="run a built-in suite: default (what 'simparity run' runs), contact (every scene with "
                     "planes), hard (the numerical-stability cases, each with the verdict it must earn), bench (the "
                     "arms 'simparity bench' times, 10,000 IK targets each), articulated (real arms' joint-space "
                     "dynamics and chains in motion) or robots (every robot file the dependencies ship, each through "
                     "every engine's importer: docs/robots.md)")
    run.add_argument("--engines", type=name_list(), default=DEFAULT_ENGINES, metavar="A,B,...",
                     help=f"comma-separated engines to run (default: {','.join(DEFAULT_ENGINES)}; "
                     f"known: {allowed_engines()}; 'simparity engines' lists them)")
    run.add_argument("--out", type=path_argument, default=None, metavar="DIR",
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
    run.add_argument("--scheduler", type=name_argument, default=None, metavar="ADDRESS",
                     help="with --executor dask: the scheduler of a running cluster, e.g. tcp://10.0.0.5:8786")
    run.add_argument("--case-timeout", type=float, default=DEFAULT_CASE_SECONDS, metavar="SECONDS",
                     help="a case still running after this long is killed and becomes a failed row (from "
                     f"{MIN_CASE_SECONDS:g} to {MAX_CASE_SECONDS:g}; default: {DEFAULT_CASE_SECONDS:g})")
    run.add_argument("--case-memory", type=float, default=None, metavar="GIB",
                     help="a case whose worker's resident memory passes this is killed and becomes a failed row "
                     f"(default: {MEMORY_HELP}; at least {MIN_CASE_MEMORY_BYTES / GIB:.3g}, what an idle worker with "
                     "the engines imported holds)")
    run.add_argument("--no-report", action="store_true",
                     help="a gate-only run: draw no report.md, report.html or figures (results, run.json, the "
                     "history and --check's verdict, junit and summary as always); 'simparity report DIR' draws them "
                     "later")
    run.add_argument("--resume", type=path_argument, default=None, metavar="DIR",
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
    run.add_argument("--transform", type=name_list(TRANSFORM_NAMES, "transform"), default=(), metavar="NAME[,NAME]",
                     help="also run every scene transformed (" + ", ".join(TRANSFORM_NAMES) + ": 2 km from the "
                     "origin, turned with its gravity, its bodies reordered, its units rescaled, time in ms) and add "
                     "each engine's invariance rows (invariance_ratio_NAME <= 1, invariance_status_changes_NAME = 0; "
                     "docs/invariance.md); costs about two more runs per transform")
    run.add_argument("--check", action="store_true",
                     help="check the run against tolerances when it is done (exit 1 on a violation)")
    _add_check_options(run)
    _add_history_option(run)


def _add_check_arguments(check: argparse.ArgumentParser) -> None:
    """The arguments of ``simparity check``."""
    check.add_argument("run_dir", nargs="?", type=path_argument, default=None, metavar="RUN_DIR",
                       help="a folder written by 'simparity run' (default: the latest run in the history)")
    check.add_argument("--explain", type=name_argument, default=None, metavar="ENGINE",
                       help="print, per scene, every bound that holds ENGINE's rows (which rows, to what, and why) "
                       "instead of checking; your engine is held to the bounds of its schemes' kinds. With --scene, "
                       "--integrator or --metric: for each row, every bound that matched, its file, and which decided")
    for key in ("scene", "integrator", "metric"):
        check.add_argument(f"--{key}", type=name_argument, default=None, metavar="PATTERN",
                           help=f"with --explain: only rows whose {key} matches (fnmatch, e.g. 'order_*')")
    check.add_argument("--bless", type=path_argument, default=None, metavar="FILE",
                       help="write a tolerances file from the run instead of checking: each row held to its measured "
                       "value with a margin (never timing; a failed row refuses the file; a diverged one is marked "
                       "'expected - review'); docs/check.md")
    check.add_argument("--spread", type=path_argument, default=None, metavar="RUN_DIR",
                       help="with --bless: a second run of the same scenes (another machine, a perturbed scene); each "
                       "margin covers 3 x the two runs' difference")
    _add_check_options(check)
    _add_history_option(check)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="simparity",
        description="Run textbook IK and rigid-body methods beside MuJoCo, PyBullet and Pinocchio "
        "on identical scenes; report error, drift and speed, and check them against tolerances.",
    )
    commands = cast(_Commands, parser.add_subparsers(dest="command", metavar="COMMAND", required=True,
                                                     action=_Commands))

    listing = commands.add_parser("list", help="list the built-in scenes",
                                  description="List the built-in scenes, one per line, with the suites they are in.")
    listing.add_argument("--suite", default=None, choices=SUITES, help="only the scenes of this suite")

    commands.add_parser(
        "engines", help="list the engines: built-in and installed plugins, with what each supports",
        description="List every engine, one per line: its name (what --engines takes), where it comes from (built-in, "
        "or the installed package and entry point of a plugin in the group 'simparity.engines'), its version, its "
        "dynamics integrators, IK solvers and whether it does kinematics; an engine that cannot run says why, a "
        "plugin shadowed by a built-in of the same name says so. Code that is not packaged runs as "
        "--engines module:Class. Writing one: docs/plugins.md.")

    commands.add_command(
        "run", _add_run_arguments, help="run scenes on engines and write results.csv and report.md",
        description="Run scenes on engines; write results.csv, run.json and report.md into a new output folder, "
        "and record the run in the history database.")

    commands.add_command(
        "check", _add_check_arguments, help="hold a stored run to tolerances (exit 1 on a violation)",
        description="Hold every metric of a stored run to its bound; print each violation on one line. Exit 0 "
        "when all are inside, 1 when any is not (or, with --baseline, when numerics moved), 2 on bad input.")

    history = commands.add_parser(
        "history", help="how metrics moved across recorded runs",
        description="Show one metric (or all) across the runs recorded in the history database.")
    history.add_argument("scene", nargs="?", type=name_argument, default=None, metavar="SCENE")
    history.add_argument("--engine", type=name_argument, default=None)
    history.add_argument("--metric", type=name_argument, default=None)
    _add_history_option(history)

    export = commands.add_parser(
        "export", help="print the model an adapter builds for a scene",
        description="Print the model (MJCF, URDF or Pinocchio's model) an engine is given for a scene.",
    )
    export.add_argument("scene", metavar="SCENE|FILE")
    export.add_argument("--engine", required=True, choices=EXPORTABLE)
    export.add_argument("--integrator", type=name_argument, default=None, help="dynamics only (default: the engine's first)")
    export.add_argument("--dt", type=float, default=None, help="dynamics only, [s] (default: the scene's first)")

    show = commands.add_parser(
        "show", help="print a scene as the loader understood it",
        description="Print a scene in SI units as loaded: bodies (mass, COM and inertia tensor, computed for a body "
        "built from point masses), forces, planes (normalised), shapes and every body-plane material.")
    show.add_argument("scene", metavar="SCENE|FILE")

    robot = commands.add_parser(
        "import", help="say which readers read a robot file (URDF or MJCF): core's and each engine's importer",
        description="Read a URDF or MJCF file with core's reader and with MuJoCo's, Pinocchio's and PyBullet's "
        "importers, as the file is, and print one line per reader: what it compiled, or why it does not read the "
        "file. Exit 2 only when no reader reads it (docs/robots.md).")
    robot.add_argument("file", metavar="FILE")

    bench = commands.add_parser(
        "bench", help="measure speed with accuracy, core against the engines; write BENCHMARKS.md",
        description="Time rigid-body stepping (B = 1, 100, 10,000 bodies), FK + Jacobian, IK (the bench suite's "
        "arms, 10,000 targets each), the arms' joint-space dynamics and their motion (RK4 of B = 1, 100, 10,000 "
        "falling arms) for core and every engine in one run, each time with the error it reaches; "
        "write BENCHMARKS.md and benchmarks.csv with the ratios and the targets met or missed. About 45 minutes "
        "on an idle 2-core machine, the default suite and the quick gate timed too (--quick: a few minutes, "
        "without them).")
    bench.add_argument("--out", type=path_argument, default=Path("."), metavar="DIR",
                       help="folder for BENCHMARKS.md and benchmarks.csv (default: the current folder)")
    bench.add_argument("--quick", action="store_true", help="B = 1 and 100 only, 300 IK targets per arm")

    report = commands.add_parser(
        "report", help="re-render report.md, report.html and figures/ of a stored run",
        description="Re-render report.md, report.html and the figures (SVG, PNG) from a stored run's results.csv, "
        "series.csv.gz and run.json; runs no engine. Flagged findings hold the run to --tolerances.")
    report.add_argument("run_dir", type=path_argument, metavar="DIR")
    report.add_argument("--tolerances", type=path_argument, default=None, metavar="FILE",
                        help=f"bounds for the flagged findings (default: the shipped {DEFAULT_TOLERANCES.name}); its "
                        "check_engines, if any, say which of your engines open the report with 'Is ENGINE right?'")
    return parser
