"""A template simparity engine; the engine is :class:`simparity_example_engine.engine.ExampleEngine`."""

__version__ = "0.1.0"
