"""Where each record of a CSV file starts and ends, read from its newlines and quotes at once (vectorised, no loop
over rows), and how many fields a record has: what ``pandas.read_csv`` does not say (it pads a row cut short with
empty cells, and reads a last row cut mid-line as if it were whole)."""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

_QUOTE, _NEWLINE = ord('"'), ord("\n")


@dataclass(frozen=True)
class Records:
    """The records of a CSV file, the header first: ``starts`` and ``stops`` (R,) the byte range of each (its newline
    left out), ``lines`` (R,) the line each starts on (from 1; a quoted newline inside a record counts), ``ended``
    whether the last one ends with a newline."""

    starts: np.ndarray
    stops: np.ndarray
    lines: np.ndarray
    ended: bool

    def rows(self) -> np.ndarray:
        """The records of the rows after the header, by index: blank lines (which pandas skips) left out."""
        return np.flatnonzero(self.stops > self.starts)[1:]

    def fields(self, data: bytes, which: np.ndarray) -> np.ndarray:
        """The number of fields of each record of ``which`` (indices) in ``data``, parsed by :mod:`csv` (-1 for a
        record it cannot parse): a loop over ``which`` alone, the few records a reader has reason to doubt."""
        counts = []
        for index in which:
            text = data[self.starts[index]:self.stops[index]].decode("utf-8", "replace")
            try:
                counts.append(len(next(csv.reader([text], strict=True), [])))
            except csv.Error:
                counts.append(-1)
        return np.asarray(counts, dtype=np.int64)


def records(data: bytes) -> Records:
    """The records of the CSV text ``data`` (RFC 4180: quoted with '"', a quote inside a quoted field doubled): a
    newline ends a record unless an odd number of quotes precedes it (it is inside a quoted field). One pass over the
    bytes per character looked for; the rest is searches among their positions."""
    codes = np.frombuffer(data, np.uint8)
    newlines = np.flatnonzero(codes == _NEWLINE)
    ends = newlines[np.searchsorted(np.flatnonzero(codes == _QUOTE), newlines) % 2 == 0]
    ended = len(ends) > 0 and ends[-1] == len(data) - 1
    count = len(ends) + (0 if ended or not data else 1)
    starts = np.concatenate(([0], ends + 1))[:count]
    stops = np.concatenate((ends, [len(data)]))[:count]
    return Records(starts, stops, np.searchsorted(newlines, starts) + 1, bool(ended))
