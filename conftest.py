"""Repository-wide pytest wiring: per-notebook nbval modes (see tests/nbval_modes.py), the tests that
need the real-motion network last (tests/order.py), and the CPU as the default torch device.

The known answers of the tests and the notebooks' stored outputs were computed on the CPU, so a
machine with a GPU runs them there too (``MOTIONLAB_DEVICE``, read by
``motionlab.retargeting.devices``; the notebooks' kernels inherit it). The GPU's own tests name
their device: ``pytest -m cuda``. Set ``MOTIONLAB_DEVICE`` before pytest to choose another default.
"""

import os

os.environ.setdefault("MOTIONLAB_DEVICE", "cpu")

pytest_plugins = ["tests.nbval_modes", "tests.order"]
