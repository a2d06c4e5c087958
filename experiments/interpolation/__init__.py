"""Studies of system C (key-pose interpolation and gap filling).

* :mod:`.gap_eval`     measuring detection and filling on clips with frames removed
* :mod:`.paper`        the paper's experiments (§4: Fig. 6/7 walk, Fig. 8 run → squat)
* :mod:`.benchmark`    LaFAN1-style benchmark (L2Q, L2P, NPSS); ``bench_inbetween`` prints its table
* ``bench_gap_rigs``, ``check_gaps``, ``check_tracking_pose``, ``compare_counts``, ``compare_feet``,
  ``compare_stride_root``, ``reproduce_keypose_paper``: the command-line studies whose tables are in
  ``docs/results_interpolation.md``
"""
