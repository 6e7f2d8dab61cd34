"""Where a run is stored when no folder is named: ``simparity-results/<UTC date-time>/``."""

from __future__ import annotations

import datetime as dt
from pathlib import Path

DEFAULT_OUT_ROOT = Path("simparity-results")
"""Default parent folder of runs: each run goes to ``simparity-results/<UTC time>/``."""


def default_out_dir() -> Path:
    """A new folder ``simparity-results/<UTC date-time>[-k]/`` that does not exist yet."""
    stamp = DEFAULT_OUT_ROOT / dt.datetime.now(dt.timezone.utc).strftime("%Y%m%d-%H%M%S")
    candidate, k = stamp, 1
    while candidate.exists():
        candidate, k = stamp.with_name(f"{stamp.name}-{k}"), k + 1
    return candidate
