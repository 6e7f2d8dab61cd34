"""Renders stored runs. Reads ``results.csv`` and ``run.json``; never runs an engine."""
