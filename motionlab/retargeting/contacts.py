"""Foot contacts of the source for the contact term: :mod:`motionlab.core.contacts`, the package's
one foot-contact detector, re-exported here where the retargeting code and notebook 03 name it."""

from motionlab.core import contacts as _core
from motionlab.core.contacts import *  # noqa: F403  (the names of core's __all__)

__all__ = _core.__all__
