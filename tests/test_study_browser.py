"""The study page in a real browser (Debian chromium + Playwright): two synchronised viewers
labelled A and B, a vote through the page, script-injection text shown as text, no method
name anywhere in the page, and a reload that goes on with the same participant."""

from __future__ import annotations

import json
import sqlite3
import time

import pytest
from conftest import artifact, run_app, study_setup
from test_study_api import leaks

ADMIN = "browser-admin-token-77"
INJECTION = '<img src=x onerror="window.__pwned=1"><script>window.__pwned=2</script> a person waves'
CONFIG = {
    "name": "browser-test",
    "title": "Which motion is better?",
    "methods": ["motion_mamba", "baseline"],
    "seeds": [0],
    "trials_per_participant": 2,
    "criteria": ["realism", "matches the text"],
    "allow_custom_prompts": True,
    "custom_prompt_seconds": 2,
    "prompts": [{"text": "a person walks forward", "seconds": 2}],
}


@pytest.fixture(scope="module")
def study_server(tmp_path_factory):
    setup = study_setup(tmp_path_factory.mktemp("study-page"), CONFIG, ADMIN)
    with run_app(setup["out"], setup["env"]) as srv:
        yield {**srv, "db": setup["db"]}


# Gradio's status tracker puts a red "Error" badge over each output of an event that raised
ERROR_BADGES = """() => Array.from(document.querySelectorAll('.error, [class*=error]')).filter((el) =>
  el.offsetParent !== null && el.textContent.trim() === 'Error' && !el.closest('[data-testid=toast-body]')).length"""


def study_frames(pg):
    """Both viewers' frames, A first. The iframes carry ``data-src`` and the page's script sets
    ``src`` after the trial is shown, so on a busy machine ``pg.frames`` may not hold them yet
    when the counter appears (the same race the main page's viewer test had): poll for both."""
    deadline = time.monotonic() + 60
    while len(frames := [f for f in pg.frames if "viewer.html" in f.url]) < 2:
        assert time.monotonic() < deadline, [f.url for f in pg.frames]
        pg.wait_for_timeout(100)
    assert len(frames) == 2
    frames.sort(key=lambda f: "lead=1" not in f.url)  # A (the clock leader) first
    for f in frames:
        f.wait_for_function("!!window.viewer")
    return frames


def test_study_page_plays_a_and_b_in_sync_and_stores_a_vote(browser, study_server):
    ctx = browser.new_context(viewport={"width": 1400, "height": 1000})
    pg = ctx.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    pg.goto(study_server["url"])
    pg.fill("#study-first-prompt textarea", INJECTION)
    pg.click("#study-start")
    pg.locator("#study-counter", has_text="Trial 1 of 2").wait_for(timeout=120_000)
    a, b = study_frames(pg)
    for f in (a, b):
        f.wait_for_function("viewer.ready && viewer.playing && viewer.loadedAt !== null", timeout=60_000)

    # the injected markup is shown as text, in the page and in both viewers, and never runs
    assert pg.input_value("#study-prompt textarea") == INJECTION
    for f in (a, b):
        assert INJECTION in f.evaluate("document.getElementById('segment-text').textContent")
    for ctx_ in (pg, a, b):
        assert ctx_.evaluate("window.__pwned === undefined")

    # synchronised: B follows A's clock; pausing either pauses both; scrubbing B moves A
    pg.wait_for_timeout(1500)
    ta, tb = a.evaluate("viewer.time"), b.evaluate("viewer.time")
    assert abs(ta - tb) < 0.12 or abs(abs(ta - tb) - a.evaluate("viewer.duration")) < 0.12, (ta, tb)
    a.click("#play")
    b.wait_for_function("!viewer.playing", timeout=5000)
    b.evaluate(
        "() => { const s = document.getElementById('scrub'); s.value = '10'; s.dispatchEvent(new Event('input')); }"
    )
    a.wait_for_function("Math.abs(viewer.time - 0.5) < 0.01", timeout=5000)
    b.click("#play")
    a.wait_for_function("viewer.playing", timeout=5000)
    # both labelled, no method name anywhere in the page or the viewers
    assert pg.locator(".mms-side-label").all_inner_texts() == ["A", "B"]
    for f in (pg, a, b):
        assert not leaks(f.content()), leaks(f.content())

    # watch both through once, then vote through the page
    for f in (a, b):
        f.wait_for_function("viewer.plays >= 1", timeout=30_000)
    first_trial_urls = (a.evaluate("viewer.url"), b.evaluate("viewer.url"))
    # submitting without an answer: one message, and the trial stays as it was (no badges)
    pg.click("#study-submit")
    pg.get_by_text("choose an overall answer first").first.wait_for(timeout=30_000)
    assert pg.evaluate(ERROR_BADGES) == 0
    assert "Trial 1 of 2" in pg.inner_text("#study-counter")
    pg.locator("#study-answer label", has_text="B is better").click()
    pg.locator("#study-criterion-0").get_by_test_id("A-radio-label").click()
    pg.click("#study-submit")
    pg.locator("#study-counter", has_text="Trial 2 of 2").wait_for(timeout=120_000)
    a, b = study_frames(pg)
    a.wait_for_function("(old) => viewer.url !== old && viewer.ready", arg=first_trial_urls[0], timeout=60_000)
    # the README's picture: the second trial has the config's own prompt, not the test string
    for f in (a, b):
        f.wait_for_function("viewer.playing && viewer.time > 0.8", timeout=30_000)
    pg.screenshot(path=str(artifact("docs/screenshot-study.png")), full_page=True)

    con = sqlite3.connect(study_server["db"])
    rows = con.execute(
        "SELECT v.answer, v.criteria, v.watched_a, v.watched_b, t.prompt, t.custom_prompt "
        "FROM votes v JOIN trials t ON t.id = v.trial_id"
    ).fetchall()
    con.close()
    assert rows == [("B", json.dumps({"realism": "A"}), 1, 1, INJECTION, 1)]

    # a reload goes on with the same participant and the open trial (fresh file URLs)
    pg.reload()
    # the returning participant is told that their open trial resumes
    pg.locator("#study-welcome", has_text="your open trial (trial 2) resumes").wait_for(timeout=30_000)
    pg.click("#study-start")
    pg.locator("#study-counter", has_text="Trial 2 of 2 (resumed where you left off)").wait_for(timeout=60_000)
    pg.locator("#study-answer label", has_text="About the same").click()
    pg.click("#study-submit")
    pg.locator("#study-done", has_text="2 answers are stored").wait_for(timeout=60_000)
    ctx.close()
    assert not errors, errors


def test_results_tab_needs_the_token_and_shows_the_tables(browser, study_server):
    from gradio_client import Client

    client = Client(study_server["url"], verbose=False)  # one participant through the API
    view = client.predict("", api_name="/study_start")
    while not view["done"]:
        view = client.predict(view["participant"], view["trial"], "A", "{}", "[]", "", api_name="/study_vote")
    ctx = browser.new_context(viewport={"width": 1400, "height": 1400})
    pg = ctx.new_page()
    pg.goto(study_server["url"])
    pg.get_by_role("tab", name="Results").click()
    # a wrong or an empty token: the message, and no red "Error" badge over the outputs
    # (a raised gr.Error left two, over the plots, after the message had gone)
    for wrong in ("not-the-token", ""):
        pg.fill("#results-token input", wrong)
        pg.click("#results-show")
        toast = pg.locator("[data-testid=toast-body]", has_text="wrong admin token")
        toast.first.wait_for(timeout=30_000)
        pg.wait_for_timeout(500)  # the status tracker draws its badges after the message
        assert pg.evaluate(ERROR_BADGES) == 0
        assert "Bradley-Terry" not in pg.inner_text("#results-summary")
        toast.first.locator("button").first.click()  # close it
        toast.first.wait_for(state="detached", timeout=10_000)
    pg.fill("#results-token input", ADMIN)
    pg.click("#results-show")
    pg.locator("#results-summary", has_text="Bradley-Terry").wait_for(timeout=60_000)
    summary = pg.inner_text("#results-summary")
    assert "baseline vs motion_mamba" in summary  # the admin view names the methods
    pg.locator(".js-plotly-plot").nth(1).wait_for(timeout=30_000)
    with pg.expect_download() as dl:
        pg.click("#results-csv")
    csv_text = dl.value.path().read_text()
    assert csv_text.startswith("vote_id,participant,trial") and len(csv_text.strip().splitlines()) >= 2
    pg.screenshot(path=str(artifact("docs/screenshot-study-results.png")), full_page=True)
    ctx.close()
