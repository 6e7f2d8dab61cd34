"""Renders stored runs. Reads a run's results (``results.parquet`` or ``results.csv``), ``series.csv.gz`` and
``run.json``; never runs an engine."""
