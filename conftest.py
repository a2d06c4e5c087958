"""Repository-wide pytest wiring: per-notebook nbval modes (see tests/nbval_modes.py), and the
tests that need the real-motion network last (tests/order.py)."""

pytest_plugins = ["tests.nbval_modes", "tests.order"]
