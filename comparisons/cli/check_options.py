"""The check's options (``run --check`` and ``check``), refused before any work when they mean nothing or cannot
be reached: given where no check runs, ``--baseline-rel`` out of range or without ``--baseline``, a ``--baseline``
that is no run folder, ``--junit`` or ``--summary`` where no file can be written; and the baseline's rows."""

from __future__ import annotations

import math
from pathlib import Path

from simparity.comparisons.cli.destinations import writable_file
from simparity.comparisons.gate.history import history_path, latest_before, run_table
from simparity.core.model.errors import SimparityError, echo, one_line
from simparity.reports.store import read_run

CHECK_OPTIONS = ("tolerances", "check_engines", "require_engines", "allow_unbounded", "verbose", "baseline",
                 "baseline_rel", "junit", "summary")
"""The options of the check (:func:`parser._add_check_options`): on ``run``, they act only with ``--check``."""


def refuse_check_options(args, names: tuple[str, ...], where: str, allowed: str) -> None:
    """Refuse the check's options (``names`` of them) where no check runs (a run without ``--check``, ``check
    --bless`` or ``--explain``): they would be read and silently do nothing."""
    given = [name for name in names if getattr(args, name) not in (None, False)]
    if given:
        flags = ", ".join("--" + name.replace("_", "-") for name in given)
        raise SimparityError(f"{flags} {where}: they act only on the check (allowed: {allowed})")


def checked_check_options(args) -> None:
    """Refuse, before any work, the check's options that mean nothing or cannot be reached: --baseline-rel without
    --baseline or not a finite number >= 0, --baseline that is no folder, --junit or --summary where no file can
    be written."""
    if args.baseline_rel is not None:
        if args.baseline is None:
            raise SimparityError(f"--baseline-rel {args.baseline_rel:g} without --baseline (allowed: add --baseline "
                                 "DIR|latest, or drop --baseline-rel)")
        if not (math.isfinite(args.baseline_rel) and args.baseline_rel >= 0):
            raise SimparityError(f"--baseline-rel {args.baseline_rel:g}: out of range (allowed: a finite relative "
                                 "change >= 0; 0: any change is a move)")
    if args.baseline is not None and args.baseline != "latest":
        baseline_folder(args.baseline)
    for option, path in (("--junit", args.junit), ("--summary", args.summary)):
        if path is not None:
            writable_file(option, path)


def baseline_folder(option: str) -> Path:
    """``--baseline``'s folder, refused in one line when it is no folder at all (what a folder holds is
    :func:`reports.store.read_run`'s to check)."""
    allowed = "allowed: the folder of a stored run, or 'latest'"
    if not option.strip():
        raise SimparityError(f"--baseline {echo(option)}: no folder named ({allowed})")
    path = Path(option)
    try:
        if not path.exists():
            raise SimparityError(f"--baseline {one_line(option)}: no such folder ({allowed})")
        if not path.is_dir():
            raise SimparityError(f"--baseline {one_line(option)}: a file, not a folder ({allowed})")
    except (OSError, ValueError) as err:  # a name the system rejects: too long, a NUL byte
        raise SimparityError(f"--baseline {one_line(option)}: {getattr(err, 'strerror', None) or err} "
                             f"({allowed})") from None
    return path


def baseline_run(option: str):
    """(results table, run information) of the run in ``--baseline``'s folder; what is wrong with it is one line
    naming the option."""
    try:
        return read_run(baseline_folder(option))
    except SimparityError as err:
        if str(err).startswith("--baseline "):
            raise
        raise SimparityError(f"--baseline {one_line(option)}: {err}") from None


def baseline_table(option: str, run_dir: Path, profile: str, history_option: str | None):
    """The baseline's rows: a stored run's folder, or ``latest``, the latest earlier run of ``profile`` (this run's)
    in the history; a baseline of another profile is refused (its rows are of other time steps and horizons)."""
    if option == "latest":
        path = history_path(history_option)
        run_id, _ = latest_before(path, run_dir.resolve(), profile)  # of this profile, or of none recorded
        return run_table(path, run_id)
    table, info = baseline_run(option)
    if profile and info.profile and info.profile != profile:
        raise SimparityError(f"--baseline {one_line(option)}: a {info.profile}-profile run, this one is {profile} "
                             f"(allowed: a baseline of the {profile} profile; its rows have other time steps and "
                             "horizons)")
    return table
