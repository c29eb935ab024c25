"""Test helpers: shared data and the modules child processes import by name."""
