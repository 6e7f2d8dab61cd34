"""Writing a stored run: ``results.csv`` (appended scene by scene) and ``run.json``."""

from __future__ import annotations

import datetime as dt
import json
import os
import platform
import subprocess
from pathlib import Path

import pandas as pd

from simparity.core.results import COLUMNS, RESULTS_FILE, RUN_INFO_FILE, SCHEMA_VERSION, ResultRow

DEFAULT_OUT_ROOT = Path("simparity-results")
"""Default parent folder of runs: each run goes to ``simparity-results/<UTC time>/``."""


def default_out_dir() -> Path:
    """A new folder ``simparity-results/<UTC date-time>[-k]/`` that does not exist yet."""
    stamp = DEFAULT_OUT_ROOT / dt.datetime.now(dt.timezone.utc).strftime("%Y%m%d-%H%M%S")
    candidate, k = stamp, 1
    while candidate.exists():
        candidate, k = stamp.with_name(f"{stamp.name}-{k}"), k + 1
    return candidate


def git_commit() -> str:
    """``git describe``-style commit of the project source (``unknown`` outside a checkout)."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "describe", "--always", "--dirty", "--abbrev=12"],
            cwd=here, capture_output=True, text=True, timeout=10,
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return out.stdout.strip() if out.returncode == 0 and out.stdout.strip() else "unknown"


def machine() -> dict:
    return {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
    }


class RunWriter:
    """Appends rows to ``results.csv`` as they are produced, so nothing computed is lost."""

    def __init__(self, out_dir: Path, engine_versions: dict[str, str], command: str, scenes: list) -> None:
        self.out_dir = Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.results_path = self.out_dir / RESULTS_FILE
        pd.DataFrame(columns=list(COLUMNS)).to_csv(self.results_path, index=False)
        info = {
            "schema_version": SCHEMA_VERSION,
            "created_utc": dt.datetime.now(dt.timezone.utc).isoformat(timespec="seconds"),
            "command": command,
            "git_commit": git_commit(),
            "machine": machine(),
            "engine_versions": engine_versions,
            "scenes": {
                s.name: {"kind": s.kind, "description": s.description, "reference": s.reference, "source": s.source,
                         "suites": list(s.suites)}
                for s in scenes
            },
        }
        (self.out_dir / RUN_INFO_FILE).write_text(json.dumps(info, indent=2) + "\n", encoding="utf-8")

    def append(self, rows: list[ResultRow]) -> None:
        frame = pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))
        frame.to_csv(self.results_path, mode="a", header=False, index=False, float_format="%.17g")
