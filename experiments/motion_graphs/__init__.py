"""Studies of system motion graphs: rule comparisons and evaluations that import motionlab as a user would;
run each from the repository root as ``python -m experiments.motion_graphs.NAME``."""
