"""The scene library and loader, metrics, the runner and the CLI."""
