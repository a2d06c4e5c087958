"""Studies of motionlab: evaluation sweeps, rule comparisons and paper reproductions.

They import :mod:`motionlab` as any user would and are not part of the package. Run them from the
repository root as modules, e.g. ``python -m experiments.interpolation.check_gaps --quick``; the
tests import them the same way (``tests/experiments/``; pytest puts the repository root on
``sys.path`` through the root ``conftest.py``).
"""
