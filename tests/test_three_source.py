"""three.js without npm: the pip-only path of a hosted space.

With node_modules/three hidden from the app (MMS_THREE_DIR points at nothing) and three.js
served by a local HTTP mirror laid out like the CDN (MMS_THREE_URL), the demo's viewer loads
every module file from the mirror, checked against the pinned sha384 hashes, and plays a
generated motion; the page says where three.js came from. A mirror serving other bytes, or
none at all, gives a message in the viewer instead of a blank box. The pinned hashes are
those of the installed package, for every file the viewer's imports pull in.
"""

from __future__ import annotations

import json
import urllib.error
import urllib.request

import pytest
from conftest import REPO, artifact, pip_only_env, run_app, study_setup, three_mirror
from test_browser import generate_and_wait, set_timeline, viewer_frame
from test_study_browser import study_frames

from app import viewer


def test_manifest_pins_the_installed_three_and_covers_every_viewer_import():
    manifest = viewer.three_manifest()
    assert manifest == viewer.build_three_manifest(REPO / "node_modules" / "three", REPO / "static" / "viewer.js")
    assert json.loads((REPO / "package.json").read_text())["dependencies"]["three"] == manifest["version"]
    # three.module.js imports three.core.js and GLTFLoader its utils: modules imported by other
    # modules are in the integrity table too, not only the ones viewer.js names
    assert {"build/three.core.js", "examples/jsm/utils/BufferGeometryUtils.js"} <= set(manifest["files"])


def test_source_is_node_modules_else_the_pinned_cdn_else_none(tmp_path, monkeypatch):
    monkeypatch.delenv("MMS_THREE_URL", raising=False)
    local = viewer.three_source()
    assert local.kind == "local" and local.importmap()["imports"]["three"].endswith("/build/three.module.js")
    assert "integrity" not in local.importmap()

    monkeypatch.setattr(viewer, "THREE", tmp_path / "missing")
    cdn = viewer.three_source()
    version = viewer.three_manifest()["version"]
    assert cdn.kind == "remote" and cdn.base == f"https://cdn.jsdelivr.net/npm/three@{version}/"
    assert cdn.importmap()["integrity"][cdn.base + "build/three.core.js"].startswith("sha384-")
    assert "cdn.jsdelivr.net" in cdn.label and viewer.three_missing_html() is None
    assert viewer.THREE not in viewer.static_paths()  # nothing to serve locally

    monkeypatch.setenv("MMS_THREE_URL", "http://mirror.example/three")
    assert viewer.three_source().base == "http://mirror.example/three/"
    monkeypatch.setenv("MMS_THREE_URL", "")
    assert viewer.three_source().kind == "none" and "MMS_THREE_URL" in viewer.three_missing_html()


@pytest.fixture(scope="module")
def mirror(tmp_path_factory):
    """A local stand-in for the CDN: the npm package laid out as jsDelivr serves it."""
    root = tmp_path_factory.mktemp("cdn")
    version = viewer.three_manifest()["version"]
    (root / f"three@{version}").symlink_to(REPO / "node_modules" / "three")
    with three_mirror(root) as m:
        yield {**m, "base": f"{m['url']}three@{version}/"}


@pytest.fixture(scope="module")
def pip_only(tmp_path_factory, mirror):
    """The demo as a pip-only host runs it: no node_modules, three.js from the mirror."""
    out = tmp_path_factory.mktemp("outputs")
    with run_app(out, pip_only_env(out, mirror["url"])) as srv:
        yield {**srv, "mirror": mirror, "base": mirror["base"]}


def test_pip_only_host_plays_a_motion_with_three_from_the_mirror(browser, pip_only):
    base = pip_only["url"].rstrip("/")
    # the app serves no three.js of its own: node_modules is hidden from it
    with pytest.raises(urllib.error.HTTPError):
        urllib.request.urlopen(base + viewer.file_url(REPO / "node_modules/three/build/three.module.js"))
    source = urllib.request.urlopen(base + viewer.THREE_SOURCE_ROUTE).read().decode()
    assert pip_only["base"] in source and '"kind": "remote"' in source

    ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(pip_only["url"])
    pg.wait_for_selector("#generate")
    set_timeline(pg, [("a person walks forward", 3)])
    generate_and_wait(pg)
    frame = viewer_frame(pg)
    frame.wait_for_function("viewer.playing && viewer.time > 0.3", timeout=30_000)
    assert frame.evaluate("mmsThree.kind") == "remote" and frame.evaluate("mmsThree.base") == pip_only["base"]
    assert "127.0.0.1" in frame.inner_text("#three-source")  # the page says where three came from
    asked = {p.split("three@", 1)[1].split("/", 1)[1] for p in pip_only["mirror"]["requests"] if "three@" in p}
    assert set(viewer.three_manifest()["files"]) <= asked  # every module file from the mirror
    pg.screenshot(path=str(artifact("docs/screenshot-pip-only.png")))
    ctx.close()
    assert not errors, errors


@pytest.mark.parametrize("fault", ["none", "tampered", "unreachable"])
def test_viewer_says_why_when_three_does_not_load(browser, pip_only, fault):
    """Other bytes than the pinned ones (integrity) or no answer: a message, not a blank box.
    "none" passes the same file through the same interception unchanged, and the viewer starts."""
    ctx = browser.new_context(viewport={"width": 900, "height": 600})
    pg = ctx.new_page()

    def route(r):
        if fault == "unreachable":
            r.abort()
            return
        body = urllib.request.urlopen(r.request.url).read()
        if fault == "tampered":
            body += b"\n// not the pinned bytes\n"
        headers = {"Access-Control-Allow-Origin": "*", "Content-Type": "text/javascript"}
        r.fulfill(status=200, body=body, headers=headers)

    # a module that only another module imports: the import map's integrity table covers it
    pg.route(pip_only["base"] + "examples/jsm/utils/BufferGeometryUtils.js", route)
    pg.goto(pip_only["url"].rstrip("/") + viewer.viewer_page_url())
    if fault == "none":
        pg.wait_for_function("!!window.viewer", timeout=30_000)
        assert pg.evaluate("mmsThree.error") is None
        ctx.close()
        return
    pg.wait_for_function("window.mmsThree && mmsThree.error", timeout=30_000)
    message = pg.inner_text("#message")
    assert "could not start" in message and pip_only["base"] in message and "integrity" in message
    assert pg.evaluate("window.viewer === undefined")  # nothing half-started
    if fault == "tampered":
        pg.screenshot(path=str(artifact("docs/screenshot-three-integrity-error.png")))
    ctx.close()


def test_pip_only_study_page_plays_both_viewers(browser, mirror, tmp_path):
    config = {
        "name": "pip-only",
        "methods": ["motion_mamba", "baseline"],
        "prompts": [{"text": "a person walks forward", "seconds": 2}],
        "seeds": [0],
        "trials_per_participant": 1,
    }
    setup = study_setup(tmp_path, config, "pip-only-admin-token-5e")
    with run_app(setup["out"], {**setup["env"], **pip_only_env(tmp_path, mirror["url"])}) as srv:
        ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
        pg = ctx.new_page()
        errors: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.goto(srv["url"])
        pg.click("#study-start")
        pg.locator("#study-counter", has_text="Trial 1 of 1").wait_for(timeout=120_000)
        for f in study_frames(pg):
            f.wait_for_function("viewer.ready && viewer.playing && viewer.time > 0.3", timeout=60_000)
            assert f.evaluate("mmsThree.base") == mirror["base"]
        ctx.close()
        assert not errors, errors
