"""The ``simparity`` console script: the CLI (:mod:`comparisons.cli`), with Ctrl-C during its imports (NumPy,
pandas, the engines: ~1 s) one line and exit 130 like Ctrl-C anywhere else, not a traceback."""

from __future__ import annotations

import sys

EXIT_INTERRUPTED = 130
"""The shell's code for a process ended by Ctrl-C (128 + SIGINT), as the CLI's own."""


def main() -> int:
    try:
        from simparity.comparisons.cli.main import main as cli_main
    except KeyboardInterrupt:
        print("simparity: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    return cli_main()
