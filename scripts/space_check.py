"""The browser half of scripts/space_check.sh: a pip-only space, driven as its visitors would.

    python scripts/space_check.py --space CLONE --python VENV/bin/python --mirror DIR

Starts ``python app.py`` from CLONE with the given interpreter (a venv that has only
requirements.txt), node_modules absent, three.js from a local mirror of DIR (laid out like the
CDN: DIR/three@VERSION/...) through MMS_THREE_URL. Measures the cold start (process start to
the first generation served through the HTTP API), then checks in Debian's chromium that a
generated motion plays in the demo's viewer and that the study page's two viewers play.
Prints the figures as JSON; exits non-zero on the first failed check.
"""

from __future__ import annotations

import argparse
import functools
import http.server
import json
import os
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def serve_mirror(root: Path) -> str:
    """A stand-in for the CDN on 127.0.0.1 (with the CORS header a CDN sends)."""

    class Handler(http.server.SimpleHTTPRequestHandler):
        def end_headers(self) -> None:
            self.send_header("Access-Control-Allow-Origin", "*")
            super().end_headers()

        def log_message(self, *args) -> None:
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Handler, directory=str(root)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return f"http://127.0.0.1:{server.server_address[1]}/"


def start_app(space: Path, python: str, env: dict[str, str], log: Path) -> tuple[subprocess.Popen, str]:
    port = free_port()
    full = {**os.environ, **env, "PORT": str(port)}
    full.pop("HOST", None)
    proc = subprocess.Popen([python, "app.py"], cwd=space, env=full, stdout=log.open("w"), stderr=subprocess.STDOUT)
    return proc, f"http://127.0.0.1:{port}/"


def wait_page(proc: subprocess.Popen, url: str, log: Path, timeout_s: float = 180) -> None:
    deadline = time.time() + timeout_s
    while True:
        if proc.poll() is not None:
            sys.exit("app.py exited:\n" + log.read_text())
        try:
            urllib.request.urlopen(url, timeout=2).close()
            return
        except OSError:
            if time.time() > deadline:
                sys.exit(f"app.py did not answer in {timeout_s:.0f} s")
            time.sleep(0.1)


def stop(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def check(ok: bool, what: str) -> None:
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        sys.exit(1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--space", type=Path, required=True)
    ap.add_argument("--python", required=True)
    ap.add_argument("--mirror", type=Path, required=True)
    ap.add_argument("--shots", type=Path, default=None, help="folder for screenshots")
    args = ap.parse_args()
    from gradio_client import Client
    from playwright.sync_api import sync_playwright

    version = json.loads((args.space / "app" / "three_manifest.json").read_text())["version"]
    check(not (args.space / "node_modules").exists(), "the space has no node_modules")
    base = serve_mirror(args.mirror) + f"three@{version}/"
    work = Path(os.environ.get("TMPDIR", "/tmp")) / f"mms-space-check-{os.getpid()}"
    work.mkdir(parents=True, exist_ok=True)
    shots = args.shots or work
    shots.mkdir(parents=True, exist_ok=True)
    env = {"MMS_THREE_URL": base, "MMS_OUTPUT_DIR": str(work / "outputs")}
    figures: dict[str, object] = {"three_url": base}

    # cold start: `python app.py` to the first generation served
    t0 = time.perf_counter()
    proc, url = start_app(args.space, args.python, env, work / "demo.log")
    try:
        wait_page(proc, url, work / "demo.log")
        figures["page_answers_s"] = round(time.perf_counter() - t0, 1)
        res = Client(url, verbose=False).predict(
            json.dumps({"text": ["a person walks forward"], "seconds": [3.0]}),
            "motion_mamba",
            0,
            api_name="/generate_motion",
        )
        figures["first_generation_served_s"] = round(time.perf_counter() - t0, 1)
        check(res["frames"] == 60, f"first generation served after {figures['first_generation_served_s']} s")

        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--headless", "--no-sandbox", "--disable-gpu"])
            pg = browser.new_page(viewport={"width": 1400, "height": 1000})
            pg.goto(url)
            pg.wait_for_selector("#generate")
            frame = pg.wait_for_selector("iframe.mms-viewer", timeout=60_000).content_frame()
            frame.wait_for_function("!!window.viewer", timeout=60_000)
            pg.click("#generate")
            frame.wait_for_function("viewer.ready && viewer.playing && viewer.time > 0.3", timeout=180_000)
            source = frame.evaluate("mmsThree")
            check(source["kind"] == "remote" and source["base"] == base, "demo viewer: three.js from the mirror")
            check(frame.evaluate("viewer.frames") > 0, f"demo viewer plays {frame.evaluate('viewer.frames')} frames")
            pg.screenshot(path=str(shots / "space-check-demo.png"))
            browser.close()
    finally:
        stop(proc)

    # the study page: both viewers play a trial
    cfg = work / "study.json"
    cfg.write_text(
        json.dumps(
            {
                "name": "space-check",
                "methods": ["motion_mamba", "baseline"],
                "prompts": [{"text": "a person walks forward", "seconds": 2}],
                "seeds": [0],
                "trials_per_participant": 1,
            }
        )
    )
    study_env = {**env, "MMS_MODE": "study", "MMS_STUDY_CONFIG": str(cfg), "MMS_STUDY_DB": str(work / "s.sqlite")}
    proc, url = start_app(args.space, args.python, study_env, work / "study.log")
    try:
        wait_page(proc, url, work / "study.log")
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM, args=["--headless", "--no-sandbox", "--disable-gpu"])
            pg = browser.new_page(viewport={"width": 1400, "height": 1000})
            pg.goto(url)
            pg.click("#study-start")
            pg.locator("#study-counter", has_text="Trial 1 of 1").wait_for(timeout=180_000)
            deadline = time.time() + 60
            while len(frames := [f for f in pg.frames if "viewer.html" in f.url]) < 2 and time.time() < deadline:
                pg.wait_for_timeout(100)
            check(len(frames) == 2, "study page: two viewers")
            for f in frames:
                playing = "!!window.viewer && viewer.ready && viewer.playing && viewer.time > 0.3"
                f.wait_for_function(playing, timeout=60_000)
                check(f.evaluate("mmsThree.kind") == "remote", "study viewer: three.js from the mirror, playing")
            pg.screenshot(path=str(shots / "space-check-study.png"), full_page=True)
            browser.close()
    finally:
        stop(proc)
    print(json.dumps(figures, indent=1))


if __name__ == "__main__":
    main()
