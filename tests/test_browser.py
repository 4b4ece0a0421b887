"""The demo in a real browser: Debian's chromium driven by Playwright, against `python app.py`.

Covers the app issue's checks: the page loads, a 2-segment timeline is composed, every
method generates and the viewer draws and plays it, downloads validate, every bad input
shows its message (and keeps the previous result), two sessions stay apart. Screenshots go
to docs/ for the README; the click-to-playing time goes to results/browser_timing.json (both
in the checkout with MMS_WRITE_ARTIFACTS=1, else in a temporary folder: see conftest).
"""

from __future__ import annotations

import itertools
import json
import os
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from conftest import FULL_FRAME_RATE, REPO, artifact, drawn, run_app
from test_export import validate_gltf

import motion_core

TWO_SEGMENTS = [("a person walks forward", 5), ("a person waves with the right hand", 5)]  # 10 s
METHODS = [m["name"] for m in motion_core.methods()]


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """`python app.py` (the demo) on a free port, with its own output directory. Generation
    is rate limited at 120 a minute, burst 30, not the default 20 / 10: with 10 DDIM steps a
    timing test's 16 generations in one session came faster than one per 3 s and the 13th
    was refused ("Slow down"), which the test saw as a viewer that never loaded. The
    limiter's own behaviour is tested in test_study.py and test_load.py."""
    with run_app(tmp_path_factory.mktemp("outputs"), {"MMS_RATE_GENERATE": "120/30"}) as srv:
        yield srv


@pytest.fixture
def page(request, browser, server):
    ctx = browser.new_context(viewport={"width": 1400, "height": 1000}, accept_downloads=True)
    if request.node.get_closest_marker("long"):  # the timing tests: the viewer as users get it
        ctx.add_init_script(FULL_FRAME_RATE)
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(server["url"])
    pg.wait_for_selector("#generate")
    yield pg
    ctx.close()
    assert not errors, errors


def viewer_frame(pg):
    """The viewer's frame once its script runs. Gradio can show #generate before it mounts
    the viewer's iframe, so on a busy machine ``pg.frames`` may not hold it yet (a clean-clone
    CI run failed here with StopIteration): wait for the element, then for its document."""
    frame = pg.wait_for_selector("iframe.mms-viewer", timeout=60_000).content_frame()
    assert frame is not None
    frame.wait_for_function("!!window.viewer && location.pathname.endsWith('viewer.html')", timeout=60_000)
    return frame


def set_timeline(pg, segments) -> None:
    """Make the timeline exactly ``segments`` through the UI's own buttons and fields."""

    def rows() -> int:
        return pg.locator("[id^=seg-row-]:visible").count()

    while (n := rows()) > len(segments):
        pg.click(f"#seg-remove-{n - 1}")
        pg.locator(f"#seg-row-{n - 1}").wait_for(state="hidden")
    while (n := rows()) < len(segments):
        pg.click("#seg-add")
        pg.locator(f"#seg-row-{n}").wait_for(state="visible")
    for i, (text, sec) in enumerate(segments):
        pg.fill(f"#seg-text-{i} textarea", text)
        pg.fill(f"#seg-sec-{i} input", str(sec))
    # Gradio sends a box's value on blur (change); leave the last box before acting on the form
    pg.locator(f"#seg-sec-{len(segments) - 1} input").blur()


def pick_method(pg, name: str) -> None:
    display = next(m["display_name"] for m in motion_core.methods() if m["name"] == name)
    pg.locator("#method label", has_text=display).click()
    # wait for the pick's own update (the method's note, sampler and sliders): a seed typed
    # before it came back was sometimes lost (the page sent seed 0; clean-clone CI, 3 of 11
    # local runs). A click on the method already shown sends no update at all: this wait
    # passes at once there, and a late update used to lose the seed all the same
    pg.wait_for_function(
        "(d) => document.querySelector('#method-info').innerText.includes(d)", arg=display, timeout=30_000
    )


def generate_and_wait(pg, timeout_s: float = 180) -> tuple[float, str]:
    """Click Generate; returns (ms from the click to the viewer drawing the new motion, its URL).

    The click time is taken by a listener in the page, at the click event itself: Playwright's
    own click first waits for the button to be stable over animation frames, which in a
    software-rendered page busy drawing the viewer adds ~0.6 s that no user would see.
    """
    frame = viewer_frame(pg)
    old = frame.evaluate("viewer.url")
    pg.evaluate(
        "document.querySelector('#generate').addEventListener('click', "
        "() => { window.__clickedAt = Date.now(); }, {capture: true, once: true})"
    )
    pg.click("#generate")
    frame.wait_for_function(
        "(old) => viewer.url !== old && viewer.ready && viewer.loadedAt !== null",
        arg=old,
        timeout=timeout_s * 1000,
        polling=20,
    )
    return frame.evaluate("viewer.loadedAt") - pg.evaluate("window.__clickedAt"), frame.evaluate("viewer.url")


CANVAS_STATS = """() => {
  const c = document.querySelector('#stage canvas');
  const g = document.createElement('canvas');
  g.width = c.width; g.height = c.height;
  const x = g.getContext('2d');
  x.drawImage(c, 0, 0);
  const d = x.getImageData(0, 0, g.width, g.height).data;
  let coloured = 0, magenta = 0, sum = 0, all = 0;
  for (let i = 0; i < d.length; i += 4) {
    all = (all * 31 + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) % 1000000007;
    const mx = Math.max(d[i], d[i + 1], d[i + 2]), mn = Math.min(d[i], d[i + 1], d[i + 2]);
    if (mx - mn > 80) { coloured++; sum = (sum * 31 + i) % 1000000007; }
    if (d[i] - d[i + 1] > 50 && d[i + 2] - d[i + 1] > 20) magenta++;  // key-frame ghosts
  }
  const n = d.length / 4;
  return {coloured: coloured / n, magenta: magenta / n, signature: sum, picture: all};
}"""


def toast_texts(pg) -> list[str]:
    return [t.strip() for t in pg.locator("[data-testid='toast-text']").all_inner_texts()]


def import_timeline(pg, segments) -> None:
    """Make the timeline ``segments`` through the Import / export panel (open) in one event,
    and wait until the rows show it."""
    doc = {"text": [t for t, _ in segments], "seconds": [s for _, s in segments]}
    pg.fill("#timeline-json textarea", json.dumps(doc))
    pg.click("#timeline-import")
    last = len(segments) - 1
    pg.wait_for_function(
        f"""() => {{
          const rows = Array.from(document.querySelectorAll('[id^=seg-row-]')).filter((r) => r.offsetParent !== null);
          const box = document.querySelector('#seg-text-{last} textarea');
          return rows.length === {len(segments)} && box && box.value === {json.dumps(segments[-1][0])};
        }}"""
    )


def wait_toast(pg, fragment: str, timeout_s: float = 20) -> str:
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        for t in toast_texts(pg):
            if fragment in t:
                return t
        time.sleep(0.1)
    raise AssertionError(f"no message containing {fragment!r}; saw {toast_texts(pg)}")


def close_toasts(pg) -> None:
    """Close the open messages and wait until none is left. A message can close itself (its
    timer) while being clicked: its button turns inert and leaves the page, which a plain
    click waited on for 30 s in a loaded CI run; such a message is gone all the same."""
    from playwright.sync_api import Error as PlaywrightError

    for b in pg.locator("[data-testid='toast-close']").all():
        try:
            b.click(timeout=3000)
        except PlaywrightError:
            pass
    deadline = time.time() + 15
    while toast_texts(pg) and time.time() < deadline:
        time.sleep(0.1)
    assert not toast_texts(pg), f"messages still open: {toast_texts(pg)}"


# ---------------------------------------------------------------------------- tests


def test_timeline_composer_edits_rows_and_strip(page):
    pg = page
    pg.click("#example-2")  # 4-segment story
    pg.locator("#seg-row-3").wait_for(state="visible")
    # the strip follows the rows through its own change event, a moment later
    pg.wait_for_function("document.querySelectorAll('#timeline-strip .mms-block').length === 4", timeout=10000)
    first, second = pg.input_value("#seg-text-0 textarea"), pg.input_value("#seg-text-1 textarea")
    pg.click("#seg-down-0")
    pg.wait_for_function("(t) => document.querySelector('#seg-text-0 textarea').value === t", arg=second, timeout=10000)
    assert pg.input_value("#seg-text-1 textarea") == first
    pg.click("#seg-remove-3")
    pg.locator("#seg-row-3").wait_for(state="hidden")
    pg.wait_for_function("document.querySelectorAll('#timeline-strip .mms-block').length === 3")
    pg.fill("#seg-sec-0 input", "6")
    pg.locator("#seg-sec-0 input").blur()
    pg.wait_for_function("document.querySelector('#timeline-strip').innerText.includes('6 s')")
    pg.click("#example-0")
    pg.locator("#seg-row-1").wait_for(state="hidden")
    assert pg.input_value("#seg-text-0 textarea") == "a person walks forward"


@pytest.mark.parametrize("method", METHODS)
def test_generate_two_segments_plays_in_viewer(page, method):
    pg = page
    set_timeline(pg, TWO_SEGMENTS)
    pick_method(pg, method)
    generate_and_wait(pg)
    frame = viewer_frame(pg)
    state = frame.evaluate("({frames: viewer.frames, fps: viewer.fps, segments: viewer.segments, error: viewer.error})")
    assert state["error"] is None
    assert state["frames"] == 200 and state["fps"] == 20
    assert [s["text"] for s in state["segments"]] == [t for t, _ in TWO_SEGMENTS]
    assert frame.locator("#bands .band").count() == 2
    # the viewer draws the figure and the animation advances. The body's tinted limbs are
    # less saturated than the bones' capsules were (0.07% of the canvas in a clean-clone run
    # of a walk and a wave, against the capsules' 0.1% bound); the bones' toggle is below
    t1 = frame.evaluate("viewer.time")
    with drawn(frame, 2):
        stats1 = frame.evaluate(CANVAS_STATS)
        frame.wait_for_function(f"viewer.time > {t1} + 0.3", timeout=15000)
    stats2 = frame.evaluate(CANVAS_STATS)
    assert stats1["coloured"] > 0.0002 and stats2["coloured"] > 0.0002, (stats1, stats2)
    assert frame.evaluate("viewer.showing") == "body"
    with drawn(frame):
        frame.uncheck("#body")  # the bones: strongly coloured capsules, as before
    assert frame.evaluate("viewer.showing") == "bones" and frame.evaluate(CANVAS_STATS)["coloured"] > 0.001
    frame.check("#body")
    assert stats1["signature"] != stats2["signature"], "the picture did not change while playing"
    assert frame.inner_text("#segment-text").startswith(("1/2", "2/2"))
    assert "Generated **10.0 s**".replace("**", "") in pg.inner_text("#timing")
    pg.wait_for_function("document.querySelector('#plot .js-plotly-plot') !== null", timeout=20000)
    if method == "kmm":
        # KMM's key frames reach the viewer and its density plot (d, S, gamma) is drawn
        keys = frame.evaluate("viewer.keyframes")
        assert keys and all(0 <= k < 200 for k in keys)
        pg.wait_for_function("document.querySelector('#plot').innerText.includes('gamma')", timeout=20000)
    pg.screenshot(path=str(artifact(f"docs/screenshot-{method}.png")), full_page=True)


def test_the_viewer_holds_still_from_the_click_until_the_new_motion(page):
    """The click pauses the viewer before the request's answer arrives, and nothing is drawn
    while it waits: a software-GL frame took ~85 ms of the page's one thread, and the pause
    used to arrive 5 ms after the new motion (its listener ran second) while the follow
    camera's glide went on drawing. Each message the viewer gets is logged with the frames
    drawn so far; the new motion's own first frame comes after its load message."""
    pg = page
    set_timeline(pg, TWO_SEGMENTS)
    pick_method(pg, METHODS[0])
    generate_and_wait(pg)  # a motion playing, the follow camera on
    frame = viewer_frame(pg)
    frame.wait_for_timeout(500)
    frame.evaluate(
        "() => { window.__log = []; window.addEventListener('message', (e) => "
        "window.__log.push([e.data.type, viewer.renderedFrames])); }"
    )
    before = frame.evaluate("viewer.renderedFrames")
    generate_and_wait(pg)
    log = frame.evaluate("window.__log")
    kinds = [k for k, _ in log]
    assert "mms-busy" in kinds and "mms-load" in kinds, log
    assert kinds.index("mms-busy") < kinds.index("mms-load"), log  # paused before the answer
    busy_at = log[kinds.index("mms-busy")][1]
    load_at = log[kinds.index("mms-load")][1]
    assert busy_at >= before and load_at == busy_at, log  # no frame drawn while waiting
    assert frame.evaluate("viewer.playing") and frame.evaluate("viewer.renderedFrames") > 0


def test_an_idle_message_during_a_load_does_not_replay_the_old_motion(page):
    """The page's "idle" (after the plot's round trip) can come while the new motion is
    still being fetched and parsed: the old motion must stay paused until the new one
    plays. Messages are posted as the page posts them: busy, the new file, idle at once."""
    pg = page
    set_timeline(pg, TWO_SEGMENTS)
    pick_method(pg, METHODS[0])
    _, url = generate_and_wait(pg)
    frame = viewer_frame(pg)
    assert frame.evaluate("viewer.playing")
    # logged after the viewer's own handler has run (this listener is added later)
    frame.evaluate(
        "() => { window.__log = []; window.addEventListener('message', (e) => "
        "window.__log.push([e.data.type, viewer.playing, viewer.url])); }"
    )
    fresh = url + ("&" if "?" in url else "?") + "again=1"  # the same file under a new URL
    pg.evaluate(
        """(glb) => { const w = document.querySelector('iframe.mms-viewer').contentWindow;
        for (const m of [{type: 'mms-busy'}, {type: 'mms-load', glb}, {type: 'mms-idle'}])
          w.postMessage(m, location.origin); }""",
        fresh,
    )
    frame.wait_for_function("(u) => viewer.url === u && viewer.ready && viewer.playing", arg=fresh, timeout=20_000)
    log = frame.evaluate("window.__log")
    assert [k for k, *_ in log] == ["mms-busy", "mms-load", "mms-idle"], log
    idle = log[2]
    assert idle[2] == url and idle[1] is False, log  # the old motion, still paused


@pytest.mark.long
def test_click_to_playing_time_for_a_10s_two_segment_motion(page):
    """Measured after one warm-up run per method (models loaded, caches filled)."""
    pg = page
    set_timeline(pg, TWO_SEGMENTS)
    timing = {}
    for method in METHODS:
        pick_method(pg, method)
        generate_and_wait(pg)  # warm-up
        runs, server_s = [], []
        for _ in range(3):
            runs.append(generate_and_wait(pg)[0])
            # the server's own figure, from the summary line ("... in **1.23 s** (...")
            server_s.append(float(pg.inner_text("#timing").split(" in ")[1].split(" s")[0]))
        timing[method] = {
            "click_to_playing_ms": runs,
            "median_ms": float(np.median(runs)),
            "server_generate_and_export_s": server_s,
        }
        # a loose guard against regressions; the target (2 s) is reported, not asserted
        assert np.median(runs) < 30000
    report = {"motion": "10 s, 2 segments", "machine": os.uname().nodename, **timing}
    artifact("results/browser_timing.json").write_text(json.dumps(report, indent=1))
    print(json.dumps(timing))


def test_downloads_validate(page, tmp_path):
    pg = page
    set_timeline(pg, TWO_SEGMENTS)
    pick_method(pg, METHODS[-1])
    generate_and_wait(pg)
    got = {}
    stem = f"a-person-walks-forward_{METHODS[-1].replace('_', '-')}_seed0"
    for key in ("glb", "bvh", "features", "joints"):
        with pg.expect_download() as dl:
            pg.click(f"#dl-{key}")
        # named after the first prompt, the method and the seed
        assert dl.value.suggested_filename.startswith(stem), dl.value.suggested_filename
        path = tmp_path / dl.value.suggested_filename
        dl.value.save_as(path)
        got[key] = path
    (report,) = validate_gltf(got["glb"])
    assert report["errors"] == 0, report["messages"]
    joints = np.load(got["joints"])
    assert joints.shape == (200, 22, 3)
    assert np.load(got["features"]).shape == (199, 263)
    from test_bvh import _bvhio_positions

    from motion_core.body.skeleton import HUMANML3D
    from motion_core.formats.bvh import bvh_positions_m, read_bvh

    bvh = read_bvh(got["bvh"])
    theirs = _bvhio_positions(got["bvh"], bvh.n_frames, bvh.names) * 0.01
    idx = [bvh.names.index(n) for n in HUMANML3D.joint_names]
    assert np.abs(theirs[:, idx] - joints).max() < 1e-3  # a PyPI parser gets our joints within 1 mm
    assert np.abs(bvh_positions_m(bvh)[:, idx] - joints).max() < 1e-3


# (timeline, the message's title, a piece of its text)
BAD_INPUTS = [
    ([("", 3)], "Segment 1: text", "the text is empty"),
    ([("a person walks forward", 3), ("   ", 3)], "Segment 2: text", "the text is empty"),
    ([("a" * 301, 3)], "Segment 1: text", "301 characters (at most 300)"),
    ([("a person walks", 0.5)], "Segment 1: seconds", "duration 0.5 s is outside 1-10 s"),
    ([("a person walks", 3), ("a person runs", 12)], "Segment 2: seconds", "duration 12 s is outside 1-10 s"),
    ([("a person walks", 9)] * 7, "Timeline too long", "lasts 63 s (at most 60 s in all)"),
]

# Gradio's status tracker puts a red "Error" badge over each output of an event that raised
ERROR_BADGES = """() => Array.from(document.querySelectorAll('.error, [class*=error]')).filter((el) =>
  el.offsetParent !== null && el.textContent.trim() === 'Error' && !el.closest('[data-testid=toast-body]')).length"""


def assert_form_intact(pg, segments, url: str, timing: str) -> None:
    """No error badge, every row's text in its box, the viewer on the last good motion and
    playing it, not "Generating…"."""
    assert pg.evaluate(ERROR_BADGES) == 0
    for i, (text, _) in enumerate(segments):
        assert pg.locator(f"#seg-text-{i} textarea").is_visible()
        assert pg.input_value(f"#seg-text-{i} textarea") == text
    frame = viewer_frame(pg)
    frame.wait_for_function("document.getElementById('message').textContent !== 'Generating…'", timeout=10000)
    frame.wait_for_function("viewer.playing", timeout=10000)
    assert frame.evaluate("viewer.url") == url
    assert timing in pg.inner_text("#timing")


def test_bad_inputs_get_one_titled_message_and_leave_the_form_intact(page, server):
    pg = page
    frame = viewer_frame(pg)
    # an empty viewer invites to compose, it does not claim to be generating
    assert frame.inner_text("#message") == "Compose a timeline and press Generate."
    set_timeline(pg, [("a person walks forward", 2)])
    pick_method(pg, METHODS[-1])
    _, url = generate_and_wait(pg)
    timing = pg.inner_text("#timing")
    log_before = server["log"].read_text()
    for segments, title, message in BAD_INPUTS:
        set_timeline(pg, segments)
        pg.click("#generate")
        text = wait_toast(pg, message)
        assert "Traceback" not in text
        assert text.startswith(f"{title}: "), text
        assert_form_intact(pg, segments, url, timing)
        close_toasts(pg)
    # the user's mistakes are logged one line each, without a traceback
    log = server["log"].read_text()[len(log_before) :]
    assert "Traceback" not in log
    assert sum("rejected" in line for line in log.splitlines()) >= len(BAD_INPUTS)
    # live limits: a character counter, the seconds box's bounds, + Add segment off at 10 rows.
    # The rows come from the JSON import, one event each (clicking ✕ six times and + nine,
    # each a round trip to a page whose viewer plays on software GL, took half the test)
    pg.get_by_text("Import / export the timeline (JSON)").click()
    import_timeline(pg, [("a person walks", 2)])
    pg.fill("#seg-text-0 textarea", "a" * 305)
    pg.wait_for_function("document.querySelector('#seg-text-0 .mms-count').textContent.includes('5 too many')")
    sec = pg.locator("#seg-sec-0 input")
    assert (sec.get_attribute("min"), sec.get_attribute("max")) == ("1", "10")
    assert pg.is_disabled("#seg-remove-0")  # the only row cannot be removed
    import_timeline(pg, [("a person walks", 2)] * 10)
    pg.wait_for_function("document.querySelector('#seg-add').disabled")
    assert not pg.is_disabled("#seg-remove-0")
    assert pg.evaluate(ERROR_BADGES) == 0
    pg.fill("#timeline-json textarea", json.dumps({"text": ["a person walks"] * 11, "seconds": [2] * 11}))
    pg.click("#timeline-import")
    wait_toast(pg, "too many segments: 11")
    close_toasts(pg)
    pg.fill("#timeline-json textarea", "{not json")
    pg.click("#timeline-import")
    wait_toast(pg, "does not parse")
    assert_form_intact(pg, [("a person walks", 2)] * 10, url, timing)
    assert "Traceback" not in pg.content()
    close_toasts(pg)
    # a sentence of several actions in a full timeline: its reading, and why it is not split
    type_row(pg, 0, SPLIT_SENTENCE)
    pg.locator("#seg-split-0").wait_for(state="visible", timeout=30_000)
    # (the half-typed sentence's reading says two actions, 11 rows)
    full = "would make 12 rows, more than the 10 a timeline holds"
    assert full in reading_of(pg, 0, settles_to=full)
    assert pg.locator("#seg-split-btn-0").is_hidden()
    # a sentence over 300 characters beside a row of 12 s: Generate names the text, as any
    # overlong text; split, its rows fit, and Generate names the 12 s row (now row 7)
    import_timeline(pg, [("a person walks", 2), ("a person jumps up", 2)])
    pg.fill("#seg-sec-1 input", "12")
    pg.locator("#seg-sec-1 input").blur()
    type_row(pg, 0, LONG_SENTENCE, typed=12)
    assert offered(pg, 0, settles_to="Split into 6 segments") == "Split into 6 segments"
    pg.click("#generate")
    text = wait_toast(pg, f"{len(LONG_SENTENCE)} characters (at most 300)")
    assert text.startswith("Segment 1: text: "), text
    assert_form_intact(pg, [(LONG_SENTENCE, 0), ("a person jumps up", 0)], url, timing)
    close_toasts(pg)
    pg.click("#seg-split-btn-0")
    pg.locator("#seg-row-6").wait_for(state="visible")
    rows = visible_rows(pg)
    assert rows[-1] == ("a person jumps up", 12.0) and all(len(t) <= 300 for t, _ in rows), rows
    pg.click("#generate")
    text = wait_toast(pg, "duration 12 s is outside 1-10 s")
    assert text.startswith("Segment 7: seconds: "), text
    assert_form_intact(pg, rows, url, timing)
    close_toasts(pg)
    # an emptied row: its offer goes with its text
    type_row(pg, 0, SPLIT_SENTENCE)
    offered(pg, 0)
    area = pg.locator("#seg-text-0 textarea")
    area.press("Control+a")
    area.press("Backspace")
    pg.locator("#seg-split-0").wait_for(state="hidden", timeout=10_000)
    assert pg.evaluate(ERROR_BADGES) == 0


def test_api_reports_unknown_method_and_generates(server):
    from gradio_client import Client

    client = Client(server["url"], verbose=False)
    timeline = json.dumps({"text": ["a person walks forward"], "seconds": [2]})
    with pytest.raises(Exception, match="unknown method 'teleport'"):
        client.predict(timeline, "teleport", 0, api_name="/generate_motion")
    with pytest.raises(Exception, match="rig must be one of"):
        client.predict(timeline, METHODS[-1], 0, True, "mixamo", api_name="/generate_motion")
    res = client.predict(timeline, METHODS[-1], 3, api_name="/generate_motion")
    assert res["frames"] == 40 and res["method"] == METHODS[-1]
    with urllib.request.urlopen(server["url"].rstrip("/") + res["files"]["glb"]) as r:
        assert r.read(4) == b"glTF"
    # a null duration is the length estimator's, and the API takes foot lock and the rig
    blank = json.dumps({"text": ["a person walks forward", "a person jumps up"], "seconds": [None, 2]})
    res2 = client.predict(blank, METHODS[-1], 3, False, "humanoid", api_name="/generate_motion")
    first = res2["segments"][0]
    assert 20 <= first["end"] - first["start"] <= 200 and res2["segments"][1]["end"] - first["end"] == 40
    with urllib.request.urlopen(server["url"].rstrip("/") + res2["files"]["bvh"]) as r:
        bvh = r.read().decode()
    assert "ROOT Hips" in bvh and "LeftUpLeg" in bvh
    with urllib.request.urlopen(server["url"].rstrip("/") + res["files"]["bvh"]) as r:
        assert "ROOT pelvis" in r.read().decode()  # HumanML3D's names by default


def test_sessions_do_not_see_each_other(browser, server):
    pages = []
    for _ in range(2):
        ctx = browser.new_context(viewport={"width": 1200, "height": 900})
        pg = ctx.new_page()
        pg.goto(server["url"])
        pg.wait_for_selector("#generate")
        pages.append((ctx, pg))
    (_, a), (_, b) = pages
    set_timeline(a, [("a person walks forward", 2)])
    set_timeline(b, [("a person jumps up twice", 3)])
    pick_method(a, METHODS[-1])
    pick_method(b, METHODS[-1])
    _, url_a = generate_and_wait(a)
    _, url_b = generate_and_wait(b)
    assert url_a != url_b and Path(url_a).parent != Path(url_b).parent
    assert viewer_frame(a).evaluate("viewer.frames") == 40
    assert viewer_frame(b).evaluate("viewer.frames") == 60
    assert "2.0 s" in a.inner_text("#timing") and "3.0 s" in b.inner_text("#timing")
    for ctx, _ in pages:
        ctx.close()


def test_a_blank_seconds_box_gets_the_estimated_duration(page):
    """Seconds left blank are the length estimator's, shown in the box after
    generating, and the motion lasts that long."""
    set_timeline(page, [("a person claps twice", 2), ("a person walks forward", "")])
    pick_method(page, "kmm")
    generate_and_wait(page)
    page.wait_for_function("document.querySelector('#seg-sec-1 input').value !== ''", timeout=30_000)
    estimate = float(page.input_value("#seg-sec-1 input"))
    assert 1.0 <= estimate <= 10.0
    # the row says the box holds an estimate, not a number the user typed
    page.wait_for_function(
        "(t) => document.querySelector('#seg-sec-1').innerText.includes(t)", arg=f"estimated {estimate:.1f} s"
    )
    assert "estimated" not in page.inner_text("#seg-sec-0")
    assert viewer_frame(page).evaluate("viewer.frames") == 40 + round(estimate * 20)
    assert page.evaluate(ERROR_BADGES) == 0
    # the estimate (4.8 s, say: not a multiple of 0.5) is a valid value, not a red box
    assert page.evaluate("document.querySelector('#seg-sec-1 input').checkValidity()")


def test_viewer_without_three_is_explained(tmp_path, monkeypatch):
    """No node_modules and no remote three.js (MMS_THREE_URL empty): how to get three instead
    of a blank box."""
    import app.viewer as viewer

    monkeypatch.setattr(viewer, "THREE", tmp_path / "missing")
    monkeypatch.setenv("MMS_THREE_URL", "")
    assert "npm package <code>three</code>" in viewer.viewer_template()


def test_viewer_marks_key_frames_and_shows_ghost_poses(browser, server):
    """KMM's key frames (from the GLB's extras) as scrubber ticks and ghost poses on request."""
    from motion_helpers import random_fk_motion

    from app.viewer import file_url, viewer_page_url
    from motion_core import Motion
    from motion_core.formats.export import export_glb

    joints = random_fk_motion(60, seed=4).astype(np.float32)
    motion = Motion(joints, 20, [(0, 30, "a"), (30, 60, "b")], "kmm", 0, keyframes=[5, 22, 41])
    d = server["out"] / "keyframes"
    d.mkdir(exist_ok=True)
    glb = export_glb(motion, d / "motion.glb")
    ctx = browser.new_context(viewport={"width": 900, "height": 600})
    pg = ctx.new_page()
    pg.goto(server["url"].rstrip("/") + viewer_page_url(glb) + "&autoplay=0")
    pg.wait_for_function("window.viewer && window.viewer.ready && window.viewer.loadedAt !== null")
    assert pg.evaluate("viewer.url") == file_url(glb)
    assert pg.evaluate("viewer.keyframes") == [5, 22, 41]
    assert pg.locator("#ticks .tick").count() == 3
    assert not pg.is_disabled("#ghosts")
    before = pg.evaluate(CANVAS_STATS)["magenta"]
    with drawn(pg):
        pg.check("#ghosts")
    after = pg.evaluate(CANVAS_STATS)["magenta"]
    assert before < 1e-4 < after, (before, after)  # three translucent key-frame figures appeared
    pg.screenshot(path=str(artifact("docs/viewer-keyframe-ghosts.png")))
    # scrubbing moves the figure and names the segment under the cursor
    pg.locator("#scrub").fill("45")
    pg.wait_for_function("viewer.frame === 45")
    assert pg.inner_text("#segment-text") == "2/2 · b"
    ctx.close()


def test_the_viewer_records_a_video_of_one_play_through(browser, server, tmp_path):
    """The record button saves what the viewer shows as a WebM: one video frame per motion
    frame, the figure moving, named after the motion's file."""
    import av
    from motion_helpers import random_fk_motion

    from app.viewer import viewer_page_url
    from motion_core import Motion
    from motion_core.formats.export import export_glb

    joints = random_fk_motion(40, seed=5).astype(np.float32)  # 2 s at 20 fps
    d = server["out"] / "video"
    d.mkdir(exist_ok=True)
    glb = export_glb(Motion(joints, 20, [(0, 40, "a")], "kmm", 0), d / "a_person_waves.glb")
    ctx = browser.new_context(viewport={"width": 640, "height": 480}, accept_downloads=True)
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(server["url"].rstrip("/") + viewer_page_url(glb) + "&autoplay=0&view=front")
    pg.wait_for_function("window.viewer && window.viewer.ready && window.viewer.loadedAt !== null")
    with pg.expect_download(timeout=60_000) as dl:
        pg.click("#record")
    assert dl.value.suggested_filename == "a_person_waves.webm"
    path = tmp_path / "video.webm"
    dl.value.save_as(path)
    with av.open(str(path)) as container:
        frames = [f.to_ndarray(format="rgb24").astype(np.int16) for f in container.decode(video=0)]
    assert len(frames) == 40, len(frames)
    assert frames[0].shape[:2] == (pg.evaluate("viewer.canvasHeight"), pg.evaluate("viewer.canvasWidth"))
    # the figure moves: consecutive frames differ, and the first and last poses differ more
    steps = [float(np.abs(a - b).mean()) for a, b in itertools.pairwise(frames)]
    assert np.median(steps) > 0.02 and float(np.abs(frames[0] - frames[-1]).mean()) > np.median(steps), steps
    assert not pg.evaluate("viewer.recording") and not errors, errors
    ctx.close()


def test_no_file_outside_the_served_folders(server):
    """Path traversal out of the output folder, and files of the repository, are refused."""
    import urllib.error

    from app.viewer import file_url

    base = server["url"].rstrip("/")
    secret = REPO / "README.md"
    for url in (
        file_url(secret),
        "/gradio_api/file=" + str(server["out"]) + "/../../../../etc/passwd",
        "/gradio_api/file=" + str(server["out"]) + "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
        "/gradio_api/file=/etc/passwd",
    ):
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(base + url, timeout=10).read()
        assert e.value.code in (403, 404), url


def set_seed(pg, seed: int) -> None:
    """Type a seed into the Advanced panel as a user would, and press Enter.

    Clean-clone CI lost a typed seed now and then (the page generated with seed 0; about one
    run in three late on 2026-11-26, not reproduced by hand). The box is typed into once it
    is shown and has settled, and Enter commits it as a user's would; the cause on the page
    is not found (docs/training-log.md, 2026-11-26)."""
    box = pg.locator("#seed input")
    box.wait_for(state="visible")
    pg.wait_for_timeout(300)  # the Advanced panel's content settles after it opens
    box.fill(str(seed))
    box.press("Enter")
    box.blur()
    pg.wait_for_function("(s) => document.querySelector('#seed input').value === s", arg=str(seed))


def checked_method(pg) -> str:
    """The picked method's label text in the Method radio."""
    return pg.locator("#method label:has(input:checked)").inner_text().strip()


def test_the_preselected_method_is_the_best_measured_and_says_its_figures(page, browser, server, tmp_path):
    from gradio_client import Client

    from app.method_figures import best_method, default_rows, load_figures, percent

    pg = page
    figures = load_figures(METHODS, rows=default_rows(motion_core.methods()))  # as the page reads them
    best = best_method(METHODS, figures)  # FTMoMamba since 2026-11-27, the baseline from 2026-11-26, KMM before
    display = next(m["display_name"] for m in motion_core.methods() if m["name"] == best)
    from app.ui import n_kinds

    about = f"of prompts about the {n_kinds()} actions it knows"  # what the test prompts are about
    follows = f"follows {percent(figures[best].pass_rate)} {about}"
    assert checked_method(pg).startswith(f"{display} · {follows}")
    labels = pg.locator("#method label").all_inner_texts()
    assert len(labels) == len(METHODS) and all("follows " in t and " for 10 s" in t for t in labels)
    assert "passed the automatic verifier" in pg.inner_text("#method-info")
    pick_method(pg, "motion_mamba")
    from app.ui import text_following_warning

    # the warning that fits Motion Mamba's measured figure, or none where it follows the text;
    # a low figure's warning is checked below (KMM's, in a results folder that says 20%)
    mm = percent(figures["motion_mamba"].pass_rate)
    pg.wait_for_function(
        "document.querySelector('#method-info').innerText.includes('Motion Mamba') && "
        f"document.querySelector('#method-info').innerText.includes({mm!r})"
    )
    info = pg.inner_text("#method-info")
    warning = text_following_warning(figures["motion_mamba"].pass_rate)
    if warning is None:
        assert "only partly" not in info and "mostly ignores" not in info
    else:
        assert warning.split("**")[1] in info
    # the API lists the methods with their figures, and generate_motion's method is an enum
    client = Client(server["url"], verbose=False)
    rows = client.predict(api_name="/methods")
    assert [r["name"] for r in rows if r["default"]] == [best]
    assert abs(next(r for r in rows if r["name"] == "kmm")["text_following"] - figures["kmm"].pass_rate) < 1e-9
    api = client.view_api(return_format="dict", print_info=False)["named_endpoints"]["/generate_motion"]
    method_param = next(p for p in api["parameters"] if p["parameter_name"] == "method")
    assert sorted(method_param["type"]["enum"]) == sorted(METHODS)
    assert {"frames", "files", "segments"} <= set(api["returns"][0]["type"]["properties"])
    # new figures (a temporary results folder): the page preselects the new best method
    import shutil

    res = tmp_path / "results"
    res.mkdir()
    for f in (REPO / "results").glob("*.json"):
        shutil.copy(f, res / f.name)
    for name in ("verifier.json", "verifier_real.json"):
        doc = json.loads((res / name).read_text())
        doc["baseline"]["pass_rate"], doc["kmm"]["pass_rate"] = 0.97, 0.2
        (res / name).write_text(json.dumps(doc))
    out = tmp_path / "out"
    out.mkdir()
    with run_app(out, env={"MMS_RESULTS_DIR": str(res)}) as other:
        ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
        p2 = ctx.new_page()
        p2.goto(other["url"])
        p2.wait_for_selector("#generate")
        assert checked_method(p2).startswith(f"Transformer baseline (MLD-style) · follows 97% {about}")
        assert f"KMM · follows 20% {about}" in p2.inner_text("#method")
        pick_method(p2, "kmm")
        p2.wait_for_function(
            "document.querySelector('#method-info').innerText.includes('follows the text only partly')"
        )
        assert "passed 20% of the test prompts" in p2.inner_text("#method-info")
        ctx.close()


def test_prompt_guidance_warns_about_unfamiliar_prompts_before_and_after(page):
    pg = page
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person walks forward", 2)])
    # what the models know: the corpus's kinds, one clickable example each
    pg.get_by_text("What the models know").click()
    table = pg.locator("#known-actions")
    table.get_by_text("jumping jacks", exact=True).wait_for()
    from motion_core.corpus.prompt_guide import action_kinds

    assert len(action_kinds()) >= 29 and table.get_by_text(action_kinds()[0].example).count() == 1
    table.get_by_text("a person does jumping jacks three times").click()
    pg.locator("#seg-row-1").wait_for(state="visible")  # no empty row: a new one holds the example
    assert pg.input_value("#seg-text-1 textarea") == "a person does jumping jacks three times"
    set_timeline(pg, [("a person walks forward", 2)])
    # gibberish: the warning shows as the user types, and again with the generated motion
    pg.locator("#seg-text-0 textarea").fill("")
    pg.locator("#seg-text-0 textarea").type("asdf qwer zxcv", delay=20)
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('have not learned anything like')")
    assert "nearest known phrasings" in pg.inner_text("#prompt-guide")
    generate_and_wait(pg)
    assert "Segment 1: The models have not learned anything like" in pg.inner_text("#timing")
    # a known phrasing: its nearest neighbours, no warning before or after
    pg.locator("#seg-text-0 textarea").fill("")
    pg.locator("#seg-text-0 textarea").type("a person waves with the right hand", delay=10)
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('waves the right hand')")
    assert "not learned" not in pg.inner_text("#prompt-guide")
    generate_and_wait(pg)
    assert "not trained" not in pg.inner_text("#timing")


def test_viewer_views_path_trace_thin_ghosts_and_phone_width(browser, server):
    """Camera presets, the root's path on the floor, fullscreen, a scrubber as wide as the
    viewer, at most 8 ghosts ~1 s apart, and controls that fit a 390 px phone."""
    from motion_helpers import random_fk_motion

    from app.viewer import viewer_page_url
    from motion_core import Motion
    from motion_core.formats.export import export_glb

    joints = random_fk_motion(230, seed=5).astype(np.float32)
    keys = list(range(4, 230, 9))  # 25 key frames, as KMM picks for an 11.5 s story
    motion = Motion(joints, 20, [(0, 115, "a"), (115, 230, "b")], "kmm", 0, keyframes=keys)
    d = server["out"] / "views"
    d.mkdir(exist_ok=True)
    glb = export_glb(motion, d / "views.glb")
    ctx = browser.new_context(viewport={"width": 390, "height": 700})
    pg = ctx.new_page()
    pg.goto(server["url"].rstrip("/") + viewer_page_url(glb) + "&autoplay=0")
    pg.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null")
    ghosts = pg.evaluate("viewer.ghostFrames")
    assert 2 <= len(ghosts) <= 8 and all(b - a >= 20 for a, b in itertools.pairwise(ghosts))
    assert len(pg.evaluate("viewer.path")) == 230
    # everything fits the phone's width and the scrubber spans it
    assert pg.evaluate("document.documentElement.scrollWidth") <= 390
    for sel in ("#play", "#speed", "#view", "#loop", "#trace", "#ghosts", "#fullscreen", "#clock"):
        box = pg.locator(sel).bounding_box()
        assert box and box["x"] >= 0 and box["x"] + box["width"] <= 390, (sel, box)
    assert pg.locator("#scrub").bounding_box()["width"] > 340
    stage = pg.locator("#stage").bounding_box()
    assert stage["y"] + stage["height"] <= pg.locator("#controls").bounding_box()["y"] + 1  # not under the bar
    pictures = {}
    for view in ("follow", "front", "side", "top"):
        with drawn(pg):
            pg.select_option("#view", view)
        pictures[view] = pg.evaluate(CANVAS_STATS)["picture"]  # every pixel: a pale far body too
    assert len(set(pictures.values())) == 4, pictures
    assert pg.evaluate("viewer.view") == "top"
    pg.screenshot(path=str(artifact("docs/viewer-phone-top-view.png")))
    pg.click("#fullscreen")
    pg.wait_for_function("document.fullscreenElement !== null")
    ctx.close()


def test_demo_page_works_at_phone_width(browser, server):
    ctx = browser.new_context(viewport={"width": 390, "height": 844}, is_mobile=True, has_touch=True)
    pg = ctx.new_page()
    pg.goto(server["url"])
    pg.wait_for_selector("#generate")
    pick_method(pg, "kmm")
    generate_and_wait(pg)
    assert pg.evaluate("document.documentElement.scrollWidth") <= 390
    frame = viewer_frame(pg)
    box = pg.locator("iframe.mms-viewer").bounding_box()
    assert box["width"] <= 390 and box["height"] >= 300
    assert frame.locator("#scrub").bounding_box()["width"] > 0.85 * box["width"]  # not a dot
    for sel in ("#play", "#view", "#fullscreen"):
        b = frame.locator(sel).bounding_box()
        assert b and box["x"] <= b["x"] and b["x"] + b["width"] <= box["x"] + box["width"] + 1, sel  # page coords
    ctx.close()


def grid_frames(pg, n: int, kind: str) -> list:
    """The n viewer frames of the compare / variations grid, once each has drawn its motion."""
    pg.wait_for_function(
        f"document.querySelectorAll('#multi-view .mms-grid-{kind} iframe.mms-tile-viewer').length === {n}",
        timeout=180_000,
    )
    frames = [h.content_frame() for h in pg.query_selector_all(f"#multi-view .mms-grid-{kind} iframe")]
    for f in frames:
        f.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null", timeout=60_000)
    return frames


def test_compare_shows_one_synchronised_viewer_per_method(page):
    pg = page
    set_timeline(pg, [("a person waves with the right hand", 2)])
    pg.click("#compare")
    frames = grid_frames(pg, len(METHODS), "compare")
    titles = pg.locator("#multi-view .mms-tile-title").all_inner_texts()
    assert titles == [m["display_name"] for m in motion_core.methods()]
    captions = pg.locator("#multi-view .mms-tile-caption").all_inner_texts()
    assert all("follows " in c and "generated in " in c for c in captions), captions
    assert {f.evaluate("viewer.method") for f in frames} == set(METHODS)
    assert all(f.evaluate("viewer.frames") == 40 for f in frames)
    # one control acts on all: pause the last viewer, every viewer stops
    frames[-1].click("#play")
    for f in frames:
        f.wait_for_function("!viewer.playing", timeout=10_000)
    pg.screenshot(path=str(artifact("docs/demo-compare.png")), full_page=True)


def test_a_variation_picked_from_the_grid_becomes_the_download(page, server, tmp_path):
    pg = page
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person jumps in place twice", 3)])
    pg.get_by_text("Advanced", exact=True).click()
    set_seed(pg, 10)
    pg.click("#variations")
    frames = grid_frames(pg, 4, "variations")
    urls = [f.evaluate("viewer.url") for f in frames]
    assert len(set(urls)) == 4
    pg.locator("#pick label", has_text="seed 12").click()
    main = viewer_frame(pg)
    main.wait_for_function("(u) => viewer.url === u && viewer.ready", arg=urls[2], timeout=60_000)
    pg.wait_for_function("document.querySelector('#seed input').value === '12'")
    assert "seed 12" in pg.inner_text("#timing")
    with pg.expect_download() as dl:
        pg.click("#dl-glb")
    assert dl.value.suggested_filename == "a-person-jumps-in-place-twice_kmm_seed12.glb"
    got = tmp_path / "picked.glb"
    dl.value.save_as(got)
    assert got.read_bytes() == _fetch(server["url"], urls[2])  # the very file the grid showed for seed 12
    # "New seed" generates at once with a fresh seed
    old = main.evaluate("viewer.url")
    pg.click("#new-seed")
    main.wait_for_function("(o) => viewer.url !== o && viewer.ready", arg=old, timeout=60_000)
    assert pg.input_value("#seed input") != "12"


def _fetch(base: str, url: str) -> bytes:
    with urllib.request.urlopen(base.rstrip("/") + url) as r:
        return r.read()


def test_a_shared_link_reproduces_the_same_motion_bit_for_bit(page, browser, server):
    pg = page
    story = [("a person walks forward", 3), ("a person waves with the left hand", 2.5)]
    set_timeline(pg, story)
    pick_method(pg, "baseline")
    pg.get_by_text("Advanced", exact=True).click()
    set_seed(pg, 7)
    _, glb = generate_and_wait(pg)
    pg.wait_for_function("location.search.includes('timeline=') && location.search.includes('seed=7')")
    link = pg.url
    assert pg.locator("#share-link").get_attribute("href").endswith(link.split("/", 3)[3].lstrip("/"))
    ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
    other = ctx.new_page()
    other.goto(link)  # opening the link refills the form and regenerates
    frame = viewer_frame(other)
    frame.wait_for_function("viewer.ready && viewer.url", timeout=120_000)
    glb2 = frame.evaluate("viewer.url")
    assert glb2 != glb  # a new generation, in its own folder ...
    for i, (text, sec) in enumerate(story):
        assert other.input_value(f"#seg-text-{i} textarea") == text
        assert float(other.input_value(f"#seg-sec-{i} input")) == sec
    assert checked_method(other).startswith("Transformer baseline")
    for suffix in ("_joints.npy", "_features.npy", ".bvh"):  # ... with the same motion, bit for bit
        a = _fetch(server["url"], glb.replace(".glb", suffix))
        b = _fetch(server["url"], glb2.replace(".glb", suffix))
        assert a == b, suffix
    ctx.close()
    # this tab keeps its generations: a second one lists the first under "Earlier in this tab"
    set_timeline(pg, [("a person jumps in place twice", 2)])
    generate_and_wait(pg)
    pg.wait_for_function("document.querySelector('#mms-history').innerText.includes('Earlier in this tab')")
    # a timeline is named by its first segment, and says how many more it has; then how it
    # was sampled (the baseline's defaults: its DDIM sampler, 5 steps at guidance 3)
    label = "a person walks forward (+1 more) · baseline · quality, 5 steps, guidance 3 · seed 7"
    assert label in pg.locator("#mms-history").text_content()  # (the list is folded)


@pytest.mark.parametrize("seconds", [8, 3])
def test_the_viewer_ends_on_the_motions_last_pose(browser, server, seconds):
    """Played to the end with loop off, the viewer stops on the last frame's pose, not the
    first's: at the clip's end time three.js's repeating action wrapped to time 0, so the
    clock read "7.95 / 7.95 s" under the last segment's caption over the body as it started."""
    from motion_helpers import random_fk_motion

    from app.viewer import viewer_page_url
    from motion_core import Motion
    from motion_core.formats.export import export_glb

    n = seconds * 20
    joints = random_fk_motion(n, seed=6).astype(np.float32)
    half = n // 2
    d = server["out"] / f"last-pose-{seconds}"
    d.mkdir(exist_ok=True)
    glb = export_glb(Motion(joints, 20, [(0, half, "a"), (half, n, "and sits down")], "kmm", 0), d / "m.glb")
    ctx = browser.new_context(viewport={"width": 900, "height": 600})
    pg = ctx.new_page()
    pg.goto(server["url"].rstrip("/") + viewer_page_url(glb) + "&autoplay=0")
    pg.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null")
    pg.uncheck("#loop")
    duration = pg.evaluate("viewer.duration")
    assert abs(duration - (n - 1) / 20) < 1e-4
    pg.evaluate(f"viewer.setTime({duration - 0.4})")
    pg.click("#play")
    pg.wait_for_function("!viewer.playing", timeout=20_000)
    assert pg.evaluate("viewer.time") == duration and pg.evaluate("viewer.frame") == n - 1
    assert pg.inner_text("#segment-text") == "2/2 · and sits down"
    got = np.array(pg.evaluate("viewer.jointPositions()"))
    assert np.abs(got - joints[-1]).max() < 1e-3, np.abs(got - joints[-1]).max()
    assert np.abs(got - joints[0]).max() > 0.1  # (the start is elsewhere: the root walked)
    # scrubbed to the last frame, too; and the first frame is still the first pose
    pg.locator("#scrub").fill(str(n - 1))
    assert np.abs(np.array(pg.evaluate("viewer.jointPositions()")) - joints[-1]).max() < 1e-3
    pg.evaluate("viewer.setTime(0)")
    assert np.abs(np.array(pg.evaluate("viewer.jointPositions()")) - joints[0]).max() < 1e-3
    ctx.close()


def in_view(pg, selector: str) -> bool:
    """Whether the element's top lies inside the window (a user sees it without scrolling)."""
    return pg.evaluate(
        """(s) => { const el = document.querySelector(s); if (!el) return false;
        const r = el.getBoundingClientRect(); return r.height > 0 && r.top >= 0 && r.top < window.innerHeight; }""",
        selector,
    )


def test_results_land_in_view_and_the_history_stays_short(browser, server):
    """At 1400x900 Generate is on the first screen; a click on Compare shows at once where its
    grid will come, and the grid is in the window when it comes; the tab's history keeps the
    last few generations, folded. (The grid used to render ~1,700 px down with nothing
    changing in view, under a history of every generation in the tab.)"""
    ctx = browser.new_context(viewport={"width": 1400, "height": 900})
    pg = ctx.new_page()
    pg.goto(server["url"])
    pg.wait_for_selector("#generate")
    viewer_frame(pg)
    box = pg.locator("#generate").bounding_box()
    assert box["y"] + box["height"] <= 900, box  # the default two rows: Generate on the first screen
    # a long history from earlier in the tab: one more generation keeps the last few, folded
    pg.evaluate(
        "sessionStorage.setItem('mms-history', JSON.stringify(Array.from({length: 12}, (_, i) => "
        "({query: `timeline=x&seed=${i}`, label: `earlier ${i}`}))))"
    )
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person waves with the right hand", 2)])
    generate_and_wait(pg)
    pg.wait_for_function("document.querySelector('#mms-history details') !== null", timeout=30_000)
    from app.page_js import HISTORY_EARLIER

    assert pg.evaluate("JSON.parse(sessionStorage.getItem('mms-history')).length") == HISTORY_EARLIER + 1
    assert pg.locator("#mms-history li").count() == HISTORY_EARLIER
    assert not pg.evaluate("document.querySelector('#mms-history details').open")  # folded
    pg.evaluate("window.scrollTo(0, 0)")
    pg.click("#compare")
    # something in view changes at once (within a few seconds on a loaded machine: the
    # placeholder comes, then lays out)
    pg.wait_for_function(
        """() => { const el = document.querySelector('#multi-view .mms-pending'); if (!el) return false;
        const r = el.getBoundingClientRect(); return r.height > 0 && r.top >= 0 && r.top < window.innerHeight; }""",
        timeout=5_000,
    )
    grid_frames(pg, len(METHODS), "compare")
    pg.wait_for_function("document.querySelector('#multi-view .mms-pending') === null", timeout=10_000)
    assert in_view(pg, "#multi-view .mms-grid"), pg.evaluate("window.scrollY")
    ctx.close()


def test_on_a_phone_the_viewer_comes_first_and_shows_the_new_motion(browser, server):
    """At 390x844 the viewer is above the controls (it used to come after all of them, 1.5
    screens down), a row's ↑ ↓ ✕ stay together, and after Generate (pressed far down the
    page) the viewer comes into view with the new motion."""
    ctx = browser.new_context(viewport={"width": 390, "height": 844}, is_mobile=True, has_touch=True)
    pg = ctx.new_page()
    pg.goto(server["url"])
    pg.wait_for_selector("#generate")
    frame = viewer_frame(pg)
    viewer = pg.locator("iframe.mms-viewer").bounding_box()
    assert viewer["y"] < pg.locator("#seg-row-0").bounding_box()["y"] < pg.locator("#generate").bounding_box()["y"]
    up, down, remove = (pg.locator(f"#seg-{k}-0").bounding_box() for k in ("up", "down", "remove"))
    assert up["y"] == down["y"] == remove["y"], (up, down, remove)
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person waves with the right hand", 2)])
    pg.locator("#generate").scroll_into_view_if_needed()
    assert not in_view(pg, "iframe.mms-viewer")
    old = frame.evaluate("viewer.url")
    pg.click("#generate")
    frame.wait_for_function("(o) => viewer.url !== o && viewer.ready", arg=old, timeout=120_000)
    pg.wait_for_function(
        "() => { const r = document.querySelector('iframe.mms-viewer').getBoundingClientRect();"
        " return r.top > -2 && r.top < window.innerHeight; }",
        timeout=20_000,
    )
    ctx.close()


def wait_true(pg, fn: str, timeout_s: float = 10) -> None:
    """Until ``fn`` (a function's source) is true in the page, asked from here every 0.2 s."""
    deadline = time.time() + timeout_s
    while not pg.evaluate(fn):
        assert time.time() < deadline, f"still false after {timeout_s} s: {fn}"
        time.sleep(0.2)


def test_the_guide_line_follows_the_rows_and_stale_results_say_so(page):
    """The nearest-phrasings line names the row its text is in now, and goes with the text;
    a variations grid of an earlier timeline is marked stale; a picked variation's seed says
    that it stays. (The line read "Segment 7, ..." over a timeline of one row; a cleared box
    kept its phrasings; old grids looked current.)"""
    pg = page
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person walks forward", 2), ("", 2)])
    # the line as shown (a hidden one shows nothing)
    guide = "((g) => (g && g.offsetParent ? g.innerText : ''))(document.querySelector('#prompt-guide'))"
    pg.locator("#seg-text-1 textarea").type("a person jumps in place twice", delay=10)
    pg.wait_for_function(f"() => {guide}.includes('Segment 2, nearest known phrasings')")
    pg.click("#seg-up-1")  # the typed text moves to row 1: the line follows it
    pg.wait_for_function("document.querySelector('#seg-text-0 textarea').value.includes('jumps')")
    # the line's event queues behind the typed keys' (always-last): on a loaded machine it takes a while
    pg.wait_for_function(f"() => {guide}.includes('Segment 1, nearest known phrasings')", timeout=30_000)
    pg.click("#example-0")  # a one-row example: no row holds the typed text any more
    pg.locator("#seg-row-1").wait_for(state="hidden")
    wait_true(pg, f"() => !{guide}.includes('nearest known phrasings')")
    pg.locator("#seg-text-0 textarea").fill("")
    pg.locator("#seg-text-0 textarea").type("a person sits down", delay=10)
    pg.wait_for_function(f"() => {guide}.includes('Segment 1, nearest')")
    pg.locator("#seg-text-0 textarea").fill("")  # a cleared box: no phrasings left
    # (the clearing is an input event of its own, queued behind the typed keys' on a loaded machine)
    wait_true(pg, f"() => !{guide}.includes('nearest known phrasings')", timeout_s=30)
    # a grid of variations, then the timeline changes: the grid says it is of another one
    set_timeline(pg, [("a person claps twice", 2)])
    pg.click("#variations")
    grid_frames(pg, 4, "variations")
    assert pg.locator("#multi-view .mms-stale-note").is_hidden()
    pg.get_by_text("Advanced", exact=True).click()  # where the seed is shown
    pg.locator("#seed input").wait_for(state="visible")
    assert "every generation uses this seed" in pg.inner_text("#seed")
    pg.locator("#pick label", has_text="seed 2").click()
    pg.wait_for_function(
        "() => document.querySelector('#seed').innerText.includes('from the variation you picked')", timeout=30_000
    )
    assert pg.input_value("#seed input") == "2"
    pg.fill("#seg-text-0 textarea", "a person walks backwards")
    pg.locator("#multi-view .mms-stale-note").wait_for(state="visible", timeout=15_000)
    assert "earlier timeline" in pg.inner_text("#multi-view .mms-stale-note")
    pg.fill("#seg-text-0 textarea", "a person claps twice")  # back to the grid's own timeline
    pg.locator("#multi-view .mms-stale-note").wait_for(state="hidden", timeout=15_000)


def test_a_link_with_too_many_segments_says_it_was_cut(browser, server):
    """A shared link of 11 segments: the page holds 10, generates those and says so."""
    from urllib.parse import urlencode

    from motion_core.inference.base import MAX_SEGMENTS

    rows = [[f"a person walks forward {i}", 1] for i in range(MAX_SEGMENTS + 1)]
    query = urlencode({"timeline": json.dumps(rows), "method": "kmm", "seed": "0", "sampler": "quality"})
    ctx = browser.new_context(viewport={"width": 1400, "height": 900})
    pg = ctx.new_page()
    pg.goto(server["url"] + "?" + query)
    text = wait_toast(pg, f"{MAX_SEGMENTS + 1} segments", timeout_s=60)
    assert f"the first {MAX_SEGMENTS}" in text and "the last 1 left out" in text, text
    frame = viewer_frame(pg)
    frame.wait_for_function("viewer.ready && viewer.url", timeout=120_000)
    assert frame.evaluate("viewer.segments.length") == MAX_SEGMENTS
    ctx.close()


def test_an_unknown_action_is_named_in_the_warning(page):
    pg = page
    set_timeline(pg, [("a person walks forward", 2)])
    pg.locator("#seg-text-0 textarea").fill("")
    pg.locator("#seg-text-0 textarea").type("a person picks up a box", delay=10)
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('picks up a box')")
    assert "not learned 'picks up a box' (nearest: reach forward" in pg.inner_text("#prompt-guide")


# a sentence the prompt reader splits into three known actions (walk, sit down, wave)
SPLIT_SENTENCE = "a person walks forward, then sits down and waves"
# 335 characters, six actions: over a row's 300, each of its clauses well under
LONG_SENTENCE = (
    "a person walks forward very slowly and carefully along a long straight line across the whole room, "
    "then turns around to the left, then jumps up twice in place with both feet together, then claps the "
    "hands three times above the head, then waves with the right hand three times, then sits down slowly "
    "on a chair in the corner of the room"
)


def type_row(pg, i: int, text: str, delay: float = 5, typed: int | None = None) -> None:
    """Empty row ``i``'s text and type ``text`` as a user does (keys: the box's input event;
    Playwright's fill sends none). ``typed``: only the last so many characters are typed, the
    rest filled in (a long text typed key by key took over 30 s on a loaded 2-core machine)."""
    area = pg.locator(f"#seg-text-{i} textarea")
    area.click()
    area.press("Control+a")
    area.press("Backspace")
    if typed is not None:
        area.fill(text[:-typed])
        area.press("End")
        text = text[-typed:]
    area.type(text, delay=delay)


def reading_of(pg, i: int, settles_to: str, timeout_s: float = 30) -> str:
    """Row ``i``'s reading once it holds ``settles_to`` (or what it holds after ``timeout_s``,
    for the assertion to show): a half-typed sentence's reading can land after the last key,
    and the whole sentence's replaces it (the box's input events run always-last)."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeoutError

    sel = f"#seg-reading-{i} .mms-reading"
    try:
        pg.wait_for_function(
            "([sel, want]) => ((document.querySelector(sel) || {}).innerText || '').includes(want)",
            arg=[sel, settles_to],
            timeout=timeout_s * 1000,
        )
    except PlaywrightTimeoutError:
        pass
    return pg.inner_text(sel)


def offered(pg, i: int, timeout_s: float = 30, settles_to: str | None = None) -> str:
    """Wait for row ``i``'s split offer; its button's text. ``settles_to``: also wait (within
    the same timeout) for the button to read that, since the reading of a half-typed sentence
    ("walks forward, then sits down") can arrive after the last key and is replaced by the
    whole sentence's once its event runs (the box's input events run always-last)."""
    btn = f"#seg-split-btn-{i}"
    pg.locator(btn).wait_for(state="visible", timeout=timeout_s * 1000)
    if settles_to is not None:
        from playwright.sync_api import TimeoutError as PlaywrightTimeoutError

        try:
            pg.wait_for_function(
                "([sel, want]) => { const b = document.querySelector(sel); return b && b.innerText.trim() === want; }",
                arg=[btn, settles_to],
                timeout=timeout_s * 1000,
            )
        except PlaywrightTimeoutError:
            pass  # the assertion on the returned text says what it read instead
    return pg.inner_text(btn).strip()


def visible_rows(pg) -> list[tuple[str, float]]:
    n = pg.locator("[id^=seg-row-]:visible").count()
    return [(pg.input_value(f"#seg-text-{i} textarea"), float(pg.input_value(f"#seg-sec-{i} input"))) for i in range(n)]


def test_a_sentence_of_several_actions_splits_into_rows_to_edit_and_generate(page):
    """Typed into one row, a sentence the reader reads as three actions gets "Split into 3
    segments" and the reading in one line; the click puts the plan's rows in its place (the
    user's words, the estimator's seconds), which the user edits before generating."""
    pg = page
    plan = motion_core.read_prompt(SPLIT_SENTENCE).plan()
    assert [s.kinds for s in plan] == [("walk",), ("sit_down",), ("wave",)]
    pick_method(pg, "kmm")
    set_timeline(pg, [("a person claps twice", 2), ("", 3)])
    type_row(pg, 1, SPLIT_SENTENCE)
    assert offered(pg, 1, settles_to="Split into 3 segments") == "Split into 3 segments"
    read = "Read as: walk (forward) → sit down → wave."
    assert reading_of(pg, 1, settles_to=read).strip() == read
    assert pg.locator("#seg-split-0").is_hidden()  # a row of one action: nothing to offer
    pg.click("#seg-split-btn-1")
    pg.locator("#seg-row-3").wait_for(state="visible")
    assert visible_rows(pg) == [("a person claps twice", 2.0), *[(s.text, s.seconds) for s in plan]]
    pg.locator("#seg-split-1").wait_for(state="hidden", timeout=5_000)  # the offer went with the sentence
    assert "estimated" in pg.inner_text("#seg-sec-1") and "estimated" not in pg.inner_text("#seg-sec-0")
    pg.wait_for_function("document.querySelectorAll('#timeline-strip .mms-block').length === 4", timeout=10_000)
    # the rows are the user's to edit: the wave becomes a left-handed one of 3 s
    type_row(pg, 3, "a person waves with the left hand")
    pg.fill("#seg-sec-3 input", "3")
    pg.locator("#seg-sec-3 input").blur()
    generate_and_wait(pg)
    frame = viewer_frame(pg)
    want = ["a person claps twice", plan[0].text, plan[1].text, "a person waves with the left hand"]
    assert [s["text"] for s in frame.evaluate("viewer.segments")] == want
    assert frame.evaluate("viewer.frames") == sum(round(20 * s) for s in (2, plan[0].seconds, plan[1].seconds, 3))
    assert pg.evaluate(ERROR_BADGES) == 0
    assert "not learned" not in pg.inner_text("#timing")  # three known actions: no warning


def test_a_sentence_pasted_into_a_row_gets_the_split_offer(browser, server):
    """A paste (here the keyboard's; a mouse's context-menu paste sends the same input event)
    into an empty row brings the offer, as typing does, and deleting words with Backspace
    takes it away; the guide line follows the pasted text. Gradio's textbox sends its input
    event from a keypress, which neither a paste nor Backspace sends (the page passes such a
    change on: PAGE_JS)."""
    ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
    ctx.grant_permissions(["clipboard-read", "clipboard-write"], origin=server["url"].rstrip("/"))
    pg = ctx.new_page()
    pg.goto(server["url"])
    pg.wait_for_selector("#generate")
    set_timeline(pg, [("", 3)])
    pg.evaluate("(t) => navigator.clipboard.writeText(t)", SPLIT_SENTENCE)
    area = pg.locator("#seg-text-0 textarea")
    area.click()
    area.press("Control+v")
    assert area.input_value() == SPLIT_SENTENCE  # the paste itself reached the box
    assert offered(pg, 0, settles_to="Split into 3 segments") == "Split into 3 segments"
    # the guide line is about the pasted text too
    pg.wait_for_function(
        "() => document.querySelector('#prompt-guide').innerText.includes('Segment 1, nearest known phrasings')",
        timeout=30_000,
    )
    # Backspace sends no keypress either: deleting back to one action takes the offer away
    area.press("End")
    for _ in range(len(SPLIT_SENTENCE) - len("a person walks forward")):
        area.press("Backspace")
    assert area.input_value() == "a person walks forward"
    pg.locator("#seg-split-0").wait_for(state="hidden", timeout=30_000)
    ctx.close()


def test_a_known_one_action_prompt_gets_no_warning_and_no_split_offer(page):
    pg = page
    set_timeline(pg, [("", 3)])
    type_row(pg, 0, SPLIT_SENTENCE)
    offered(pg, 0)  # the row's offer is there while its text reads as several actions ...
    type_row(pg, 0, "a person waves with the right hand")
    pg.locator("#seg-split-0").wait_for(state="hidden", timeout=30_000)  # ... and goes with them
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('waves the right hand')")
    pg.wait_for_timeout(1000)  # a late answer would show either again
    assert pg.locator("#seg-split-0").is_hidden()
    guide = pg.inner_text("#prompt-guide")
    assert "not learned" not in guide and "⚠" not in guide, guide


def test_rows_from_a_link_an_import_or_an_example_are_never_split(browser, server):
    """A shared link's sentence of several actions generates as the link has it, one segment,
    with no offer; an imported one gets none either, and an example's rows take the place of
    a typed row's offer. Once the user edits the link's row, the row is theirs: offered."""
    from urllib.parse import urlencode

    query = urlencode({"timeline": json.dumps([[SPLIT_SENTENCE, 6]]), "method": "kmm", "seed": "0"})
    ctx = browser.new_context(viewport={"width": 1400, "height": 900})
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(server["url"] + "?" + query)
    frame = viewer_frame(pg)
    frame.wait_for_function("viewer.ready && viewer.url", timeout=120_000)
    assert [s["text"] for s in frame.evaluate("viewer.segments")] == [SPLIT_SENTENCE]
    assert visible_rows(pg) == [(SPLIT_SENTENCE, 6.0)] and pg.locator("#seg-split-0").is_hidden()
    pg.get_by_text("Import / export the timeline (JSON)").click()
    import_timeline(pg, [("a person bows", 3), (SPLIT_SENTENCE, 6)])
    pg.wait_for_timeout(1000)
    assert pg.locator("#seg-split-0").is_hidden() and pg.locator("#seg-split-1").is_hidden()
    # a typed row's offer goes when an example fills the rows
    type_row(pg, 0, SPLIT_SENTENCE)
    offered(pg, 0)
    pg.click("#example-2")  # the 4-segment story
    pg.locator("#seg-row-3").wait_for(state="visible")
    pg.locator("#seg-split-0").wait_for(state="hidden", timeout=10_000)
    assert pg.locator("[class*=mms-split]:visible").count() == 0
    # the link's sentence, edited by the user: theirs now, so it is offered (not split)
    import_timeline(pg, [(SPLIT_SENTENCE, 6)])
    area = pg.locator("#seg-text-0 textarea")
    area.click()
    area.press("Control+End")
    area.type(" twice", delay=20)
    assert offered(pg, 0, settles_to="Split into 3 segments") == "Split into 3 segments"
    # the half-typed sentence's reading ("... and waves tw") reads as three actions as well
    assert "wave (twice)" in reading_of(pg, 0, settles_to="wave (twice)")
    assert visible_rows(pg) == [(SPLIT_SENTENCE + " twice", 6.0)]
    ctx.close()
    assert not errors, errors
