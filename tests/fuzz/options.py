"""Command-line options that mean nothing (issue #39, sections 1 and 2): comma lists ('', ',', 'a,', repeats),
every numeric option at nan, inf, -1, 0 and huge, paths that cannot be read or written (a folder where a file is
meant, /dev/full, /proc, missing parents, ''), ``--engines module:attr`` naming what is not an engine. ``run``
options are tried on a scene of 20 steps; ``check``, ``report`` and ``export`` options on the stored run."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import numpy as np

from tests.fuzz.oracle import EITHER, FAILS, REFUSED, VALID, VALID_OR_FAILS, Base, Call, Case

RUN_FAMILY, CHECK_FAMILY = "run_options", "check_options"
DRAWN_NUMBERS = 4
"""Values of :data:`NUMBERS` each numeric option of ``run`` is tried with (drawn per option), besides its own."""
DRAWN_PATHS = 4
"""Paths of :data:`IN_PATHS` each input option is tried with (drawn per option)."""

LISTS = ("", ",", "{name},", "{name},{name}")
"""Comma lists with an empty or a repeated name ({name}: a name the option knows)."""
NOT_ENGINES = ("nosuch", "os:path", "json:dumps", "math:pi", "tests.fuzz.oracle:Base", "nosuchmodule:Engine", "math:")
"""``--engines`` entries that are no engine: unknown names, module attributes that are no engine class."""
NUMBERS = ("nan", "inf", "-inf", "-1", "0", "1e308", "1" + "0" * 30)
"""Every numeric option is tried with each (an int option's nan and 1e308 are argparse's refusals)."""

HUGE = "1" + "0" * 30
RUN_NUMBERS: dict[str, dict[str, frozenset[int]]] = {
    "--repeats": {"0": VALID, HUGE: REFUSED},
    "--jobs": {HUGE: REFUSED},
    "--case-timeout": {"1e308": EITHER, HUGE: EITHER, "1e-9": FAILS},
    "--case-memory": {"1e308": REFUSED, HUGE: REFUSED, "1e-9": REFUSED},
    "--max-steps": {HUGE: EITHER},
    "--max-samples": {HUGE: EITHER},
    "--max-joints": {HUGE: EITHER},
}
"""``run``'s numeric options: every value of :data:`NUMBERS` (and the extra ones here) is refused unless said here
(1e-9 GiB of memory: every case would die, which the issue asks refused; 1e-9 s: every case times out, a run of
failed cases, exit 1, or refused). Valid values run the tiny scene (~5 s of CPU each): --repeats 0 (one cold call), a
timeout or step limit beyond any run."""


def _out_paths(folder: Path) -> dict[str, tuple[str, frozenset[int]]]:
    """Paths an output option may be pointed at: name -> (path, exit codes accepted)."""
    (folder / "a-folder").mkdir(exist_ok=True)
    return {"a folder": (str(folder / "a-folder"), REFUSED), "/dev/full": ("/dev/full", REFUSED),
            "/proc": ("/proc/self/fuzz", REFUSED), "''": ("", REFUSED), "/": ("/", REFUSED),
            "missing parents": (str(folder / "no" / "such" / "file"), EITHER)}


OUT_PATHS = ("a folder", "/dev/full", "/proc", "''", "/", "missing parents")
IN_PATHS = ("''", "/", "/proc", "an empty folder", "a missing folder", "a file")


def _in_path(kind: str, folder: Path, base: Base) -> str:
    """A path an input option may be pointed at that holds no run (or no file of its kind)."""
    if kind == "an empty folder":
        (folder / "empty").mkdir(exist_ok=True)
        return str(folder / "empty")
    return {"''": "", "/": "/", "/proc": "/proc/self", "a missing folder": str(folder / "missing"),
            "a file": str(base.run_dir / "results.csv")}[kind]


def _run(options: tuple[str, ...], folder: Path, base: Base, names: tuple[str, ...], keeps: bool = False,
         subprocess: bool = False) -> Call:
    out = folder / "out"
    argv = ("run", str(base.scene), "--engines", "core", "--jobs", "1", "--quick", "--out", str(out), *options)
    return Call(argv=argv, names=names, keeps=(out / "results.csv",) if keeps else (), subprocess=subprocess)


def _run_option(option: str, value: str, folder: Path, base: Base) -> Call:
    return _run((option, value), folder, base, (option,))


def _run_engines(value: str, folder: Path, base: Base) -> Call:
    argv = ("run", str(base.scene), "--engines", value, "--jobs", "1", "--quick", "--out", str(folder / "out"))
    return Call(argv=argv, names=("--engines", value.split(":")[0] or "--engines"))


def _run_output(option: str, kind: str, folder: Path, base: Base, subprocess: bool = False) -> Call:
    path = _out_paths(folder)[kind][0]
    return _run(("--check", "--allow-unbounded", option, path), folder, base, (option,), keeps=True,
                subprocess=subprocess)


def _run_out(kind: str, folder: Path, base: Base) -> Call:
    path = _out_paths(folder)[kind][0]
    argv = ("run", str(base.scene), "--engines", "core", "--jobs", "1", "--quick", "--out", path)
    return Call(argv=argv, names=("--out",))


def _check(options: tuple[str, ...], names: tuple[str, ...], folder: Path, base: Base) -> Call:
    return Call(argv=("check", str(base.run_dir), *options), names=names)


def _check_output(option: str, kind: str, folder: Path, base: Base) -> Call:
    return _check((option, _out_paths(folder)[kind][0]), (option,), folder, base)


def _check_input(option: str, kind: str, folder: Path, base: Base, extra: tuple[str, ...] = ()) -> Call:
    path = _in_path(kind, folder, base)
    return _check((*extra, option, path), (option,) + ((path,) if path else ()), folder, base)


def _bless_spread(kind: str, folder: Path, base: Base) -> Call:
    path = _in_path(kind, folder, base)
    return _check(("--bless", str(folder / "blessed.toml"), "--spread", path), ("--spread",) + ((path,) if path
                                                                                               else ()), folder, base)


def _command_dir(command: str, kind: str, folder: Path, base: Base) -> Call:
    path = _in_path(kind, folder, base)
    return Call(argv=(command, path), names=(path or "''", "run.json", "results.csv", command))


def _export_dt(value: str, folder: Path, base: Base) -> Call:
    return Call(argv=("export", str(base.scene), "--engine", "mujoco", "--dt", value), names=("--dt",))


def _resume(kind: str, folder: Path, base: Base) -> Call:
    path = _in_path(kind, folder, base)
    return Call(argv=("run", "--resume", path), names=("--resume",))


def run_cases(rng: np.random.Generator) -> list[Case]:
    """``run``'s options (and ``export --dt``): each numeric option at :data:`DRAWN_NUMBERS` values drawn from
    :data:`NUMBERS` and its own; comma lists; engines that are not; output paths; ``--resume`` folders."""
    found = []
    for option, special in RUN_NUMBERS.items():
        drawn = [str(v) for v in rng.choice(NUMBERS, DRAWN_NUMBERS, replace=False)]
        for value in dict.fromkeys(drawn + list(special)):
            found.append(Case(RUN_FAMILY, f"run {option} {value}", partial(_run_option, option, value),
                              special.get(value, REFUSED)))
    for option, name in (("--transform", "translate"), ("--engines", "core")):
        for pattern in LISTS:
            value = pattern.format(name=name)
            found.append(Case(RUN_FAMILY, f"run {option} {value!r}", partial(_run_option, option, value)))
    found += [Case(RUN_FAMILY, f"run --transform {value!r}", partial(_run_option, "--transform", value))
              for value in ("nosuch", "translate,nosuch")]
    # a module that does not import is an engine unavailable here (n/a rows with the reason, like a missing library):
    # exit 1 or a refusal; an attribute that is no engine class is refused
    found += [Case(RUN_FAMILY, f"run --engines {value}", partial(_run_engines, value),
                   FAILS if value.startswith("nosuchmodule:") else REFUSED) for value in NOT_ENGINES]
    # never --out /: a simparity that does not refuse it writes a run into the root folder
    found += [Case(RUN_FAMILY, f"run --out {kind}", partial(_run_out, kind)) for kind in ("/dev/full", "/proc", "''")]
    drawn = [str(k) for k in rng.choice([k for k in OUT_PATHS if k != "missing parents"], 2, replace=False)]
    for option in ("--junit", "--summary"):
        for kind in drawn:  # each costs a run where the path is only tried when the run is done
            found.append(Case(RUN_FAMILY, f"run --check {option} {kind}", partial(_run_output, option, kind)))
    found.append(Case(RUN_FAMILY, "run --check --junit a folder (subprocess)",
                      partial(_run_output, "--junit", "a folder", subprocess=True)))
    found += [Case(RUN_FAMILY, f"export --dt {value}", partial(_export_dt, value))
              for value in NUMBERS[:-1] + ("5e-324",)]
    found += [Case(RUN_FAMILY, f"run --resume {kind}", partial(_resume, kind)) for kind in IN_PATHS]
    return found


def check_cases(rng: np.random.Generator) -> list[Case]:
    """``check``'s and ``report``'s options: output paths, input folders and files (:data:`DRAWN_PATHS` of
    :data:`IN_PATHS` each, drawn), ``--baseline-rel``, engine lists, ``--explain``."""
    found = []
    for option in ("--junit", "--summary", "--bless"):
        for kind in OUT_PATHS:
            found.append(Case(CHECK_FAMILY, f"check {option} {kind}", partial(_check_output, option, kind),
                              EITHER if kind == "missing parents" else REFUSED))

    def drawn() -> list[str]:
        return [str(kind) for kind in rng.choice(IN_PATHS, DRAWN_PATHS, replace=False)]

    found += [Case(CHECK_FAMILY, f"check --baseline {kind}", partial(_check_input, "--baseline", kind))
              for kind in drawn()]
    found += [Case(CHECK_FAMILY, f"check --tolerances {kind}", partial(_check_input, "--tolerances", kind))
              for kind in drawn()]
    found += [Case(CHECK_FAMILY, f"check --baseline latest --history {kind}",
                   partial(_check_input, "--history", kind, extra=("--baseline", "latest"))) for kind in drawn()]
    found += [Case(CHECK_FAMILY, f"check --bless --spread {kind}", partial(_bless_spread, kind)) for kind in drawn()]
    found += [Case(CHECK_FAMILY, f"{command} DIR {kind}", partial(_command_dir, command, kind))
              for command in ("check", "report") for kind in drawn()]
    found += [Case(CHECK_FAMILY, f"check --baseline-rel {value}", partial(_baseline_rel, value))
              for value in ("nan", "inf", "-1", "-inf")]
    found += [Case(CHECK_FAMILY, f"check --baseline-rel {value} (valid)", partial(_baseline_rel, value),
                   VALID_OR_FAILS) for value in ("0", "1e308")]
    for option, name in (("--check-engines", "core"), ("--require-engines", "core")):
        for pattern in LISTS[:3] + ("nosuch", "core,nosuch"):
            value = pattern.format(name=name)
            # an engine required and not in the run fails the check (exit 1, documented); one that exists nowhere
            # may be refused as well
            accept = FAILS if option == "--require-engines" and "nosuch" in value else REFUSED
            found.append(Case(CHECK_FAMILY, f"check {option} {value!r}", partial(_check, (option, value), (option,)),
                              accept))
    found += [Case(CHECK_FAMILY, f"check --explain {value!r}", partial(_check, ("--explain", value), ("--explain",)))
              for value in ("", "nosuch")]
    found.append(Case(CHECK_FAMILY, "control: check --bless a new file",
                      partial(_check, ("--bless", "blessed.toml"), ()), VALID))
    return found


def _baseline_rel(value: str, folder: Path, base: Base) -> Call:
    return _check(("--baseline", str(base.run_dir), "--baseline-rel", value), ("--baseline-rel",), folder, base)
