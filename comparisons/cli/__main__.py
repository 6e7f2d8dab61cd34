"""``python -m simparity.comparisons.cli``: the ``simparity`` command."""

import sys

from simparity.comparisons.cli.main import main

sys.exit(main())
