"""Which torch device the retargeting network runs on: the one home of the default and its checks.

The default is the device ``MOTIONLAB_DEVICE`` names when it is set (``cpu`` keeps a GPU machine
on the CPU, as the test suite does: its known answers and the notebooks' stored outputs were made
there), else CUDA when ``torch.cuda.is_available()``, else the CPU. A device that is named
(``--device``, ``TrainConfig.device``, :func:`motionlab.retargeting.load`) must exist on this
machine: :func:`pick` refuses a name torch does not know and a CUDA (or MPS) device this torch
cannot use, with a :class:`ValueError` saying which devices there are, instead of a torch
traceback at the first tensor.

Every tensor of the retargeting code follows its inputs: the network's weights decide the
device and float type, and each tensor made from other data names them (``device=``, ``dtype=``)
explicitly. ``tests/retargeting/test_devices.py`` checks that rule on the CPU.
"""

from __future__ import annotations

import os

import torch

__all__ = ["pick", "available", "index", "DEVICE_ENV"]

DEVICE_ENV = "MOTIONLAB_DEVICE"
"""The environment variable that names the default device."""

_INDEX: dict = {}


def available() -> list[str]:
    """The device names usable here: ``"cpu"``, then ``"cuda"``, ``"cuda:0"``… and ``"mps"`` where present."""
    names = ["cpu"]
    if torch.cuda.is_available():
        names += ["cuda"] + [f"cuda:{i}" for i in range(torch.cuda.device_count())]
    mps = getattr(torch.backends, "mps", None)
    if mps is not None and mps.is_available():
        names.append("mps")
    return names


def pick(device: str | torch.device | None = None) -> torch.device:
    """``device`` checked, or the default: the device :data:`DEVICE_ENV` names, else CUDA when
    available, else the CPU.

    Raises
    ------
    ValueError
        ``device`` (or :data:`DEVICE_ENV`, named in the message) is not a torch device name, or
        names a CUDA / MPS device this machine or this build of torch does not have (the message
        lists the devices there are).
    """
    if device is None:
        named = os.environ.get(DEVICE_ENV, "").strip()
        if not named:
            return torch.device("cuda" if torch.cuda.is_available() else "cpu")
        try:
            return pick(named)
        except ValueError as e:
            raise ValueError(f"{DEVICE_ENV}: {e}") from None
    try:
        dev = torch.device(device)
    except (RuntimeError, TypeError):
        raise ValueError(f"device {device!r} is not a torch device; expected one of {available()}") from None
    if dev.type == "cuda":
        if not torch.cuda.is_available():
            build = "a CPU-only build" if torch.version.cuda is None else f"built for CUDA {torch.version.cuda}"
            raise ValueError(
                f"device {device!r}: this machine has no usable CUDA GPU (torch {torch.__version__}, {build}); use cpu"
            )
        if dev.index is not None and dev.index >= torch.cuda.device_count():
            raise ValueError(f"device {device!r}: there are {torch.cuda.device_count()} CUDA GPU(s); use {available()}")
    elif dev.type == "mps":
        mps = getattr(torch.backends, "mps", None)
        if mps is None or not mps.is_available():
            raise ValueError(f"device {device!r}: MPS is not available here; expected one of {available()}")
    elif dev.type != "cpu":
        raise ValueError(f"device {device!r}: motionlab runs on {available()}, not on {dev.type}")
    return dev


def index(values, device: torch.device) -> torch.Tensor:
    """``values`` (a sequence of ints) as an int64 tensor on ``device``, made once per values and
    device. The latent iteration indexes joints and tree levels at every step: a Python list as an
    index is copied to the device each time, and on a GPU that copy waits for the queued work."""
    key = (tuple(int(v) for v in values), torch.device(device))
    if key not in _INDEX:
        _INDEX[key] = torch.tensor(key[0], dtype=torch.int64, device=key[1])
    return _INDEX[key]
