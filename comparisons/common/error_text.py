"""An exception as one line of text: what a failed row, a broken plugin or a probe says."""

from __future__ import annotations

import traceback

from simparity.core.model.errors import PluginError


def error_text(err: BaseException) -> str:
    """``Type: message at file:line`` of an exception, on one line; an engine standing in for a broken one raises
    a :class:`PluginError` whose message says all (where it was raised is simparity's, not the engine's)."""
    if isinstance(err, PluginError):
        return str(err).replace("\n", " ")
    where = traceback.extract_tb(err.__traceback__)[-1] if err.__traceback__ else None
    at = f" at {where.filename.rsplit('/', 1)[-1]}:{where.lineno}" if where else ""
    return f"{type(err).__name__}: {err}{at}".replace("\n", " ")
