"""Fuzzed inputs for the surfaces of issue #39: stored runs, history databases, tolerance files, command-line options
and joint inputs (tests/system/test_fuzz_inputs.py runs them under the sweep marker; ``python -m tests.fuzz`` prints every
failing input grouped by class, or materialises one input to reproduce it).

Each family module has ``cases(rng) -> list[Case]``: built from a seeded ``numpy.random.Generator`` passed in, so the
same seed gives the same inputs (and the same test ids) in every process. A case writes its input into a folder of
its own when it is tried (:mod:`.oracle`), from the valid stored run made once (:class:`.oracle.Base`).
"""
