"""``python -m motionlab`` runs the command line (same as the ``motionlab`` command)."""

import sys

from motionlab.cli import main

sys.exit(main())
