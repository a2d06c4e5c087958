"""Sub-commands that gather several parts of the package (``info``, ``convert``, ``synth``, ``demo``).

They live above ``core`` because they use ``synthetic`` and the demo; ``core`` imports nothing
from here (``tests/test_layers.py`` checks the direction of every import).
"""
