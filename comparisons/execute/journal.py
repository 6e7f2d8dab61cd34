"""The finished cases of a run, kept as they finish so an interrupted run resumes where it stopped.

Each finished case is one file ``cases/<key digest>.pickle`` in the run's folder (written to a
temporary name and renamed, so a kill leaves no half-written case), holding its :class:`CaseKey`
and :class:`CaseOutcome`; reading one rebuilds only simparity's data types and NumPy arrays, never
runs code a file names. A case that did not finish (its worker crashed, hung or ran out of memory)
is not kept: a resumed run tries it again. ``resume.json`` holds what the run was asked to do. A run that
finishes with every case done removes its kept cases (they are in ``results.csv``; ~15 MB for the default
suite).
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import fcntl
import json
import os
import pickle
import sys
from pathlib import Path
from typing import cast

from simparity.comparisons.execute.cases import CaseKey, CaseOutcome
from simparity.core.model.errors import SimparityError, one_line
from simparity.core.model.json_input import COUNT, TEXT, JSONInputError, Shape, list_of, read_json, record

CASES_FOLDER = "cases"
RESUME_FILE = "resume.json"
LOCK_FILE = ".lock"


NUMPY_GLOBALS = frozenset({
    ("numpy", "ndarray"), ("numpy", "dtype"),
    ("numpy._core.multiarray", "_reconstruct"), ("numpy.core.multiarray", "_reconstruct"),
    ("numpy._core.multiarray", "scalar"), ("numpy.core.multiarray", "scalar"),
    ("numpy._core.numeric", "_frombuffer"), ("numpy.core.numeric", "_frombuffer"),
})
"""What NumPy's arrays, dtypes and scalars are rebuilt from (NumPy 2 names, and 1.x's)."""


class _CaseUnpickler(pickle.Unpickler):
    """Reads a kept case and nothing else: simparity's dataclasses and enums (their constructors only store
    values) and NumPy's arrays. Any other global a file names (``os.system``, a simparity function) is
    refused, so a tampered or foreign case file is computed again instead of running code."""

    def find_class(self, module: str, name: str):
        if (module, name) in NUMPY_GLOBALS:
            return super().find_class(module, name)
        if module.startswith("simparity.") and "." not in name:
            try:
                found = super().find_class(module, name)
            except (ImportError, AttributeError):  # kept before a module moved: the type by its name alone
                found = _kept_types().get(name)
            if _is_kept_type(found):
                return found
        raise pickle.UnpicklingError(f"{module}.{name} is not part of a kept case")


def _is_kept_type(found) -> bool:
    return isinstance(found, type) and (dataclasses.is_dataclass(found) or issubclass(found, enum.Enum))


def _kept_types() -> dict[str, type]:
    """simparity's dataclasses and enums by class name, from its loaded modules (a name two classes share is
    left out): a kept case names its types by module path, and a module may move between versions."""
    found: dict[str, list[type]] = {}
    for module_name, module in list(sys.modules.items()):
        if module_name.startswith("simparity.") and module is not None:
            for value in list(vars(module).values()):
                if _is_kept_type(value) and value.__module__ == module_name:
                    found.setdefault(value.__name__, []).append(value)
    return {name: types[0] for name, types in found.items() if len(types) == 1}


class Journal:
    """The finished cases of the run in ``run_dir``."""

    def __init__(self, run_dir: Path) -> None:
        self.folder = Path(run_dir) / CASES_FOLDER
        self.folder.mkdir(parents=True, exist_ok=True)
        self.unfinished = 0
        """Cases offered to :meth:`save` that did not finish (a resumed run tries them again)."""
        self.unreadable = 0
        """Kept cases :meth:`load` could not read (damaged, foreign, or of another simparity): computed again."""

    def _path(self, key: CaseKey) -> Path:
        return self.folder / f"{key.digest()}.pickle"

    def __contains__(self, key: CaseKey) -> bool:
        """Whether an outcome is kept under ``key`` (read or not)."""
        return self._path(key).is_file()

    def load(self, key: CaseKey) -> CaseOutcome | None:
        """The outcome stored under ``key``, or None (never stored, or unreadable: computed again)."""
        try:
            with open(self._path(key), "rb") as handle:
                stored_key, outcome = _CaseUnpickler(handle).load()
        except FileNotFoundError:
            return None
        except (OSError, EOFError, pickle.UnpicklingError, ValueError, TypeError, AttributeError, KeyError,
                IndexError, ImportError):
            self.unreadable += 1
            return None
        # by digest: a key's dt is NaN for every case but a time step's (IK, kinematics, joint dynamics), and NaN != NaN
        same = isinstance(stored_key, CaseKey) and stored_key.digest() == key.digest()
        return outcome if same and isinstance(outcome, CaseOutcome) else None

    def save(self, key: CaseKey, outcome: CaseOutcome) -> None:
        """Keep a finished case (not one that did not finish: a resumed run tries it again)."""
        if outcome.harness_failure:
            self.unfinished += 1
            return
        path = self._path(key)
        partial = path.with_suffix(".partial")
        with open(partial, "wb") as handle:
            pickle.dump((key, outcome), handle, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(partial, path)

    def clear(self) -> None:
        """Forget every kept case (a new run in a folder that held one: ``--force``)."""
        for path in self.folder.iterdir():
            if path.suffix in (".pickle", ".partial"):
                path.unlink()

    def remove(self) -> None:
        """Forget every kept case and the folder: the run finished, nothing is left to resume."""
        self.clear()
        self.folder.rmdir()

    def __len__(self) -> int:
        return sum(1 for _ in self.folder.glob("*.pickle"))


def write_request(run_dir: Path, request: dict) -> None:
    """Record what a run was asked to do (JSON-able), for ``simparity run --resume``."""
    (Path(run_dir) / RESUME_FILE).write_text(json.dumps(request, indent=2) + "\n", encoding="utf-8")


MAX_REQUEST_BYTES = 10_000_000
"""Largest ``resume.json`` read [bytes]: a request lists its scenes by path or name (1,000 scene files: ~200 kB)."""

_COUNT_ABOVE_0 = Shape("a whole number > 0", lambda v: COUNT.accepts(v) and v > 0)  # type: ignore[operator]
REQUEST_SHAPE = record(
    "a table (JSON object): the request a run wrote",
    scenes=list_of(TEXT), suite=Shape("text or null", lambda v: v is None or isinstance(v, str)),
    engines=list_of(TEXT), repeats=COUNT, quick=Shape("a boolean", lambda v: isinstance(v, bool)),
    max_steps=_COUNT_ABOVE_0, max_samples=_COUNT_ABOVE_0, max_joints=_COUNT_ABOVE_0, transform=list_of(TEXT))
"""What each key of ``resume.json`` holds (:func:`comparisons.cli.main._request` writes it)."""


def read_request(run_dir: Path) -> dict:
    """What the run in ``run_dir`` was asked to do; a folder without it is a one-line error."""
    path = Path(run_dir) / RESUME_FILE
    if not path.exists():
        raise SimparityError(f"--resume {one_line(run_dir)}: no {RESUME_FILE} there (allowed: the folder of a run "
                             "started by 'simparity run')")
    try:  # bounded in size, depth and integer length, no NaN, no key twice: json_input.read_json
        request = read_json(path, MAX_REQUEST_BYTES, "the file a run wrote")
    except JSONInputError as err:
        raise SimparityError(f"--resume {one_line(path)}: {err}") from None
    problem = REQUEST_SHAPE.problem(request)
    if problem:
        raise SimparityError(f"--resume {one_line(path)}: {problem}")
    return cast(dict, request)  # REQUEST_SHAPE accepts a table (JSON object) only


@contextlib.contextmanager
def run_lock(run_dir: Path):
    """Hold the run folder for this process: a second run (or ``--resume``) on the same folder while one is
    writing it is a one-line error, not two runs interleaving their files. Released when the block ends or
    the process dies."""
    handle = open(Path(run_dir) / LOCK_FILE, "a+b")
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise SimparityError(f"--out {one_line(run_dir)}: another simparity run is writing this folder (allowed: "
                                 "wait for it to end, or another folder)") from None
        yield
    finally:
        handle.close()
