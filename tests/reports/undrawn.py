"""Reports built for their text alone: each figure is still made by its figure function (so one that fails, fails the
test), then closed unsaved. Saving (SVG and PNG, on a process pool) is most of a report's time and is what
reports/figures.py's tests, the real runs of test_report.py and the sweep file's end-to-end run look at; the tests of
the Markdown here never read a figure's file."""

import concurrent.futures
import contextlib
from collections.abc import Iterator
from unittest import mock

from simparity.reports import figures


class _UndrawnWriter:
    """Stands for :class:`reports.figures.FigureWriter`: :meth:`submit` closes the figure and hands back its SVG text
    as empty."""

    def __init__(self, *args, **kwargs) -> None:
        pass

    def __enter__(self) -> "_UndrawnWriter":
        return self

    def __exit__(self, *exc) -> None:
        return None

    def submit(self, fig, folder, name) -> concurrent.futures.Future:
        figures.plt.close(fig)
        done: concurrent.futures.Future = concurrent.futures.Future()
        done.set_result("")
        return done


@contextlib.contextmanager
def undrawn_figures() -> Iterator[None]:
    """Within it, a report (:func:`reports.content.build`) makes its figures but saves none."""
    with mock.patch.object(figures, "FigureWriter", _UndrawnWriter):
        yield
