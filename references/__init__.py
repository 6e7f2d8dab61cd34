"""Adapters to MuJoCo, PyBullet and Pinocchio, and analytic ground truths.

Every convention conversion between an engine and the project happens here and nowhere
else. Imports ``core`` only (plus the engines themselves).
"""
