"""Open notebook 04 in JupyterLab in a real browser, run it, and check that the views render.

Not a pytest test (it needs Debian's ``chromium`` and the ``playwright`` package, and takes
about a minute); run it by hand or in a CI job that has both::

    apt-get install -y chromium libegl1 libgl1-mesa-dri
    pip install playwright          # never `playwright install`: we drive /usr/bin/chromium
    python tests/browser/check_notebook_in_chromium.py --out /tmp/nb04.png [--backend trame]

What it does:

1. copies the notebook without its stored outputs to a temporary folder (so the sentinel must
   come from this run, and JupyterLab's autosave never writes into the repository) and starts JupyterLab there on 127.0.0.1 with a random token and port;
2. opens ``/lab/tree/<notebook>?token=…&reset`` in headless chromium through playwright,
   runs *Run → Run All Cells* and waits for the sentinel ``NOTEBOOK 04 DONE``;
3. checks that output images (``.jp-RenderedImage img``) and widget images loaded, that the
   players' sliders (``.widget-slider``) exist, and, with ``--backend trame``, that the trame
   iframes hold a canvas or image;
4. moves the first frame slider (keyboard: End) and checks that the player's picture changed
   and is not black (OpenGL renders from a widget callback must happen on the kernel's main
   thread);
5. moves the ``legs`` proportion slider and waits for the solver's status line to change;
6. saves screenshots (player: ``--out``; ``*_editor.png``; ``*_page.png``) and prints a JSON
   summary;
7. stops JupyterLab by its process id.

Exit status 0 when every check passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
NOTEBOOK = REPO / "notebooks" / "04_playback_and_bone_proportions.ipynb"
SENTINEL = "NOTEBOOK 04 DONE"


def _copy_without_outputs(source: Path, target: Path) -> None:
    """The notebook is committed with outputs (the sentinel among them): the browser must make its own."""
    nb = json.loads(source.read_text(encoding="utf-8"))
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            cell["outputs"], cell["execution_count"] = [], None
    target.write_text(json.dumps(nb, indent=1), encoding="utf-8")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start_lab(folder: Path, port: int, token: str, backend: str, log) -> subprocess.Popen:
    env = dict(os.environ)
    env.update(
        PYVISTA_OFF_SCREEN="true",
        PYVISTA_JUPYTER_BACKEND=backend,
        PYVISTA_TRAME_JUPYTER_MODE="native",
        MOTIONLAB_QUICK=env.get("MOTIONLAB_QUICK", "1"),
    )
    env.pop("MPLBACKEND", None)  # the browser should get inline figures
    cmd = [
        sys.executable,
        "-m",
        "jupyterlab",
        "--no-browser",
        "--ServerApp.ip=127.0.0.1",
        f"--ServerApp.port={port}",
        "--ServerApp.port_retries=0",
        f"--IdentityProvider.token={token}",
        f"--ServerApp.root_dir={folder}",
        "--allow-root",
        "--LabApp.news_url=",
        "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
    ]
    return subprocess.Popen(cmd, cwd=folder, env=env, stdout=log, stderr=subprocess.STDOUT)


def _wait_for_server(port: int, token: str, timeout: float = 60.0) -> None:
    url = f"http://127.0.0.1:{port}/api/status?token={token}"
    end = time.time() + timeout
    while time.time() < end:
        try:
            with urllib.request.urlopen(url, timeout=2) as r:
                if r.status == 200:
                    return
        except OSError:
            time.sleep(0.5)
    raise RuntimeError(f"JupyterLab did not answer on port {port} within {timeout:.0f} s")


_MEAN_LEVEL = """els => els.map(e => {
    const c = document.createElement('canvas');
    c.width = e.naturalWidth; c.height = e.naturalHeight;
    if (!c.width || !c.height) return -1;
    const g = c.getContext('2d'); g.drawImage(e, 0, 0);
    const d = g.getImageData(0, 0, c.width, c.height).data;
    let s = 0; for (let i = 0; i < d.length; i += 4) s += (d[i] + d[i + 1] + d[i + 2]) / 3;
    return Math.round(s / (d.length / 4));
})"""
"""Mean grey level (0-255) of each image: black (0) or missing (-1) pictures show up here."""


def _pixels(png: bytes):
    """Decoded RGB pixels of PNG bytes, as a numpy array."""
    import io

    import numpy as np
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def run_all_cells(page, sentinel: str, timeout_s: float) -> None:
    """In an open JupyterLab notebook: Run > Run All Cells (retried until a cell starts), then wait
    until an output shows ``sentinel`` (``timeout_s`` seconds at most)."""
    news = page.locator(".jp-toast-button", has_text="No")  # "get notified about Jupyter news?"
    if news.count():
        news.first.click()
    for _attempt in range(3):
        page.locator(".lm-MenuBar-itemLabel", has_text="Run").first.click(timeout=10_000)  # menu bar: Run
        page.locator(".lm-Menu-itemLabel", has_text="Run All Cells").first.click(timeout=10_000)
        try:  # a cell shows [*] or a number once execution started
            page.wait_for_function(
                "() => [...document.querySelectorAll('.jp-InputPrompt')].some(e => /\\[(\\*|\\d+)\\]/.test(e.innerText))",
                timeout=15_000,
                polling=500,
            )
            break
        except Exception:
            page.keyboard.press("Escape")
    page.wait_for_function(
        "s => [...document.querySelectorAll('.jp-OutputArea-output')].some(e => e.innerText.includes(s))",
        arg=sentinel,
        timeout=timeout_s * 1000,
        polling=500,
    )


def _run_in_browser(url: str, out: Path, backend: str, timeout_s: float) -> dict:
    from playwright.sync_api import sync_playwright

    report: dict = {"url": url.split("?")[0], "backend": backend}
    with sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=shutil.which("chromium") or "/usr/bin/chromium",
            headless=True,
            args=["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
        )
        page = browser.new_page(viewport={"width": 1500, "height": 1000})
        start = time.time()
        page.goto(url, wait_until="domcontentloaded", timeout=60_000)
        page.wait_for_selector(".jp-Notebook .jp-Cell", timeout=60_000)
        page.wait_for_function(  # the kernel is connected and idle (status bar)
            "() => document.body.innerText.includes('| Idle')", timeout=60_000, polling=500
        )
        report["opened_s"] = round(time.time() - start, 1)
        run_all_cells(page, SENTINEL, timeout_s)
        report["ran_s"] = round(time.time() - start, 1)
        errors = page.eval_on_selector_all(
            ".jp-OutputArea-output[data-mime-type='application/vnd.jupyter.stderr']", "els => els.map(e => e.innerText)"
        )
        tracebacks = [e for e in errors if "Traceback" in e and "Exercise" not in e]
        report["tracebacks_before_sentinel"] = len(tracebacks)
        report["output_images"] = page.eval_on_selector_all(
            ".jp-RenderedImage img", "els => els.filter(e => e.complete && e.naturalWidth > 0).length"
        )
        report["widget_images"] = page.eval_on_selector_all(
            "img.widget-image", "els => els.filter(e => e.complete && e.naturalWidth > 0).length"
        )
        report["widget_image_mean_levels"] = page.eval_on_selector_all("img.widget-image", _MEAN_LEVEL)
        report["sliders"] = page.locator(".widget-slider").count()
        report["play_buttons"] = page.locator(".widget-play").count()
        frames = page.frames[1:]
        report["iframes"] = len(frames)
        # trame views are web components: playwright's locators see through their shadow DOM
        report["iframes_with_canvas_or_img"] = sum(1 for f in frames if f.locator("canvas, img").count() > 0)
        # move the first player's frame slider and watch its picture change (static image or trame iframe)
        slider = page.locator(".widget-slider").first
        slider.scroll_into_view_if_needed()
        player_box = slider.locator("xpath=ancestor::div[contains(@class,'widget-vbox')][1]")
        view = player_box.locator("img.widget-image, iframe").first
        time.sleep(1.0)
        before = view.screenshot()
        handle = slider.locator(".noUi-handle, .slider-handle, [role='slider']").first
        handle.focus()
        for key in ("End", "ArrowLeft", "ArrowLeft"):
            page.keyboard.press(key)
        report["slider_value"] = slider.locator(".widget-readout").first.inner_text()
        changed, after = False, before
        for _ in range(40):
            time.sleep(0.25)
            after = view.screenshot()
            if _pixels(after).shape != _pixels(before).shape or (_pixels(after) != _pixels(before)).any():
                changed = True
                time.sleep(0.5)
                after = view.screenshot()
                break
        report["picture_changed_after_slider"] = changed
        report["picture_mean_level_after_slider"] = round(float(_pixels(after).mean()), 1)
        player_box.scroll_into_view_if_needed()
        out.parent.mkdir(parents=True, exist_ok=True)
        player_box.screenshot(path=str(out))
        # release a proportion slider: the solver re-runs and the status line changes
        legs = page.locator(".widget-slider", has=page.locator(".widget-label", has_text="legs")).first
        editor_box = legs.locator("xpath=ancestor::div[contains(@class,'widget-hbox')][1]")
        status = editor_box.locator(".widget-label", has_text="solved in").first
        before_status = status.inner_text() if status.count() else ""
        legs.scroll_into_view_if_needed()
        legs.locator(".noUi-handle, .slider-handle, [role='slider']").first.focus()
        start_release = time.time()
        page.keyboard.press("ArrowRight")  # one step (0.05) = one release
        updated = False
        for _ in range(120):
            text = status.inner_text() if status.count() else ""
            if text and text != before_status:
                updated = True
                break
            time.sleep(0.25)
        report["proportion_slider_value"] = legs.locator(".widget-readout").first.inner_text()
        report["proportion_status"] = status.inner_text() if status.count() else ""
        report["proportion_view_updated"] = updated
        report["proportion_release_to_update_s"] = round(time.time() - start_release, 2)
        time.sleep(0.5)
        editor_box.screenshot(path=str(out.with_name(out.stem + "_editor.png")))
        page.screenshot(path=str(out.with_name(out.stem + "_page.png")))
        report["screenshot"] = str(out)
        report["total_s"] = round(time.time() - start, 1)
        browser.close()
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--out", default=str(Path(tempfile.gettempdir()) / "notebook04_chromium.png"), help="screenshot file (PNG)"
    )
    parser.add_argument(
        "--backend", choices=("static", "trame"), default="static", help="PYVISTA_JUPYTER_BACKEND for the kernel"
    )
    parser.add_argument("--timeout", type=float, default=240.0, help="seconds to wait for the notebook to finish")
    args = parser.parse_args(argv)
    if not shutil.which("chromium") and not Path("/usr/bin/chromium").exists():
        print("chromium not found: apt-get install -y chromium", file=sys.stderr)
        return 1
    folder = Path(tempfile.mkdtemp(prefix="motionlab_nb04_"))
    _copy_without_outputs(NOTEBOOK, folder / NOTEBOOK.name)
    port, token = _free_port(), secrets.token_hex(16)
    log_path = folder / "jupyterlab.log"
    with open(log_path, "w") as log:
        server = _start_lab(folder, port, token, args.backend, log)
        try:
            _wait_for_server(port, token)
            url = f"http://127.0.0.1:{port}/lab/tree/{NOTEBOOK.name}?token={token}&reset"
            report = _run_in_browser(url, Path(args.out), args.backend, args.timeout)
        except Exception as e:  # report, then stop the server below
            report = {"error": f"{type(e).__name__}: {e}", "log": str(log_path)}
        finally:
            server.send_signal(signal.SIGTERM)  # SIGINT would ask for confirmation
            try:
                server.wait(timeout=15)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
    ok = (
        "error" not in report
        and report["tracebacks_before_sentinel"] == 0
        and report["output_images"] > 0
        and report["sliders"] > 0
        and report["picture_changed_after_slider"]
        and report["picture_mean_level_after_slider"] > 0
        and report["proportion_view_updated"]
        and (args.backend != "trame" or report["iframes_with_canvas_or_img"] > 0)
        and (args.backend != "static" or report["widget_images"] > 0)
    )
    report["ok"] = ok
    print(json.dumps(report, indent=2))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
