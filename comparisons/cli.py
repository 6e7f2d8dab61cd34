"""The ``simparity`` command: list, run, export, report.

User mistakes (bad scene files, unknown names, missing runs) print one line
``simparity: error: ...`` and exit with code 2; tracebacks are kept for real bugs.
``run`` exits 0 when every case is ok, n/a or diverged, and 1 when some engine failed
(raised an error); the results computed before and after a failure are kept either way.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simparity.comparisons import library
from simparity.comparisons.engines import DEFAULT_ENGINES, ENGINE_NAMES, check_engine_names, make_engine
from simparity.comparisons.runner import DEFAULT_REPEATS, run_scene
from simparity.comparisons.store import DEFAULT_OUT_ROOT, RunWriter, default_out_dir
from simparity.core.errors import SimparityError
from simparity.core.results import FAILED, REPORT_FILE, case_counts
from simparity.reports.markdown import render
from simparity.reports.store import read_run

EXIT_OK, EXIT_FAILED_CASES, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130
EXPORTABLE = ("mujoco", "pybullet", "pinocchio")


def _engine_list(text: str) -> tuple[str, ...]:
    return tuple(n.strip() for n in text.split(",") if n.strip())


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="simparity",
        description="Run textbook IK and rigid-body methods beside MuJoCo, PyBullet and Pinocchio "
        "on identical scenes; report error, drift and speed.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    sub.add_parser("list", help="list the built-in scenes", description="List the built-in scenes, one per line.")

    run = sub.add_parser(
        "run", help="run scenes on engines and write results.csv and report.md",
        description="Run scenes on engines; write results.csv, run.json and report.md into the output folder.",
    )
    run.add_argument("scenes", nargs="*", metavar="SCENE|FILE",
                     help="built-in scene names or scene files (default: the whole built-in suite)")
    run.add_argument("--engines", type=_engine_list, default=DEFAULT_ENGINES, metavar="A,B,...",
                     help=f"comma-separated engines to run (default: {','.join(DEFAULT_ENGINES)}; "
                     f"known: {','.join(ENGINE_NAMES)})")
    run.add_argument("--out", type=Path, default=None, metavar="DIR",
                     help=f"output folder (default: {DEFAULT_OUT_ROOT}/<UTC date-time>/)")
    run.add_argument("--repeats", type=int, default=DEFAULT_REPEATS, metavar="N",
                     help=f"timed repeats per case, the best is kept (default: {DEFAULT_REPEATS})")

    export = sub.add_parser(
        "export", help="print the model an adapter builds for a scene",
        description="Print the model (MJCF, URDF or Pinocchio's model) an engine is given for a scene.",
    )
    export.add_argument("scene", metavar="SCENE|FILE")
    export.add_argument("--engine", required=True, choices=EXPORTABLE)
    export.add_argument("--integrator", default=None, help="dynamics only (default: the engine's first)")
    export.add_argument("--dt", type=float, default=None, help="dynamics only, [s] (default: the scene's first)")

    report = sub.add_parser("report", help="re-render report.md of a stored run",
                            description="Re-render report.md from a stored run's results.csv and run.json.")
    report.add_argument("run_dir", type=Path, metavar="DIR")
    return parser


def cmd_list(args, out) -> int:
    for name, path in library.builtin_paths().items():
        scene = library.load([str(path)])[0]
        print(f"{name:<28} {scene.kind:<11} reference={scene.reference:<10} {scene.description}", file=out)
    return EXIT_OK


def cmd_run(args, out) -> int:
    if args.repeats < 1:
        raise SimparityError(f"--repeats {args.repeats}: must be at least 1")
    names = check_engine_names(args.engines)
    scenes = library.load(args.scenes or list(library.builtin_paths()))
    engines = [make_engine(n) for n in names]
    out_dir = args.out or default_out_dir()
    if out_dir.exists() and not out_dir.is_dir():
        raise SimparityError(f"--out {out_dir}: exists and is not a folder")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise SimparityError(f"--out {out_dir}: cannot create the folder: {err.strerror}") from None
    writer = RunWriter(out_dir, {e.name: e.version() for e in engines}, " ".join(["simparity"] + sys.argv[1:]), scenes)
    failed = 0
    try:
        for scene in scenes:
            rows = run_scene(scene, engines, make_engine, repeats=args.repeats)
            writer.append(rows)
            counts = case_counts(rows)
            failed += counts[FAILED]
            print(f"{scene.name}: {sum(counts.values())} cases ("
                  + ", ".join(f"{s} {c}" for s, c in counts.items() if c) + ")", file=out)
    except KeyboardInterrupt:
        print(f"interrupted; results so far are in {writer.results_path}", file=out)
        _write_report(out_dir, out)
        return EXIT_INTERRUPTED
    except SimparityError:
        _write_report(out_dir, out)  # keep what was computed, then report the error
        raise
    _write_report(out_dir, out)
    return EXIT_FAILED_CASES if failed else EXIT_OK


def _write_report(out_dir: Path, out) -> None:
    table, info = read_run(out_dir)
    path = Path(out_dir) / REPORT_FILE
    path.write_text(render(table, info), encoding="utf-8")
    print(f"results: {Path(out_dir) / 'results.csv'}\nreport:  {path}", file=out)


def cmd_export(args, out) -> int:
    scene = library.load([args.scene])[0]
    engine = make_engine(args.engine)
    print(engine.export(scene, args.integrator, args.dt), file=out, end="")
    return EXIT_OK


def cmd_report(args, out) -> int:
    _write_report(args.run_dir, out)
    return EXIT_OK


_COMMANDS = {"list": cmd_list, "run": cmd_run, "export": cmd_export, "report": cmd_report}


def main(argv: list[str] | None = None, out=None) -> int:
    """Entry point of the ``simparity`` console script; returns the exit code."""
    out = out or sys.stdout
    args = build_parser().parse_args(argv)
    try:
        return _COMMANDS[args.command](args, out)
    except SimparityError as err:
        print(f"simparity: error: {err}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
