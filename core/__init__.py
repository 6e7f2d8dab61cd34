"""In-house implementation of the lecture's methods and the project's data model.

Imports NumPy (and SciPy where it truly helps) and nothing above it: no engine, no
``references``, ``comparisons`` or ``reports``.
"""
