"""The checking machinery behind every exercise: :class:`Exercise`, :class:`Mistake`, :class:`Result`.

An exercise's check runs the student's function and a reference on the same cases and answers in
one line, without raising (see :mod:`motionlab.exercises`). :func:`check` is the same machinery
for ad-hoc checks.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Exercise", "Mistake", "Question", "Result", "check"]


# --------------------------------------------------------------------------- results and comparison
@dataclass(frozen=True)
class Result:
    """Outcome of one check.

    Attributes
    ----------
    passed : the answer agrees on every case
    attempted : False while the stub still raises ``NotImplementedError``
    message : the one-paragraph verdict shown in the notebook
    hint : the matched typical mistake's hint, or None
    """

    passed: bool
    attempted: bool
    message: str
    hint: str | None = None

    def __bool__(self) -> bool:
        return self.passed

    def __repr__(self) -> str:
        return self.message

    def _repr_pretty_(self, p, cycle) -> None:  # IPython shows the message, not a dataclass repr
        p.text(self.message)


@dataclass(frozen=True)
class Mistake:
    """A typical wrong answer and the hint to give when a student's answer behaves like it.

    ``answer`` is written as a student would write the mistake; an answer is recognised as this
    mistake when it agrees with ``answer`` on every case (same tolerance as the check).
    """

    answer: Callable
    hint: str


def _as_array(x) -> np.ndarray:
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.asarray(x, dtype=np.float64)


def _as_tuple(x) -> tuple:
    return x if isinstance(x, tuple) else (x,)


def _difference(got, want, atol: float, sign_free: bool, period: float | None) -> tuple[bool, str]:
    """(agrees, what differs) for one case's outputs; never shows ``want`` itself."""
    got_t, want_t = _as_tuple(got), _as_tuple(want)
    if len(got_t) != len(want_t):
        return False, f"returned {len(got_t)} value(s), expected {len(want_t)}"
    for g, w in zip(got_t, want_t):
        if g is None:
            return False, "returned None: is a `return` missing?"
        try:
            g = _as_array(g)
        except (TypeError, ValueError):
            return False, f"returned {type(g).__name__}, expected numbers"
        w = _as_array(w)
        if g.shape != w.shape:
            return False, f"returned shape {g.shape}, expected shape {w.shape}"
        diff = g - w
        if period is not None:  # angles: equal up to whole turns
            diff = (diff + period / 2) % period - period / 2
        err = np.abs(diff)
        if sign_free:  # quaternions: q and -q are the same rotation
            err = np.minimum(err.max(axis=-1), np.abs(g + w).max(axis=-1))
        if not np.all(np.isfinite(g)):
            return False, "returned NaN or infinite values"
        if not np.all(err <= atol):
            if w.size == 1:  # the size of the gap would give a single number away
                return False, "is not the expected value"
            return False, f"differs by up to {np.nanmax(err):.3g} (tolerance {atol:g})"
    return True, ""


def _call(fn: Callable, args: tuple):
    """``fn(*args)`` on a copy of the arguments: an answer that changes its inputs in place changes
    neither the reference's nor the next call's."""
    return fn(*copy.deepcopy(args))


@dataclass
class Exercise:
    """One exercise: its reference, its test cases, accepted alternatives and typical mistakes.

    Parameters
    ----------
    name : shown in messages (``"00 · exercise 1: quaternion conjugate"``)
    reference : the correct answer (usually the package's own function)
    cases : callable returning a list of argument tuples (built on demand, deterministic)
    accept : other correct answers (e.g. another finite-difference scheme); agreeing with any
        of them passes
    mistakes : typical wrong answers with their hints, tried in order
    atol : absolute tolerance per element
    sign_free : compare quaternions up to sign
    period : compare modulo this period (angles: ``2π``)
    """

    name: str
    reference: Callable
    cases: Callable[[], Sequence[tuple]]
    accept: Sequence[Callable] = ()
    mistakes: Sequence[Mistake] = ()
    atol: float = 1e-6
    sign_free: bool = False
    period: float | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    def _cases(self) -> list[tuple]:
        if "cases" not in self._cache:
            self._cache["cases"] = [_as_tuple(c) for c in self.cases()]
        return self._cache["cases"]

    def _agrees(self, outputs: list, fn: Callable, cases: list[tuple]) -> tuple[bool, str]:
        for i, (args, got) in enumerate(zip(cases, outputs)):
            ok, why = _difference(got, _call(fn, args), self.atol, self.sign_free, self.period)
            if not ok:
                return False, f"case {i + 1}: {why}"
        return True, ""

    def check(self, student: Callable) -> Result:
        """Run ``student`` on every case; see the module docstring for the three outcomes."""
        return _run_check(
            student, self.reference, self._cases(), self.accept, self.mistakes, self._agrees, label=self.name
        )


def _run_check(student, reference, cases, accept, mistakes, agrees, label: str | None) -> Result:
    fname = getattr(student, "__name__", "your function")
    head = f"{label}: " if label else ""
    outputs = []
    for i, args in enumerate(cases):
        try:
            outputs.append(_call(student, args))
        except NotImplementedError:
            return Result(
                False,
                False,
                f"… {head}{fname} is not written yet (it still raises NotImplementedError). "
                "Replace the `raise` line with your code and run this cell again; the notebook goes on.",
            )
        except Exception as e:  # a student's bug: report it, keep the notebook running
            return Result(False, True, f"✗ {head}{fname} raised {type(e).__name__} on case {i + 1}: {e}", hint=None)
    ok, why = agrees(outputs, reference, cases)
    if ok:
        return Result(True, True, f"✓ {head}{fname} is right on {len(cases)} case(s)")
    for alternative in accept:
        if agrees(outputs, alternative, cases)[0]:
            return Result(True, True, f"✓ {head}{fname} is right on {len(cases)} case(s) (an accepted variant)")
    for mistake in mistakes:
        try:
            same = agrees(outputs, mistake.answer, cases)[0]
        except Exception:  # a mistake that cannot run on these cases is simply not this one
            same = False
        if same:
            return Result(False, True, f"✗ {head}{fname} is not right yet ({why}). Hint: {mistake.hint}", mistake.hint)
    return Result(False, True, f"✗ {head}{fname} is not right yet ({why}).")


def check(
    student: Callable,
    reference: Callable,
    cases: Sequence,
    atol: float = 1e-6,
    sign_free: bool = False,
    *,
    accept: Sequence[Callable] = (),
    mistakes: Sequence[Mistake] = (),
    period: float | None = None,
) -> Result:
    """Compare ``student(*case)`` with ``reference(*case)`` on every case, without raising.

    Parameters
    ----------
    student, reference : callables returning arrays (or tuples of arrays)
    cases : list of argument tuples (a non-tuple case is passed as the single argument)
    atol : absolute tolerance
    sign_free : compare quaternions up to sign (``q`` and ``-q`` are the same rotation)
    accept : other correct answers; agreeing with any of them also passes
    mistakes : typical wrong answers with hints (see :class:`Mistake`)
    period : compare modulo this period (angles)

    Returns
    -------
    Result : ``passed``, ``attempted``, ``message`` (shown when it is the cell's last value), ``hint``
    """
    ex = Exercise("", reference, lambda: list(cases), accept, mistakes, atol, sign_free, period)
    return _run_check(student, reference, ex._cases(), accept, mistakes, ex._agrees, label=None)


# --------------------------------------------------------------------------- experiments
@dataclass
class Question:
    """An experiment whose answer is one number (or one choice among numbers).

    The student changes a parameter, runs the experiment in the notebook and types the number it
    gives. The check recomputes the experiment on the *same inputs* the notebook used (its own
    data, real or synthetic), so one key fits every data set, and compares:
    ``|answer − reference| ≤ atol + rtol · |reference|``. An answer within that of a listed
    mistake too, and nearer to it, is that mistake, where the two values differ by more than
    ``atol`` (the digits an answer is typed with).

    Parameters
    ----------
    name : shown in messages
    reference : ``reference(*inputs) -> float``, the right answer for the notebook's inputs
    accept : other correct answers (e.g. another reasonable convention), same signature
    mistakes : typical wrong experiments (:class:`Mistake`, ``answer(*inputs) -> float``) with hints
    atol, rtol : tolerance (0 and 0 for a choice among integers)
    unit : appended to messages ("°", "")
    """

    name: str
    reference: Callable[..., float]
    accept: Sequence[Callable[..., float]] = ()
    mistakes: Sequence[Mistake] = ()
    atol: float = 0.0
    rtol: float = 0.0

    def _close(self, answer: float, value: float) -> bool:
        return bool(abs(answer - value) <= self.atol + self.rtol * abs(value))

    def _mistake(self, answer: float, right: float, inputs: tuple) -> Mistake | None:
        """The listed mistake ``answer`` is: within tolerance of it and, where the right value is
        within tolerance too, nearer to it, if the two differ by more than ``atol`` (the digits an
        answer is typed with: closer, the experiment cannot tell them apart, and the answer is right)."""
        for mistake in self.mistakes:
            try:
                value = float(mistake.answer(*inputs))
            except Exception:  # a mistake that cannot run on these inputs is simply not this one
                continue
            if not self._close(answer, value):
                continue
            if not self._close(answer, right) or (
                abs(answer - value) < abs(answer - right) and abs(value - right) > self.atol
            ):
                return mistake
        return None

    def check(self, answer, *inputs) -> Result:
        """``✓``, ``…`` (the answer is still ``...``) or ``✗`` with a hint; never shows the reference."""
        head = f"{self.name}: "
        if answer is ... or answer is None:
            return Result(
                False,
                False,
                f"… {head}not answered yet (the answer is still `...`). Run the experiment, put its "
                "number in place of `...` and run this cell again; the notebook goes on.",
            )
        try:
            value = float(answer)
        except (TypeError, ValueError):
            return Result(False, True, f"✗ {head}expected a number, got {type(answer).__name__}")
        if not np.isfinite(value):
            return Result(False, True, f"✗ {head}the answer is NaN or infinite")
        right = float(self.reference(*inputs))
        mistake = self._mistake(value, right, inputs)
        if mistake is not None:
            return Result(False, True, f"✗ {head}{answer} is not right yet. Hint: {mistake.hint}", mistake.hint)
        if self._close(value, right):
            return Result(True, True, f"✓ {head}{answer} is right")
        for alternative in self.accept:
            if self._close(value, float(alternative(*inputs))):
                return Result(True, True, f"✓ {head}{answer} is right (an accepted variant)")
        return Result(False, True, f"✗ {head}{answer} is not right yet.")
