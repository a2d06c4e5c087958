"""Repository-wide pytest wiring: per-notebook nbval modes (see tests/nbval_modes.py)."""

pytest_plugins = ["tests.nbval_modes"]
