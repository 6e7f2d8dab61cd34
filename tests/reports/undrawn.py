"""Reports built for their text alone: each figure is still made by its figure function (so one that fails, fails the
test), then closed unsaved, save for the few a test names to keep. Saving (SVG and PNG, on a process pool) is most of
a report's time and is what reports/figures.py's tests and the real run of test_report.py look at; the tests of the
Markdown here never read a figure's file."""

import concurrent.futures
import contextlib
import functools
from collections.abc import Iterator
from unittest import mock

from simparity.reports import figure_writer

UNDRAWN_SVG = "<svg></svg>"
"""The SVG text handed back for a figure left unsaved: an empty one, which report.html embeds like any other."""


class _UndrawnWriter:
    """Stands for :class:`reports.figure_writer.FigureWriter`: :meth:`submit` closes the figure and hands back
    :data:`UNDRAWN_SVG`, unless its name is one of ``keep``: that one is saved (SVG and PNG) in this process."""

    def __init__(self, *args, keep: frozenset[str] = frozenset(), **kwargs) -> None:
        self._keep = keep

    def __enter__(self) -> "_UndrawnWriter":
        return self

    def __exit__(self, *exc) -> None:
        return None

    def submit(self, fig, folder, name) -> concurrent.futures.Future:
        done: concurrent.futures.Future = concurrent.futures.Future()
        if name in self._keep:
            done.set_result(figure_writer.save(fig, folder, name))
        else:
            figure_writer.plt.close(fig)
            done.set_result(UNDRAWN_SVG)
        return done


@contextlib.contextmanager
def undrawn_figures(keep: frozenset[str] = frozenset()) -> Iterator[None]:
    """Within it, a report (:func:`reports.content.build`) makes its figures but saves only those named in ``keep``."""
    with mock.patch.object(figure_writer, "FigureWriter", functools.partial(_UndrawnWriter, keep=keep)):
        yield
