"""Threads sized to the work: where one torch thread beats all cores, and interactive speed under load.

Part 1 (``--sizes``): the latent iteration (20 Adam steps, fixed) on one synthetic clip of
T frames, with one thread and with all of torch's threads, on a quiet machine. The rows
(sequences × frames) where one thread stops being faster is the evidence for
``motionlab.core.threads.SMALL_ROWS``.

Part 2 (``--load``): the two goals of issue 29, measured with ``--busy`` processes that keep the
cores busy (each spins in a loop) beside the measured work:

* notebook 04's proportion slider, from release to view (``ProportionEditor.timings['total']``,
  the latent solver on a 120-frame walk): median <= 1 s at load average 2;
* ``motionlab demo``'s full method (mean seconds per character): within 1.5× of its quiet time.

Each is measured quiet, then under load, with motionlab's thread rule and with torch's default
threads (the rule switched off), so the table shows what the rule buys.

Usage::

    python benchmarks/bench_threads.py            # both parts
    python benchmarks/bench_threads.py --load --busy 2 --repeats 5
"""

from __future__ import annotations

import argparse
import contextlib
import multiprocessing as mp
import os
import statistics
import time

import torch

from motionlab import synthetic
from motionlab.core import threads
from motionlab.retargeting import SolverConfig, load_default, retarget


def _spin(stop) -> None:
    while not stop.is_set():
        pass


@contextlib.contextmanager
def busy(processes: int):
    """``processes`` busy loops in other processes for the duration of the block."""
    stop = mp.Event()
    workers = [mp.Process(target=_spin, args=(stop,), daemon=True) for _ in range(processes)]
    for w in workers:
        w.start()
    time.sleep(3.0 if processes else 0.0)  # let the load settle
    try:
        yield
    finally:
        stop.set()
        for w in workers:
            w.join()


@contextlib.contextmanager
def rule(enabled: bool):
    """motionlab's thread rule on, or off (every solve on torch's own thread count)."""
    before = threads.SMALL_ROWS
    threads.SMALL_ROWS = before if enabled else -1
    try:
        yield
    finally:
        threads.SMALL_ROWS = before


def sizes(ckpt, lengths=(120, 480, 960, 1920), repeats=3) -> None:
    cfg = SolverConfig(max_steps=20, threshold=0.0, patience=0)
    target = synthetic.character_set(1, seed=1)[0]
    print(f"part 1: 20 latent-iteration steps, one clip; torch default threads = {torch.get_num_threads()}")
    print(f"{'frames':>8} {'1 thread (s)':>13} {'all (s)':>9}  faster")
    for n in lengths:
        clip = synthetic.generate("walk", ckpt.skeleton, n, ckpt.fps, seed=0)
        times = {}
        for label, count in (("one", 1), ("all", torch.get_num_threads())):
            with rule(False), threads.torch_threads(count):
                retarget(clip, target, ckpt, solver=cfg)  # warm-up
                runs = []
                for _ in range(repeats):
                    t0 = time.perf_counter()
                    retarget(clip, target, ckpt, solver=cfg)
                    runs.append(time.perf_counter() - t0)
            times[label] = statistics.median(runs)
        best = "one" if times["one"] <= times["all"] else "all"
        print(f"{n:8d} {times['one']:13.2f} {times['all']:9.2f}  {best}")
    print(f"motionlab uses one thread up to SMALL_ROWS = {threads.SMALL_ROWS} rows")


def slider_seconds(repeats: int) -> float:
    """Median release-to-view seconds of notebook 04's editor (latent solver, 120-frame walk)."""
    from motionlab.retargeting.proportions import proportion_solver
    from motionlab.viz.proportions import ProportionEditor

    source = synthetic.generate("walk", None, 120, 30.0, seed=1)  # as in notebook 04
    editor = ProportionEditor(source, proportion_solver(source, max_steps=30), window_size=(420, 330), off_screen=True)
    totals = []
    for k in range(repeats + 1):
        editor.update(legs=1.1 + 0.05 * k)
        totals.append(editor.timings["total"])
    editor.close()
    return statistics.median(totals[1:])  # the first includes loading the network


def demo_seconds(ckpt) -> float:
    """Mean seconds of the full method per character, as ``motionlab demo`` times it."""
    from motionlab.demo import SEGMENTS

    performance = synthetic.sequence(SEGMENTS, ckpt.skeleton, fps=60, seed=0)
    out = []
    for target in synthetic.character_set(4, seed=1):
        t0 = time.perf_counter()
        retarget(performance, target, ckpt, "full", root_mode=synthetic.ROOT_MODE)
        out.append(time.perf_counter() - t0)
    return statistics.mean(out)


def load(ckpt, processes: int, repeats: int) -> None:
    print(f"\npart 2: {processes} busy processes beside the work, {os.cpu_count()} cores")
    print(f"{'rule':>5} {'load':>6} {'slider median (s)':>18} {'demo full (s/char)':>19}")
    rows = {}
    for enabled in (True, False):
        for n in (0, processes):
            with rule(enabled), busy(n):
                avg = os.getloadavg()[0]
                rows[(enabled, n)] = (slider_seconds(repeats), demo_seconds(ckpt))
            print(
                f"{'on' if enabled else 'off':>5} {avg:6.2f} {rows[(enabled, n)][0]:18.2f} {rows[(enabled, n)][1]:19.2f}"
            )
    slider, demo_loaded = rows[(True, processes)]
    demo_quiet = rows[(True, 0)][1]
    print(f"\ngoal: slider -> view median <= 1 s under load: {slider:.2f} s ({'met' if slider <= 1.0 else 'NOT met'})")
    ratio = demo_loaded / demo_quiet
    print(f"goal: demo full method within 1.5x of quiet: {ratio:.2f}x ({'met' if ratio <= 1.5 else 'NOT met'})")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", action="store_true", help="part 1 only: the one-thread crossover")
    parser.add_argument("--load", action="store_true", help="part 2 only: slider and demo under load")
    parser.add_argument("--busy", type=int, default=2, help="busy processes beside the work (default 2)")
    parser.add_argument("--repeats", type=int, default=5, help="slider releases measured per setting (default 5)")
    args = parser.parse_args(argv)
    ckpt = load_default("cpu")
    if args.sizes or not args.load:
        sizes(ckpt)
    if args.load or not args.sizes:
        load(ckpt, args.busy, args.repeats)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
