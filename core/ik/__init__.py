"""Inverse kinematics.

The problem types (data model, shared with the engines' adapters): :mod:`.problem`
(tolerances, checked targets) and :mod:`.result` (``IKResult``, failures as data). The
in-house methods (the lecture's): :mod:`.analytic_2link`, :mod:`.jacobian_solvers` with
:mod:`.steps`, :mod:`.nullspace` and :mod:`.limits`, and :mod:`.reach`.
"""
