"""Shared test fixtures. Tests may read ../shared (CI has it beside the clone)."""

from __future__ import annotations

import contextlib
import os
import re
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")

REPO = Path(__file__).resolve().parents[1]
# Screenshots and measured figures (docs/*.png, results/*.json) are refreshed in the
# checkout only when asked (MMS_WRITE_ARTIFACTS=1); a plain test run writes them under
# pytest's temporary directory, so it leaves the checkout as it found it.
WRITE_ARTIFACTS = os.environ.get("MMS_WRITE_ARTIFACTS") == "1"
_ARTIFACTS_TMP = Path(os.environ.get("TMPDIR", "/tmp")) / f"mms-test-artifacts-{os.getpid()}"


def artifact(relative: str) -> Path:
    """Where a test writes a repo artifact (e.g. "results/load_test.json"); its folder exists."""
    path = (REPO if WRITE_ARTIFACTS else _ARTIFACTS_TMP) / relative
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _named_tests(config: pytest.Config) -> list[tuple[Path, str]]:
    """The tests the command line names (``path::test``, ``path::Class``, any spelling of the
    path), as (resolved file, name without parameters)."""
    here = Path(config.invocation_params.dir)
    out = []
    for arg in getattr(config, "args", ()):
        if "::" in arg:
            path, test = arg.split("::", 1)
            out.append(((here / path).resolve(), test.split("[")[0]))
    return out


# "long" as a whole marker name in a -m expression (pytest's names may hold - . : + as well)
_NAMES_LONG = re.compile(r"(?<![\w.:+\-])long(?![\w.:+\-])")


@pytest.hookimpl(tryfirst=True)  # before pytest's own -m filter, which reads the browser marker
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark ``browser`` every test that drives chromium (it uses the ``browser`` fixture), and
    leave out the tests marked ``long`` unless the ``-m`` expression names them (``-m long``,
    ``-m "long or not long"``; pytest's filter then applies the expression as usual) or the
    command line names the test itself (``pytest tests/test_x.py::test_y``). A ``-m 'not
    long'`` in addopts would do it only until a user's own ``-m browser`` replaced it, and then
    ran the long browser timing too."""
    for item in items:
        if "browser" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.browser)
    if _NAMES_LONG.search(config.getoption("markexpr") or ""):
        return
    named = _named_tests(config)

    def wanted(item) -> bool:
        if item.get_closest_marker("long") is None:
            return True
        test = item.nodeid.split("::", 1)[1].split("[")[0]
        path = Path(item.path).resolve()
        return any(path == p and (test == t or test.startswith(t + "::")) for p, t in named)

    dropped = [item for item in items if not wanted(item)]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = [item for item in items if wanted(item)]


SHARED = Path(os.environ.get("MMS_SHARED", REPO.parent / "shared"))
HML_FIXTURE = SHARED / "fixtures" / "humanml3d"


@pytest.fixture(scope="session")
def hml_fixture_dir() -> Path:
    if not (HML_FIXTURE / "new_joint_vecs" / "012314.npy").is_file():
        pytest.fail(f"the real HumanML3D fixture is missing under {HML_FIXTURE} (set MMS_SHARED)")
    return HML_FIXTURE


@pytest.fixture(scope="session")
def real_features(hml_fixture_dir: Path) -> np.ndarray:
    """(170, 263) float32: the real HumanML3D motion 012314."""
    return np.load(hml_fixture_dir / "new_joint_vecs" / "012314.npy")


@pytest.fixture(scope="session")
def text_encoder():
    from motion_core.nn.text import get_text_encoder

    return get_text_encoder()


BANDAI_ARCHIVE = SHARED / "data" / "bandai-namco-motion.tar.xz"
BANDAI_CACHE = REPO / ".cache" / "bandai-namco"


@pytest.fixture(scope="session")
def bandai_dir() -> Path:
    """The real Bandai Namco BVH archive, unpacked once into .cache/ (gitignored, ~10 s)."""
    from motion_core.data.mocap import unpack_archive

    if not BANDAI_ARCHIVE.is_file():
        pytest.fail(f"the Bandai Namco archive is missing: {BANDAI_ARCHIVE} (set MMS_SHARED)")
    return unpack_archive(BANDAI_ARCHIVE, BANDAI_CACHE)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def run_app(out: Path, env: dict[str, str] | None = None, timeout_s: float = 120) -> Iterator[dict]:
    """`python app.py` in a subprocess on a free port, writing into ``out``; yields
    {"url", "out", "log", "proc", "port"} once the page answers, and stops it afterwards."""
    port = free_port()
    full_env = {**os.environ, "PORT": str(port), "MMS_OUTPUT_DIR": str(out), **(env or {})}
    full_env.pop("HOST", None)
    log_path = out / "server.log"
    log = log_path.open("a")
    proc = subprocess.Popen([sys.executable, "app.py"], cwd=REPO, env=full_env, stdout=log, stderr=subprocess.STDOUT)
    url = f"http://127.0.0.1:{port}/"
    deadline = time.time() + timeout_s
    try:
        while True:
            if proc.poll() is not None:
                pytest.fail("app.py exited:\n" + log_path.read_text())
            try:
                urllib.request.urlopen(url, timeout=2).close()
                break
            except OSError:
                if time.time() > deadline:
                    pytest.fail(f"app.py did not answer in {timeout_s:.0f} s")
                time.sleep(0.5)
        yield {"url": url, "out": out, "log": log_path, "proc": proc, "port": port}
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        log.close()


CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking"]
# The viewer draws at most this many frames a second in the browser tests (a page's
# `window.MMS_MAX_FPS`; users get 30). On software GL one drawn frame took about 100 ms of
# the page's thread, so a playing motion held that thread most of the time and every Gradio
# round trip after it waited; the tests check what is shown, not how smoothly. Timing
# tests ask for the full rate again (FULL_FRAME_RATE).
TEST_VIEWER_FPS = 2
FULL_FRAME_RATE = "window.MMS_MAX_FPS = 30"


@contextlib.contextmanager
def drawn(frame, count: int = 1, timeout_ms: int = 15_000) -> Iterator[None]:
    """Wait, after the block, until the viewer in ``frame`` (a page or a frame) has drawn
    ``count`` frames more than before it: what the block changed is then on the canvas. A fixed
    wait would race the viewer's frame cap (TEST_VIEWER_FPS)."""
    before = frame.evaluate("viewer.renderedFrames")
    yield
    frame.wait_for_function(f"viewer.renderedFrames >= {before + count}", timeout=timeout_ms)


@pytest.fixture(scope="module")
def browser():
    if not Path(CHROMIUM).is_file():
        pytest.fail(f"{CHROMIUM} is missing: bash scripts/setup.sh --dev installs Debian's chromium")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        new_context = b.new_context

        def throttled_context(**kw):
            ctx = new_context(**kw)
            ctx.add_init_script(f"window.MMS_MAX_FPS = {TEST_VIEWER_FPS}")  # every frame, iframes too
            return ctx

        b.new_context = throttled_context
        yield b
        b.close()


@pytest.fixture(scope="session")
def built(tmp_path_factory):
    """A small corpus built through the real CLI (2 workers), shared by the tests that need data."""
    from motion_core.corpus.__main__ import main as corpus_main

    out = tmp_path_factory.mktemp("corpus")
    rc = corpus_main(
        [
            "build",
            str(out),
            "--train",
            "240",
            "--val",
            "10",
            "--test",
            "200",
            "--seq-train",
            "6",
            "--seq-val",
            "1",
            "--seq-test",
            "10",
            "--workers",
            "2",
        ]
    )
    assert rc == 0
    return out


def study_setup(d: Path, config: dict, admin_token: str) -> dict:
    """A study config file, database path, output folder and the server environment in d."""
    import json

    (d / "study.json").write_text(json.dumps(config))
    env = {
        "MMS_MODE": "study",
        "MMS_STUDY_CONFIG": str(d / "study.json"),
        "MMS_STUDY_DB": str(d / "votes.sqlite"),
        "MMS_ADMIN_TOKEN": admin_token,
    }
    out = d / "files"
    out.mkdir()
    return {"dir": d, "env": env, "out": out, "db": d / "votes.sqlite"}


@contextlib.contextmanager
def three_mirror(root: Path) -> Iterator[dict]:
    """A local stand-in for a CDN: ``root`` served over HTTP on 127.0.0.1 with the CORS header a
    CDN sends (module scripts from another origin need it); yields {"url", "requests"}, where
    requests lists every path asked for."""
    import functools
    import http.server
    import threading

    requests: list[str] = []

    class Handler(http.server.SimpleHTTPRequestHandler):
        def end_headers(self) -> None:
            self.send_header("Access-Control-Allow-Origin", "*")
            super().end_headers()

        def do_GET(self) -> None:
            requests.append(self.path)
            super().do_GET()

        def log_message(self, *args) -> None:  # quiet: the test reads ``requests``
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Handler, directory=str(root)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield {"url": f"http://127.0.0.1:{server.server_address[1]}/", "requests": requests}
    finally:
        server.shutdown()
        server.server_close()


def pip_only_env(tmp: Path, mirror_url: str) -> dict[str, str]:
    """The environment of a host that installed with pip only: the app's node_modules/three is
    hidden (MMS_THREE_DIR points at nothing) and three.js comes from ``mirror_url``."""
    import json

    version = json.loads((REPO / "app" / "three_manifest.json").read_text())["version"]
    return {"MMS_THREE_DIR": str(tmp / "no-node-modules"), "MMS_THREE_URL": f"{mirror_url}three@{version}/"}


class PostgresCluster:
    """A throw-away PostgreSQL cluster (Debian's postgresql package) on a Unix socket in a
    fresh folder: no TCP port, trust authentication, deleted at the end of the session."""

    def __init__(self) -> None:
        import glob
        import shutil
        import tempfile

        bins = sorted(glob.glob("/usr/lib/postgresql/*/bin"), key=lambda p: int(p.split("/")[-2]))
        if not bins or not Path(bins[-1], "initdb").is_file():
            pytest.fail("PostgreSQL is missing: bash scripts/setup.sh --dev installs Debian's postgresql")
        self.bin = Path(bins[-1])
        # short path: a Unix socket's path is limited to ~107 bytes; under /tmp so that the
        # postgres user can reach it (pytest's tmp_path is private to the user running pytest)
        self.dir = Path(tempfile.mkdtemp(prefix="mms-pg-"))
        self._as: list[str] = []
        if os.getuid() == 0:  # PostgreSQL refuses to run as root
            shutil.chown(self.dir, "postgres")
            self._as = ["runuser", "-u", "postgres", "--"]
        data = self.dir / "data"
        self._run("initdb", "-D", str(data), "-A", "trust", "-U", "mms", "--no-sync")
        opts = f"-k {self.dir} -p 5432 -c listen_addresses=''"
        self._run("pg_ctl", "-D", str(data), "-o", opts, "-l", str(self.dir / "log"), "-w", "start")
        self._n = 0

    def _run(self, tool: str, *args: str) -> None:
        res = subprocess.run([*self._as, str(self.bin / tool), *args], capture_output=True, text=True)
        if res.returncode != 0:
            pytest.fail(f"{tool} failed:\n{res.stdout}\n{res.stderr}")

    def url(self, database: str) -> str:
        return f"postgresql+psycopg://mms@/{database}?host={self.dir}&port=5432"

    def new_database(self) -> str:
        """A fresh, empty database; its SQLAlchemy URL."""
        import psycopg

        self._n += 1
        name = f"study_{self._n}"
        with psycopg.connect(f"host={self.dir} port=5432 user=mms dbname=postgres", autocommit=True) as con:
            con.execute(f"CREATE DATABASE {name}")
        return self.url(name)

    def stop(self) -> None:
        import shutil

        self._run("pg_ctl", "-D", str(self.dir / "data"), "-m", "fast", "-w", "stop")
        shutil.rmtree(self.dir, ignore_errors=True)


@pytest.fixture(scope="session")
def postgres() -> Iterator[PostgresCluster]:
    cluster = PostgresCluster()
    try:
        yield cluster
    finally:
        cluster.stop()
