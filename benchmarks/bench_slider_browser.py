"""Notebook 04's legs slider in a real browser: seconds from the key press to the updated view.

The in-process figure (``ProportionEditor.timings['total']``, ``bench_threads.py``) leaves out
what a user also waits for: the browser sending the new value, the kernel's message queue, the
widget messages back and the browser decoding the picture. This script measures all of it:

1. writes a one-cell notebook that builds the editor exactly as notebook 04 does (22-joint
   humanoid, 120-frame synthetic walk, seed 1, ``proportion_solver(clip, max_steps=30)``,
   ``window_size=(420, 330)``, first update ``legs=1.3, arms=0.8``) into a temporary folder;
2. starts JupyterLab there (127.0.0.1, random port and token) and opens it in Debian's headless
   ``/usr/bin/chromium`` through ``playwright`` (never ``playwright install``);
3. runs the cell, focuses the legs slider's handle and presses ArrowRight / ArrowLeft in turn
   (one 0.05 step = one release), ``--presses`` times;
4. for each press, times in the page (``performance.now()``) from the ``keydown`` event to
   * the first new picture: the 3D player's picture replaced *and decoded* (its ``src``
     changes, then ``img.decode()`` and one animation frame: the new pixels are on screen) --
     the editor's preview, the copied rotations on the new skeleton, when it shows one;
   * the solver's view: the last picture sent before the status line reports the solve, on
     screen, and that status line (the latent iteration's result, what the user waits for);
5. prints each press, then median and max of both, the kernel's own solve/view seconds (parsed
   from the status line), and the 1-minute load average before and after.

Usage (from the repository root, with chromium and the dev extras installed)::

    python benchmarks/bench_slider_browser.py                # 10 presses
    python benchmarks/bench_slider_browser.py --presses 20 --busy 1

``--busy N`` adds N busy-looping processes beside JupyterLab (as ``bench_threads.py`` does).
Exit status 0 when every press updated the view, 1 otherwise.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import secrets
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
from tests.browser.check_notebook_in_chromium import (  # noqa: E402
    _free_port,
    _start_lab,
    _wait_for_server,
    run_all_cells,
)

SENTINEL = "EDITOR READY"

CELL = """\
from motionlab import synthetic
from motionlab.core import humanoid
from motionlab.retargeting.proportions import proportion_solver
from motionlab.viz import proportions

skeleton = humanoid.canonical_skeleton()
clip120 = synthetic.generate("walk", skeleton, num_frames=120, fps=30.0, seed=1)
solve = proportion_solver(clip120, max_steps=30)  # as notebook 04
editor = proportions.ProportionEditor(clip120, solve=solve, window_size=(420, 330))
editor.update(legs=1.3, arms=0.8)
display(editor)
print("EDITOR READY")
"""

_ARM = """() => {
  const view = document.querySelector('img.widget-image');
  const status = [...document.querySelectorAll('.widget-label')].find(e => e.innerText.includes('solved in'));
  const rec = {key: null, shown: [], done: null, status: status.innerText, changes: 0};
  window.__slider = rec;
  document.addEventListener('keydown', () => { if (rec.key === null) rec.key = performance.now(); },
                            {capture: true, once: true});
  new MutationObserver(() => {
    rec.changes += 1;
    view.decode().catch(() => null).then(() => requestAnimationFrame(() => rec.shown.push(performance.now())));
  }).observe(view, {attributes: true, attributeFilter: ['src']});
  new MutationObserver((_, obs) => {
    const text = status.innerText;
    if (text.includes('solved in') && text !== rec.status) {
      rec.done = performance.now(); rec.status = text; rec.final = rec.changes; obs.disconnect();
    }
  }).observe(status, {childList: true, subtree: true, characterData: true});
}"""
"""Install the timers for one press: every new picture of the first widget image (the player) on
screen (decoded, then one animation frame), and the status line's final text (the solver's result)."""


def _write_notebook(path: Path) -> None:
    cell = {"cell_type": "code", "execution_count": None, "metadata": {}, "outputs": [], "source": CELL}
    nb = {
        "cells": [cell],
        "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"}},
        "nbformat": 4,
        "nbformat_minor": 5,
    }
    path.write_text(json.dumps(nb, indent=1), encoding="utf-8")


def _open_and_run(page, url: str, timeout_s: float) -> None:
    page.goto(url, wait_until="domcontentloaded", timeout=60_000)
    page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=60_000)
    page.wait_for_function("() => document.body.innerText.includes('| Idle')", timeout=60_000, polling=500)
    run_all_cells(page, SENTINEL, timeout_s)
    page.wait_for_function("() => document.body.innerText.includes('| Idle')", timeout=60_000, polling=250)


def _press(page, handle, key: str, timeout_s: float) -> dict:
    """One press: arm the timers, press ``key`` on the focused handle, wait for the solver's view.

    ``first_view_s``: press -> the first new picture on screen (the preview, when the editor shows
    one); ``view_s``: press -> the solver's picture on screen (the last picture sent before the
    final status line) or the final status line, whichever is later."""
    page.evaluate(_ARM)
    handle.focus()
    page.keyboard.press(key)
    page.wait_for_function(
        "() => { const r = window.__slider; return r.done !== null && r.shown.length >= r.final; }",
        timeout=timeout_s * 1000,
        polling="raf",
    )
    rec = page.evaluate("() => window.__slider")
    solve = re.search(r"solved in ([\d.]+) s", rec["status"])
    view = re.search(r"view in ([\d.]+) s", rec["status"])
    return {
        "key": key,
        "pictures": rec["final"],
        "first_view_s": (rec["shown"][0] - rec["key"]) / 1000,
        "view_s": (max(rec["shown"][rec["final"] - 1], rec["done"]) - rec["key"]) / 1000,
        "kernel_solve_s": float(solve.group(1)) if solve else float("nan"),
        "kernel_view_s": float(view.group(1)) if view else float("nan"),
    }


def measure(url: str, presses: int, timeout_s: float) -> list[dict]:
    """Open the notebook, run it and time ``presses`` presses of the legs slider."""
    from playwright.sync_api import sync_playwright

    rows = []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path="/usr/bin/chromium",
            headless=True,
            args=["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
        )
        page = browser.new_page(viewport={"width": 1400, "height": 1000})
        _open_and_run(page, url, timeout_s)
        legs = page.locator(".widget-slider", has=page.locator(".widget-label", has_text="legs")).first
        legs.scroll_into_view_if_needed()
        handle = legs.locator(".noUi-handle, .slider-handle, [role='slider']").first
        time.sleep(1.0)
        for k in range(presses + 1):  # the first press is a warm-up (first solve on this skeleton shape)
            row = _press(page, handle, "ArrowRight" if k % 2 == 0 else "ArrowLeft", 60.0)
            row["value"] = legs.locator(".widget-readout").first.inner_text()
            rows.append(row)
            print(
                f"{'warm-up' if k == 0 else k:>7} {row['key']:>10} legs {row['value']:>5}  first picture"
                f" {row['first_view_s']:5.2f} s  solver's view {row['view_s']:5.2f} s ({row['pictures']} pictures)"
                f"  (kernel: solve {row['kernel_solve_s']:.2f} s,"
                f" view {row['kernel_view_s']:.2f} s)  load {os.getloadavg()[0]:.2f}",
                flush=True,
            )
            time.sleep(0.5)
        browser.close()
    return rows[1:]


@contextlib.contextmanager
def _busy(processes: int):
    if not processes:
        yield
        return
    sys.path.insert(0, str(REPO / "benchmarks"))
    from bench_threads import busy

    with busy(processes):
        yield


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--presses", type=int, default=10, help="timed presses (default 10, after one warm-up)")
    parser.add_argument("--busy", type=int, default=0, help="busy processes beside JupyterLab (default 0)")
    parser.add_argument("--timeout", type=float, default=240.0, help="seconds to wait for the cell to run")
    args = parser.parse_args(argv)
    if not Path("/usr/bin/chromium").exists():
        print("chromium not found: apt-get install -y chromium", file=sys.stderr)
        return 1
    folder = Path(tempfile.mkdtemp(prefix="motionlab_slider_"))
    notebook = folder / "slider.ipynb"
    _write_notebook(notebook)
    port, token = _free_port(), secrets.token_hex(16)
    with open(folder / "jupyterlab.log", "w") as log, _busy(args.busy):
        load_before = os.getloadavg()
        server = _start_lab(folder, port, token, "static", log)
        try:
            _wait_for_server(port, token)
            rows = measure(
                f"http://127.0.0.1:{port}/lab/tree/{notebook.name}?token={token}&reset", args.presses, args.timeout
            )
        finally:
            server.send_signal(signal.SIGTERM)
            try:
                server.wait(timeout=15)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
        load_after = os.getloadavg()
    first = [r["first_view_s"] for r in rows]
    view = [r["view_s"] for r in rows]
    solve = [r["kernel_solve_s"] for r in rows]
    print(
        f"\n{len(rows)} presses, {os.cpu_count()} cores, {args.busy} busy processes; load average (1, 5, 15 min) "
        f"before {load_before[0]:.2f} {load_before[1]:.2f} {load_before[2]:.2f}, "
        f"after {load_after[0]:.2f} {load_after[1]:.2f} {load_after[2]:.2f}"
    )
    print(f"press -> first new picture on screen: median {statistics.median(first):.2f} s, max {max(first):.2f} s")
    print(f"press -> solver's view and status:    median {statistics.median(view):.2f} s, max {max(view):.2f} s")
    print(f"kernel solve (in-process):            median {statistics.median(solve):.2f} s, max {max(solve):.2f} s")
    for name, values in (("first picture", first), ("solver's view", view)):
        median = statistics.median(values)
        print(f"goal: press -> {name} median <= 1 s: {median:.2f} s ({'met' if median <= 1.0 else 'NOT met'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
