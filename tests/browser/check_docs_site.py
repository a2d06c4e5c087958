"""Open the built documentation site in headless Chromium: every figure loads, no internal link is broken.

Not a pytest test (it needs Debian's ``chromium``, the ``playwright`` package and a built site);
``.ci/run`` runs it after ``scripts/build_docs.sh``::

    apt-get install -y chromium
    pip install playwright          # never `playwright install`: we drive /usr/bin/chromium
    bash scripts/build_docs.sh && python tests/browser/check_docs_site.py --out /tmp/motionlab_docs

What it does:

1. serves ``docs/_build/html`` on 127.0.0.1 (a random free port) from a thread;
2. visits every HTML page of the site (starting at ``index.html`` and following internal links);
   on each, waits for the load event and lists the images that did not load
   (``complete && naturalWidth > 0``) and every internal link;
3. checks every internal link: the target file exists and, for ``#fragment`` links, the target
   page has an element with that id;
4. for the notebooks stored with outputs, requires at least one figure on the page;
5. saves screenshots of notebooks 00, 04 and 05 (the first figure in view) and of the home page
   into ``--out``; prints a JSON summary. Requests to other hosts (the MathJax CDN) are blocked,
   as on an offline machine; they are counted, not failures;
6. opens every notebook page that has a web player (``motionlab.viz.web``) again, from ``file://``
   with every non-file request blocked: the player must start (three.js loaded, a WebGL context on
   its canvas); the check presses play and requires the canvas to change between a first
   screenshot and one taken 0.5, 0.87 or 1.16 s after it, kept in ``--out/players/``, and in every
   one of those shots the skeletons must be in view: some figure pixels (saturated colours, not the
   grey floor and background), none on the canvas edge. Every notebook that shows motion
   (:data:`MOTION_NOTEBOOKS`) must have a working player, drawn by three.js;
7. writes a page with one player and no three.js (as a notebook in JupyterLab where
   ``scripts/vendor_three.sh`` never ran) and checks it the same way: it must draw on the
   browser's 2D canvas, move, and keep the figures in view.

Exit status 0 when every check passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import shutil
import sys
import threading
import time
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urldefrag, urlparse

REPO = Path(__file__).resolve().parents[2]
SITE = REPO / "docs" / "_build" / "html"
SCREENSHOTS = {
    "00_quaternions_and_fk": "notebooks/00_quaternions_and_fk.html",
    "04_playback_and_bone_proportions": "notebooks/04_playback_and_bone_proportions.html",
    "05_motion_graphs": "notebooks/05_motion_graphs.html",
}
MOTION_NOTEBOOKS = (
    "00_quaternions_and_fk",
    "01_preprocessing",
    "03_latent_iteration",
    "04_playback_and_bone_proportions",
    "05_motion_graphs",
    "06_keypose_interpolation",
    "07_expanding_a_database",
)
"""Notebooks that show motion: each page must hold at least one working web player."""


def _stored_notebooks() -> list[str]:
    sys.path.insert(0, str(REPO / "scripts"))
    try:
        from store_notebook_outputs import STORED
    finally:
        sys.path.pop(0)
    return list(STORED)


class _Ids(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        for key, value in attrs:
            if key in ("id", "name") and value:
                self.ids.add(value)


@functools.cache
def _ids_of(path: Path) -> frozenset:
    parser = _Ids()
    parser.feed(path.read_text(encoding="utf-8", errors="replace"))
    return frozenset(parser.ids)


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:  # no line per request
        pass


def _serve(folder: Path):
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def _local_file(url: str, base: str) -> Path | None:
    """The site file a same-origin URL points at (index.html for a folder), or None if outside."""
    path = unquote(urlparse(url).path)
    if not url.startswith(base):
        return None
    rel = path[len(urlparse(base).path) :]
    target = SITE / rel
    if rel == "" or rel.endswith("/"):
        target = target / "index.html"
    return target


def _changed_fraction(a: bytes, b: bytes) -> float:
    """Share of pixels that differ between two PNG screenshots of the same size."""
    import io

    import numpy as np
    from PIL import Image

    x, y = (np.asarray(Image.open(io.BytesIO(d)).convert("RGB"), dtype=np.int16) for d in (a, b))
    return float((np.abs(x - y).sum(axis=-1) > 0).mean()) if x.shape == y.shape else 1.0


FIGURE_SPREAD = 24
"""A pixel belongs to a skeleton when its colour channels spread by more than this (0-255): the
player's background and grid are greys (spread under 16), the skeletons the saturated colours of
``motionlab.viz.scene.PALETTE``, shaded."""


def _figure_box(png: bytes) -> dict:
    """Where the skeletons are in a canvas screenshot: ``share`` of the pixels that are figure, and
    whether their bounding box touches an edge of the canvas (``touches``: a figure cut by the view)."""
    import io

    import numpy as np
    from PIL import Image

    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)
    figure = (rgb.max(axis=-1) - rgb.min(axis=-1)) > FIGURE_SPREAD
    if not figure.any():
        return {"share": 0.0, "touches": False}
    rows, cols = np.flatnonzero(figure.any(axis=1)), np.flatnonzero(figure.any(axis=0))
    h, w = figure.shape
    touches = rows[0] <= 1 or rows[-1] >= h - 2 or cols[0] <= 1 or cols[-1] >= w - 2
    return {"share": round(float(figure.mean()), 4), "touches": bool(touches)}


def _in_view(shots: list[bytes]) -> str:
    """Empty when the skeletons are wholly in view in every shot; else why not."""
    for k, png in enumerate(shots):
        box = _figure_box(png)
        if box["share"] < 0.001:
            return f"no figure in view in shot {k}"
        if box["touches"]:
            return f"the figure leaves the view in shot {k} (it touches the canvas edge)"
    return ""


def _check_player(browser, rel: str, out: Path, timeout_ms: int = 20_000, site: Path = SITE) -> dict:
    """Open ``site / rel`` from file:// (network blocked), start its first player and watch it move;
    a player drawn by three.js must have a WebGL context, one drawn on the 2D canvas (no three.js on
    the page) is checked the same way otherwise."""
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file://") else r.abort())
    result: dict = {"page": rel, "ok": False}
    try:
        page.goto((site / rel).resolve().as_uri(), wait_until="load", timeout=timeout_ms)
        result["players"] = page.locator(".motionlab-player").count()
        player = page.locator(".motionlab-player").first
        player.scroll_into_view_if_needed()
        try:
            page.wait_for_selector(".motionlab-player[data-ready='1']", timeout=timeout_ms)
        except Exception:
            result["why"] = "player did not start: " + (player.locator(".motionlab-message").text_content() or "")
            return result
        canvas = player.locator("canvas")
        result["renderer"] = player.get_attribute("data-renderer")
        result["webgl"] = result["renderer"] == "canvas" or canvas.evaluate(
            "c => !!(c.getContext('webgl2') || c.getContext('webgl'))"
        )
        player.locator("button.motionlab-play").click()
        page.wait_for_timeout(200)
        stem = Path(rel).stem
        (out / "players").mkdir(parents=True, exist_ok=True)
        start, changed = time.monotonic(), 0.0
        first = canvas.screenshot(path=str(out / "players" / f"{stem}_0.png"))
        shots = [first]
        # Later shots 0.5, 0.87 and 1.16 s after the first began (whatever each shot took): a
        # loop whose length divides one gap shows the same frame in that shot, and no loop of a
        # few frames or more divides all three.
        for k, gap in enumerate((0.5, 0.87, 1.16), start=1):
            page.wait_for_timeout(max(0.0, 1000.0 * (gap - (time.monotonic() - start))))
            later = canvas.screenshot(path=str(out / "players" / f"{stem}_{k}.png"))
            changed = max(changed, _changed_fraction(first, later))
            shots.append(later)
        result["changed"] = round(changed, 4)
        result["errors"] = errors
        result["framing"] = _in_view(shots)  # pixels that change are not enough: the figure must be in view
        result["ok"] = bool(result["webgl"]) and result["changed"] > 0.001 and not errors and not result["framing"]
        if not result["ok"]:
            result["why"] = (
                "no WebGL context" if not result["webgl"] else errors[0] if errors else result["framing"] or "no motion"
            )
    finally:
        page.close()
    return result


def check(out: Path, timeout_ms: int = 30_000) -> dict:
    from playwright.sync_api import sync_playwright

    server = _serve(SITE)
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    report: dict = {"pages": 0, "images": 0, "broken_images": [], "links_checked": 0, "broken_links": [],
                    "external_requests_blocked": 0, "figures_per_notebook": {}, "screenshots": [],
              "players_per_notebook": {}, "players": []}  # fmt: skip
    stored = _stored_notebooks()
    out.mkdir(parents=True, exist_ok=True)
    start = time.time()
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(
                executable_path=shutil.which("chromium") or "/usr/bin/chromium",
                headless=True,
                args=["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"],
            )
            page = browser.new_page(viewport={"width": 1400, "height": 1000})

            def route(r):
                if r.request.url.startswith(base):
                    r.continue_()
                else:
                    report["external_requests_blocked"] += 1
                    r.abort()

            page.route("**/*", route)
            todo, seen, links = [base + "index.html"], set(), set()
            while todo:
                url = todo.pop()
                if url in seen:
                    continue
                seen.add(url)
                page.goto(url, wait_until="load", timeout=timeout_ms)
                report["pages"] += 1
                images = page.eval_on_selector_all(
                    "img", "els => els.map(e => [e.currentSrc || e.src, e.complete && e.naturalWidth > 0])"
                )
                report["images"] += len(images)
                report["broken_images"] += [{"page": url[len(base) :], "src": src} for src, ok in images if not ok]
                rel = url[len(base) :]
                if rel.startswith("notebooks/"):
                    name = Path(rel).stem
                    report["figures_per_notebook"][name] = page.locator(".cell_output img").count()
                    report["players_per_notebook"][name] = page.locator(".motionlab-player").count()
                for href in page.eval_on_selector_all("a[href]", "els => els.map(e => e.href)"):
                    if not href.startswith(base):
                        continue
                    links.add((rel, href))
                    target, _ = urldefrag(href)
                    if target.endswith(".html") and target not in seen:
                        todo.append(target)
                if rel in {"index.html", *SCREENSHOTS.values()}:
                    name = "index" if rel == "index.html" else Path(rel).stem
                    figure = page.locator(".cell_output img").first
                    if figure.count():
                        figure.scroll_into_view_if_needed()
                        page.evaluate("window.scrollBy(0, -250)")
                    shot = out / f"docs_{name}.png"
                    page.screenshot(path=str(shot))
                    report["screenshots"].append(str(shot))
            for name, count in sorted(report["players_per_notebook"].items()):
                if count:
                    report["players"].append(_check_player(browser, f"notebooks/{name}.html", out))
            report["player_without_three_js"] = _check_player(browser, _page_without_three_js(out), out, site=out)
            browser.close()
        for page_rel, href in sorted(links):
            target_url, fragment = urldefrag(href)
            report["links_checked"] += 1
            target = _local_file(target_url, base)
            if target is None or not target.exists():
                report["broken_links"].append({"page": page_rel, "href": href[len(base) :], "why": "no such file"})
            elif fragment and target.suffix == ".html" and unquote(fragment) not in _ids_of(target):
                report["broken_links"].append({"page": page_rel, "href": href[len(base) :], "why": "no such anchor"})
    finally:
        server.shutdown()
    missing_figures = [n for n in stored if report["figures_per_notebook"].get(n, 0) == 0]
    report["stored_notebooks_without_figures"] = missing_figures
    working = {Path(p["page"]).stem for p in report["players"] if p["ok"] and p.get("renderer") == "three"}
    report["motion_notebooks_without_a_working_player"] = [n for n in MOTION_NOTEBOOKS if n not in working]
    report["seconds"] = round(time.time() - start, 1)
    report["ok"] = (
        bool(report["pages"])
        and not report["broken_images"]
        and not report["broken_links"]
        and not missing_figures
        and not report["motion_notebooks_without_a_working_player"]
        and report["player_without_three_js"]["ok"]
        and report["player_without_three_js"].get("renderer") == "canvas"
    )
    return report


def _page_without_three_js(out: Path) -> str:
    """Write a page holding one player and no three.js (as in JupyterLab where none was vendored):
    a synthetic walker 1.75 m tall beside a 1.3x-legs one; returns its name in ``out``."""
    from motionlab import synthetic
    from motionlab.core import humanoid
    from motionlab.viz import web

    sk = humanoid.canonical_skeleton(1.75)
    walks = [
        synthetic.generate("walk", s, num_frames=90, fps=30, seed=i)
        for i, s in enumerate((sk, humanoid.scale_bones(sk, legs=1.3)))
    ]
    fragment = web.player_html(walks, names=["walker", "long legs"], spacing=1.0, three_js=None)
    (out / "player_without_three_js.html").write_text(f"<!doctype html><html><body>{fragment}</body></html>")
    return "player_without_three_js.html"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="/tmp/motionlab_docs", help="folder for the screenshots")
    args = parser.parse_args(argv)
    if not (SITE / "index.html").exists():
        print(f"{SITE}/index.html not found: build the site first (bash scripts/build_docs.sh)", file=sys.stderr)
        return 1
    if not shutil.which("chromium") and not Path("/usr/bin/chromium").exists():
        print("chromium not found: apt-get install -y chromium", file=sys.stderr)
        return 1
    report = check(Path(args.out))
    print(json.dumps(report, indent=2))
    return 0 if report["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
