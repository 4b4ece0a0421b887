"""app.py launches a Gradio 6 page on 127.0.0.1 at $PORT."""

import os
import socket
import subprocess
import sys
import time
import urllib.request

from conftest import REPO


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_app_py_serves_on_port_env():
    port = _free_port()
    env = {**os.environ, "PORT": str(port)}
    env.pop("HOST", None)
    proc = subprocess.Popen(
        [sys.executable, "app.py"], cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    try:
        deadline = time.time() + 90
        html = None
        while time.time() < deadline and proc.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as r:
                    html = r.read().decode()
                    break
            except OSError:
                time.sleep(0.5)
        assert html is not None, proc.stdout.read() if proc.poll() is not None else "no answer in 90 s"
        assert "Motion Mamba Studio" in html
        # bound to loopback only by default
        with socket.socket() as s:
            s.settimeout(1)
            lan = socket.gethostbyname(socket.gethostname())
            if not lan.startswith("127."):
                assert s.connect_ex((lan, port)) != 0
    finally:
        proc.terminate()
        proc.wait(timeout=20)
