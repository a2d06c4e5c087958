"""A CUDA graph's replay, done on the CPU: the step recorded once as aten ops, then those ops
re-run on the same tensors, with the same Python numbers, and nothing of the step's Python code.

On a GPU, :class:`motionlab.retargeting.graphs.StepGraph` runs the step eagerly a few times
(``graphs.WARMUP``), records it once, and from then on replays the recorded kernels. A replay
runs none of the step's Python: a Python number the step read while it was recorded (a counter,
an annealed weight) keeps its recorded value; a tensor the step read is read at the same memory,
so one that the caller *replaces* between steps (instead of updating it in place) is not seen;
and the recording itself changes nothing (its kernels are recorded, not run). Every one of these
gives a result on the GPU that differs from the CPU's, silently. CI has no GPU, so
:class:`Replayed` does the same on the CPU:

* the warm-up runs, as ``StepGraph`` does them (restoring the tensors it was told to ``keep``);
* the "recording" runs the step once eagerly under a :class:`TorchDispatchMode` that lists
  every aten op (forward and backward) with its arguments, the tensors kept as the objects
  themselves (their memory, as a graph keeps addresses) and every other argument as recorded;
  what an op writes to in memory the step did not allocate (a tensor that existed before the
  step, or a view of one) is copied first and put back afterwards, since a recording runs nothing;
* each :meth:`Replayed.run` re-runs the listed ops on the listed arguments and copies each
  fresh result into the tensor the recording made (a graph writes its results to the same
  memory every time), so a later op and the caller read them there.

Results that are views of their inputs (``detach``, ``expand``, in-place ops…) are the recorded
views themselves, which see their base's new values. With the same ops on the same values in
the same order, a replay gives the eager step's numbers bit for bit, unless the step depends on
something a graph does not replay, which the replay tests of ``test_devices.py`` check.
"""

from __future__ import annotations

import torch
from torch.utils._python_dispatch import TorchDispatchMode
from torch.utils._pytree import tree_flatten

from motionlab.retargeting import graphs


def _tensors(tree) -> list[torch.Tensor]:
    return [t for t in tree_flatten(tree)[0] if isinstance(t, torch.Tensor)]


def _written(func, args, kwargs) -> list[torch.Tensor]:
    """The tensor arguments that ``func``'s schema says it writes to (in-place and ``out=``)."""
    out = []
    for i, arg in enumerate(func._schema.arguments):
        value = args[i] if i < len(args) else kwargs.get(arg.name)
        if arg.alias_info is not None and arg.alias_info.is_write:
            out += _tensors(value)
    return out


def _memory(t: torch.Tensor) -> int:
    return t.untyped_storage().data_ptr()


class _Recorder(TorchDispatchMode):
    """Runs each op and lists it as ``(func, args, kwargs, tensors it made)`` (``None`` for a
    view); before an op first writes to memory the step did not allocate (a tensor made before
    it, or a view of one), keeps a copy of what it writes to in ``before``."""

    def __init__(self):
        super().__init__()
        self.ops: list[tuple] = []
        self.made: set[int] = set()  # memory some listed op allocated (kept alive by ``ops``)
        self.before: dict[int, tuple[torch.Tensor, torch.Tensor]] = {}

    def __torch_dispatch__(self, func, types, args=(), kwargs=None):
        kwargs = kwargs or {}
        for t in _written(func, args, kwargs):
            if t.numel() and _memory(t) not in self.made and id(t) not in self.before:
                self.before[id(t)] = (t, t.detach().clone())
        results = func(*args, **kwargs)
        view = any(r.alias_info is not None for r in func._schema.returns)  # of its inputs, or an input itself
        self.ops.append((func, args, kwargs, None if view else _tensors(results)))
        if not view:
            self.made.update(_memory(t) for t in _tensors(results) if t.numel())
        return results


def _replay(ops: list[tuple]) -> None:
    """Re-run the listed ops; a fresh result is copied into the one the recording made (a view's
    recorded result, ``None`` here, already sees its base's new values)."""
    with torch.no_grad():
        for func, args, kwargs, recorded in ops:
            fresh = func(*args, **kwargs)
            for old, new in zip(recorded or (), _tensors(fresh)):
                old.copy_(new)


class Replayed(graphs.StepGraph):
    """:class:`graphs.StepGraph` on any device, replaying its step as a CUDA graph does (see the
    module docstring). ``recorded`` is True; ``ops`` is the number of aten ops replayed per run."""

    def __init__(self, step, leaf, keep=()) -> None:
        self._step, self._leaf, self._keep = step, leaf, list(keep)
        with torch.no_grad():
            saved = [t.clone() for t in self._keep]
        for _ in range(graphs.WARMUP):
            self._leaf.grad = None
            self._step()
        with torch.no_grad():
            for t, value in zip(self._keep, saved):
                t.copy_(value)
        self._leaf.grad = None
        recorder = _Recorder()
        with recorder:
            self._out = self._step()
        with torch.no_grad():
            for t, value in recorder.before.values():
                t.copy_(value)  # a recording runs nothing
        self._ops, self._graph = recorder.ops, "replayed on the host"

    @property
    def ops(self) -> int:
        return len(self._ops)

    def run(self) -> tuple:
        _replay(self._ops)
        return self._out
