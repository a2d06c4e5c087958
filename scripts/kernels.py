"""Print the numeric back end this Python process would compute with: numpy's SIMD kernels,
the BLAS library and its kernel (threadpoolctl), torch's CPU capability, threads and MKL mode.

    python scripts/kernels.py

`.ci/run` prints it before each test pass, so a log shows which kernels produced which result.
"""

from __future__ import annotations

import os

MKL_BRANCHES = {
    1: "off (MKL's own choice)",
    2: "AUTO (MKL's own choice)",
    3: "COMPATIBLE",
    4: "SSE2",
    6: "SSSE3",
    7: "SSE4_1",
    8: "SSE4_2",
    9: "AVX",
    10: "AVX2",
    12: "AVX512",
    14: "AVX512_E1",
}
"""MKL's code-path codes (``mkl_cbwr.h``). MKL_CBWR asks for one, and MKL may take another
(``docs/reproducibility.md``)."""


def mkl_branch() -> str:
    """The code path torch's MKL computes with (``mkl_cbwr_get``), or why it is unknown."""
    import ctypes

    import torch

    try:
        lib = ctypes.CDLL(os.path.join(os.path.dirname(torch.__file__), "lib", "libtorch_cpu.so"))
        code = lib.mkl_serv_cbwr_get(ctypes.c_int(-1)) & 0xFFFFFFFF  # MKL_CBWR_ALL
    except (OSError, AttributeError):
        return "(unknown: no MKL in this torch)"
    strict = ", STRICT" if code & 0x10000 else ""
    return MKL_BRANCHES.get(code & 0xFFFF, f"code {code & 0xFFFF}") + strict


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
    lines.append(f"MKL in torch: code path in effect {mkl_branch()}")
    settings = ("OPENBLAS_CORETYPE", "ATEN_CPU_CAPABILITY", "MKL_CBWR", "OMP_NUM_THREADS", "NPY_DISABLE_CPU_FEATURES")
    lines.append("settings: " + ", ".join(f"{k}={os.environ.get(k, '(unset)')}" for k in settings))
    return lines


if __name__ == "__main__":
    print("\n".join(describe()))
