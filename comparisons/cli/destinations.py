"""Where a command writes (``--out``, ``--junit``, ``--summary``, ``--bless``, ``bench --out``): each destination
probed before the work starts, cheaply and without writing anything, and each later write's failure (a full device,
a folder removed meanwhile) one line naming the option and what went wrong."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from simparity.core.model.errors import SimparityError, one_line


def _reason(err: Exception) -> str:
    return getattr(err, "strerror", None) or str(err)


def writable_folder(option: str, folder: Path) -> Path:
    """``folder`` once a file could be made in it (and removed), the folders the probe had to create removed again:
    a path through a file, a read-only file system, a name the system rejects are refused here in one line, before
    any work, and a refused or failed run leaves no folder behind."""
    created: list[Path] = []
    try:
        if folder.exists() and not folder.is_dir():
            raise SimparityError(f"{option} {one_line(folder)}: exists and is not a folder (allowed: a folder you "
                                 "can write)")
        created = [p for p in (folder, *folder.parents) if not p.exists()]
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except (OSError, ValueError) as err:  # ValueError: a NUL byte in the name
        raise SimparityError(f"{option} {one_line(folder)}: cannot write in that folder: {_reason(err)} (allowed: "
                             "a folder you can write)") from None
    finally:
        for path in created:  # deepest first
            try:
                path.rmdir()
            except OSError:
                pass
    return folder


def writable_file(option: str, path: Path) -> Path:
    """``path`` once it could be opened for appending (nothing written or truncated; a file the probe created is
    removed again): a folder, a missing or read-only parent folder, a name the system rejects are refused here in
    one line, before any work. A full device is found only by writing: :func:`write_file` says so."""
    try:
        if path.is_dir():
            raise SimparityError(f"{option} {one_line(path)}: is a folder (allowed: a file path in a folder you can "
                                 "write)")
        existed = path.exists()
        os.close(os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NONBLOCK, 0o666))
        if not existed:
            path.unlink()
    except (OSError, ValueError) as err:
        raise SimparityError(f"{option} {one_line(path)}: cannot write: {_reason(err)} (allowed: a file path in a "
                             "folder you can write)") from None
    return path


def write_file(option: str, path: Path, text: str, append: bool = False) -> None:
    """Write ``text`` to ``path`` (appended when ``append``); a failure is one line naming ``option``."""
    try:
        with open(path, "a" if append else "w", encoding="utf-8") as handle:
            handle.write(text)
    except (OSError, ValueError) as err:
        raise SimparityError(f"{option} {one_line(path)}: cannot write: {_reason(err)} (allowed: a file path you can "
                             "write)") from None
