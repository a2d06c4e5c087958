"""Foot contacts of the source for the contact term: :mod:`motionlab.core.contacts`, the package's
one foot-contact detector, re-exported here where the retargeting code and notebook 03 name it."""

from motionlab.core.contacts import (
    CONTACT_JOINTS,
    HEIGHT_TOL,
    MIN_FRAMES,
    SPEED_TOL,
    detect_contacts,
    low_and_slow,
    of_motion,
    rest_heights,
    runs_at_least,
)

__all__ = [
    "CONTACT_JOINTS",
    "HEIGHT_TOL",
    "SPEED_TOL",
    "MIN_FRAMES",
    "low_and_slow",
    "runs_at_least",
    "detect_contacts",
    "rest_heights",
    "of_motion",
]
