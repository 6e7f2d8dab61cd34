"""Writing the report's figures as SVG and PNG: in this process, or for a report of many figures on a pool of
processes while the report goes on.

Kept apart from the drawing (:mod:`reports.figures`) so that a pool's process, a fresh interpreter, imports matplotlib
and this module only (not pandas nor the rest of simparity) before its first figure: ~0.5 s of CPU less per process.
Both modules set matplotlib the same way (:func:`headless`), so a figure gives the same SVG text wherever it is
written.
"""

from __future__ import annotations

import concurrent.futures
import io
import multiprocessing
import os
import pickle
import signal
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
matplotlib.rcParams["svg.hashsalt"] = "simparity"  # the same figure gives the same SVG text
import matplotlib.pyplot as plt  # noqa: E402

from simparity.core.runtime.processes import die_with_parent  # noqa: E402


def save(fig, folder: Path, name: str) -> str:
    """Write ``name.svg`` and ``name.png`` into ``folder``; return the SVG text (for embedding)."""
    folder.mkdir(parents=True, exist_ok=True)
    buffer = io.StringIO()
    fig.savefig(buffer, format="svg", metadata={"Date": None})
    svg = buffer.getvalue()
    (folder / f"{name}.svg").write_text(svg, encoding="utf-8")
    fig.savefig(folder / f"{name}.png", dpi=100)
    plt.close(fig)
    return svg


def _save_pickled(pickled: bytes, folder: Path, name: str) -> str:
    return save(pickle.loads(pickled), folder, name)


def _figure_worker(parent: int) -> None:
    """A figure process: Ctrl-C is its parent's to handle (no traceback of its own), and it dies with its parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent)


IN_PROCESS_FIGURES_MAX = 8
"""A report of at most this many figures writes them in this process, without the pool. Measured on 2 CPUs: a
figure takes ~0.5 s of CPU to write (SVG and PNG); a pool's process starts as a fresh interpreter that imports
matplotlib and simparity, ~1.5 s of CPU each before its first figure, so below ~8 figures two processes save less
wall time than they cost to start, and all their start-up CPU is extra (a report of one scene: ~3 CPU-s of ~6)."""


class WrittenFigure:
    """A figure handed to :class:`FigureWriter`: :meth:`result` is its SVG text, written in this process when the
    writer has not given it to its pool (then it is written at the latest when the writer closes)."""

    def __init__(self, fig, folder: Path, name: str) -> None:
        self._fig, self._folder, self._name = fig, folder, name
        self._future: concurrent.futures.Future | None = None
        self._svg: str | None = None

    def hand_to(self, pool: concurrent.futures.ProcessPoolExecutor) -> None:
        """Write it on ``pool``'s processes instead."""
        pickled = pickle.dumps(self._fig)
        plt.close(self._fig)
        self._fig = None
        self._future = pool.submit(_save_pickled, pickled, self._folder, self._name)

    def result(self) -> str:
        if self._future is not None:
            return self._future.result()
        if self._svg is None:
            self._svg = save(self._fig, self._folder, self._name)
            self._fig = None
        return self._svg

    def discard(self) -> None:
        """Let the figure go unwritten (the report failed)."""
        if self._fig is not None:
            plt.close(self._fig)
            self._fig = None


class FigureWriter:
    """Writes figures while the report goes on (saving, which draws each figure twice, as SVG and PNG, is most of a
    report's time: 12 s of 17 s for the default suite's figures on one CPU, when it drew 51). Use as a context
    manager; :meth:`submit` returns the figure's :class:`WrittenFigure`. The first ``in_process_max`` figures
    (:data:`IN_PROCESS_FIGURES_MAX`) wait; the one after them starts a pool of one process per CPU (``workers``), which
    writes them all and every later one; a report that ends before writes its few figures in this process. One
    CPU: always in this process."""

    def __init__(self, workers: int | None = None, in_process_max: int = IN_PROCESS_FIGURES_MAX) -> None:
        self._workers = max(1, os.cpu_count() or 1) if workers is None else workers
        self._in_process_max = in_process_max
        self._pool: concurrent.futures.ProcessPoolExecutor | None = None
        self._waiting: list[WrittenFigure] = []

    def __enter__(self) -> "FigureWriter":
        return self

    def __exit__(self, *exc) -> None:
        failed = exc[0] is not None
        try:
            for figure in self._waiting:
                figure.discard() if failed else figure.result()
        finally:  # a figure that cannot be written still lets the pool's processes go
            self._waiting = []
            if self._pool is not None:
                self._pool.shutdown(wait=True, cancel_futures=failed)

    def submit(self, fig, folder: Path, name: str) -> WrittenFigure:
        folder.mkdir(parents=True, exist_ok=True)
        figure = WrittenFigure(fig, folder, name)
        if self._pool is None and self._workers > 1 and len(self._waiting) >= self._in_process_max:
            self._pool = concurrent.futures.ProcessPoolExecutor(
                self._workers, mp_context=multiprocessing.get_context("spawn"), initializer=_figure_worker,
                initargs=(os.getpid(),))
            for waiting in self._waiting:
                waiting.hand_to(self._pool)
            self._waiting = []
        if self._pool is not None:
            figure.hand_to(self._pool)
        else:
            self._waiting.append(figure)
        return figure
