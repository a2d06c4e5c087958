"""Print the numeric back end this Python process would compute with: numpy's SIMD kernels,
the BLAS library and its kernel (threadpoolctl), torch's CPU capability, threads and MKL mode.

    python scripts/kernels.py

`.ci/run` prints it before each test pass, so a log shows which kernels produced which result.
"""

from __future__ import annotations

import os


def describe() -> list[str]:
    """One line per library: what it computes with."""
    import numpy as np
    import threadpoolctl
    import torch

    lines = []
    try:  # numpy's own record of the SIMD targets it dispatches to (private, so guarded)
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

        found = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)] or ["baseline only"]
    except ImportError:
        found = ["(unknown)"]
    lines.append(f"numpy {np.__version__}: SIMD dispatch targets in use {found}")
    for lib in threadpoolctl.threadpool_info():
        lines.append(
            f"{lib['internal_api']} ({lib['user_api']}) {lib.get('version') or ''}: "
            f"kernel {lib.get('architecture') or '-'}, {lib['num_threads']} threads"
        )
    lines.append(
        f"torch {torch.__version__}: CPU capability {torch.backends.cpu.get_cpu_capability()}, "
        f"{torch.get_num_threads()} threads"
    )
    settings = ("OPENBLAS_CORETYPE", "ATEN_CPU_CAPABILITY", "MKL_CBWR", "OMP_NUM_THREADS", "NPY_DISABLE_CPU_FEATURES")
    lines.append("settings: " + ", ".join(f"{k}={os.environ.get(k, '(unset)')}" for k in settings))
    return lines


if __name__ == "__main__":
    print("\n".join(describe()))
