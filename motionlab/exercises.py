"""Check cells for the notebooks' exercises.

Every exercise asks the student to write a function the package already has; :func:`check`
runs both on the same inputs and says plainly whether the student's answer agrees::

    def my_conj(q):
        ...
    exercises.check(my_conj, quat.conj, [q1, q2])   # prints "✓ my_conj agrees on 2 cases"

A stub that still raises ``NotImplementedError`` is reported as not done (and re-raised, so the
cell fails visibly in a notebook; CI marks these cells as expected to raise).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["check"]


def _as_array(x):
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.asarray(x, dtype=np.float64)


def check(student: Callable, reference: Callable, cases: Sequence, atol: float = 1e-6, sign_free: bool = False) -> None:
    """Compare ``student(*case)`` with ``reference(*case)`` on every case.

    Parameters
    ----------
    student, reference : callables returning arrays (or tuples of arrays)
    cases : list of argument tuples (a non-tuple case is passed as the single argument)
    atol : absolute tolerance
    sign_free : compare quaternions up to sign (``q`` and ``-q`` are the same rotation)

    Raises
    ------
    NotImplementedError if the exercise is not done yet; AssertionError naming the first case
    that disagrees, with both answers.
    """
    name = getattr(student, "__name__", "your function")
    for i, case in enumerate(cases):
        args = case if isinstance(case, tuple) else (case,)
        try:
            got = student(*args)
        except NotImplementedError:
            print(f"✗ {name} is not written yet: replace the `raise NotImplementedError` line")
            raise
        want = reference(*args)
        got_t = got if isinstance(got, tuple) else (got,)
        want_t = want if isinstance(want, tuple) else (want,)
        for g, w in zip(got_t, want_t):
            g, w = _as_array(g), _as_array(w)
            if g.shape != w.shape:
                raise AssertionError(f"case {i}: {name} returned shape {g.shape}, expected {w.shape}")
            err = np.abs(g - w)
            if sign_free:
                err = np.minimum(err.max(axis=-1), np.abs(g + w).max(axis=-1))
            if not np.all(err <= atol):
                raise AssertionError(
                    f"case {i}: {name} differs by {np.nanmax(err):.3g} (atol {atol:g})\n got {g}\n want {w}"
                )
    print(f"✓ {name} agrees with the package on {len(cases)} case(s)")
