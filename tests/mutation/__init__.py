"""A mutation suite for the CI gate (issue #23): planted bugs in copies of core, run as plugin engines.

- :mod:`.mutation`: a planted bug as a typed record, and how it is applied to a file's text;
- :mod:`.copy_of_core`: a copy of core's in-house methods as a package of its own in a folder, with at most
  one mutation, its engine under a name of its own; the data model stays the real ``simparity.core``;
- :mod:`.catalogue`: the planted bugs, and the faithful copy;
- :mod:`.gate`: ``simparity run --quick --check`` with copies beside core, and its verdict on each of them;
- :mod:`.score`: the mutation score table (``python -m tests.mutation.score``);
- :mod:`.margin`: how wide each catch is, value / bound, scene by scene (``python -m tests.mutation.margin``).
"""
