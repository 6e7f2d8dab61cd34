"""A question asked in a forked child: for engine code that may abort the process (PyBullet's parsers do on some
files), so that a crash is an answer, never the end of simparity."""

from __future__ import annotations

import os
from collections.abc import Callable

ANSWER_BYTES = 4000
"""The longest answer a child sends back."""


def asked_in_child(question: Callable[[], str]) -> tuple[str, int | None]:
    """(the text ``question`` returned in a forked child, None), or ("", the signal that ended the child). An exception
    in the child is its answer as text; the child leaves without running any of the parent's cleanup."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:
        answer = ""
        try:
            answer = question()
        except BaseException as error:  # noqa: BLE001 - every way out of the child is an answer
            answer = " ".join(str(error).split()) or type(error).__name__
        finally:
            os.write(write, answer.encode()[:ANSWER_BYTES])
            os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as reader:
        answer = reader.read().decode(errors="replace")
    _, status = os.waitpid(pid, 0)
    return (answer, None) if not os.WIFSIGNALED(status) else ("", os.WTERMSIG(status))
