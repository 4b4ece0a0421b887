"""The pictures of the README and docs/demo.md, taken from the running demo in Debian's chromium.

    python app.py &                       # or any running demo
    python tools/demo_screenshots.py --url http://127.0.0.1:7860     # every picture, into docs/
    python tools/demo_screenshots.py --url http://127.0.0.1:7860 --only demo-compare demo-phone

Each picture is made the way a user would make it: the timeline through the page's own fields
and buttons (the selectors of tests/test_browser.py), the method picked in the Method radio,
Generate / Compare / 4 variations clicked, and the result waited for in the viewer. The
pictures, named after their files in docs/:

- demo-opened: the page as it opens at 1400x900, nothing generated: Generate on the first screen;
- demo-first-screen: a three-segment story generated with the preselected method, mid-wave;
- demo-motion-end: that story played to its end with loop off: the last pose, "3/3";
- demo-prompt-guidance: an unfamiliar prompt typed and generated, "What the models know" open;
- demo-form-error: the story generated, then segment 2 at 12 s and Generate: the message;
- demo-split: a sentence of three actions typed into one row: the reader's one-line reading
  under it and "Split into 3 segments";
- demo-split-rows: the same after the click: the plan's three rows in its place;
- demo-reader-warning: a prompt with a known and an unknown part, typed and generated: the
  warning names the unknown part and the nearest known action, under the timeline and again
  under the viewer;
- viewer-top-view-path: "a person walks in a circle clockwise", top camera, the root's path;
- demo-phone-opened: the page as it opens at 390x844: the viewer first;
- demo-phone: a wave generated at 390 px (Generate pressed far down): the viewer in view;
- demo-compare: Compare all methods at 1400x900, the window as the user sees it when the grid
  has come (brought into view), the four viewers paused at the same frame;
- demo-variations: 4 variations (seeds 0-3) of a kick, seed 2 picked;
- demo-link-history: two generations; the link to the second and the first under "Earlier"
  (opened).

One browser at a time, one page per picture; needs a demo that is not busy (the timeouts
allow a loaded 2-core machine).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from playwright.sync_api import Browser, Frame, Page, sync_playwright

STORY = [
    ("a person walks forward", 3),
    ("a person waves with the right hand", 3),
    ("a person jumps in place twice", 2.5),
]
# the prompt reader reads it as walk, sit down, wave (three known actions)
SPLIT_SENTENCE = "a person walks forward, then sits down and waves"
# a known part and one the models have not learned (nearest: step over an obstacle)
READER_WARNING = "a person waves with the right hand and then climbs the stairs"
DESKTOP = {"width": 1400, "height": 900}
PHONE = {"width": 390, "height": 844}
GENERATE_TIMEOUT_MS = 180_000


# ---------------------------------------------------------------- the page's own controls


def open_page(browser: Browser, url: str, viewport: dict[str, int] = DESKTOP, **context: object) -> Page:
    """A fresh tab (its own session) on the demo, once the form is there."""
    pg = browser.new_context(viewport=viewport, **context).new_page()
    pg.on("pageerror", lambda e: print(f"  page error: {e}"))
    pg.goto(url)
    pg.wait_for_selector("#generate")
    return pg


def set_timeline(pg: Page, segments: list[tuple[str, float]]) -> None:
    """Make the timeline exactly ``segments`` with the rows' own buttons and fields."""

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
    # Gradio sends a box's value on blur: leave the last box before acting on the form
    pg.locator(f"#seg-sec-{len(segments) - 1} input").blur()


def type_row(pg: Page, i: int, text: str) -> None:
    """Empty row ``i`` and type ``text`` key by key, as a user does (the row's input event:
    Playwright's fill sends none, and the page reads only what the user types)."""
    area = pg.locator(f"#seg-text-{i} textarea")
    area.click()
    area.press("Control+a")
    area.press("Backspace")
    area.type(text, delay=15)


def pick_method(pg: Page, display_name: str) -> None:
    pg.locator("#method label", has_text=display_name).click()


def set_seed(pg: Page, seed: int) -> None:
    pg.get_by_text("Advanced", exact=True).click()
    pg.fill("#seed input", str(seed))
    pg.locator("#seed input").blur()


def viewer_frame(pg: Page) -> Frame:
    """The main viewer's frame, once its script runs."""
    frame = pg.wait_for_selector("iframe.mms-viewer", timeout=60_000).content_frame()
    assert frame is not None
    frame.wait_for_function("!!window.viewer && location.pathname.endsWith('viewer.html')", timeout=60_000)
    return frame


def generate(pg: Page, button: str = "#generate") -> Frame:
    """Click Generate (or New seed) and wait until the viewer draws the new motion."""
    frame = viewer_frame(pg)
    old = frame.evaluate("viewer.url")
    pg.click(button)
    frame.wait_for_function(
        "(old) => viewer.url !== old && viewer.ready && viewer.loadedAt !== null", arg=old, timeout=GENERATE_TIMEOUT_MS
    )
    return frame


def grid_frames(pg: Page, n: int, kind: str) -> list[Frame]:
    """The n viewers of the compare / variations grid, once each has drawn its motion."""
    tiles = f"#multi-view .mms-grid-{kind} iframe.mms-tile-viewer"
    pg.wait_for_function(f"document.querySelectorAll({tiles!r}).length === {n}", timeout=GENERATE_TIMEOUT_MS)
    frames = [h.content_frame() for h in pg.query_selector_all(tiles)]
    for f in frames:
        f.wait_for_function("window.viewer && viewer.ready && viewer.loadedAt !== null", timeout=60_000)
    return frames


def scrub_to(frame: Frame, t: float) -> None:
    """Pause a viewer at ``t`` seconds through its scrubber, as a user drags it: the viewer
    redraws (it draws on demand), and the other viewers of a grid follow their lead."""
    frame.evaluate(
        """(t) => { viewer.pause(); const s = document.getElementById('scrub');
        s.value = String(Math.round(t * viewer.fps)); s.dispatchEvent(new Event('input')); }""",
        t,
    )


def wait_paused_at(frames: list[Frame], t: float) -> None:
    """Until every viewer of a grid has followed its lead: paused, on the frame of ``t``."""
    for f in frames:
        f.wait_for_function(
            "(t) => !viewer.playing && viewer.frame === Math.round(t * viewer.fps)", arg=t, timeout=10_000
        )


def play_from(frame: Frame, t: float, settle_ms: int = 800) -> None:
    """Hold the viewer at ``t`` seconds while the page settles, then let it play: a picture
    taken right after shows (about) that moment, playing, on however loaded a machine."""
    scrub_to(frame, t)
    frame.page.wait_for_timeout(settle_ms)
    frame.evaluate("viewer.play()")


def wait_toast(pg: Page, fragment: str) -> None:
    pg.locator("[data-testid='toast-text']", has_text=fragment).first.wait_for(timeout=20_000)


def shoot_region(pg: Page, out: Path, selectors: list[str], pad: int = 8) -> None:
    """A picture of the smallest box around ``selectors``, in page coordinates (it may be
    taller than the window)."""
    pg.locator(selectors[0]).scroll_into_view_if_needed()
    pg.wait_for_timeout(500)
    sx, sy = pg.evaluate("[window.scrollX, window.scrollY]")
    boxes = [b for s in selectors if (b := pg.locator(s).bounding_box())]
    x0, y0 = min(b["x"] for b in boxes) + sx - pad, min(b["y"] for b in boxes) + sy - pad
    x1 = max(b["x"] + b["width"] for b in boxes) + sx + pad
    y1 = max(b["y"] + b["height"] for b in boxes) + sy + pad
    pg.screenshot(path=str(out), full_page=True, clip={"x": x0, "y": y0, "width": x1 - x0, "height": y1 - y0})


# ---------------------------------------------------------------- the pictures


def opened(browser: Browser, url: str, out: Path) -> None:
    """The page as a new user first sees it at 1400x900."""
    pg = open_page(browser, url)
    viewer_frame(pg)
    pg.wait_for_timeout(800)
    pg.screenshot(path=str(out))


def phone_opened(browser: Browser, url: str, out: Path) -> None:
    """The page as it opens on a phone: the viewer above the controls."""
    pg = open_page(browser, url, PHONE, is_mobile=True, has_touch=True)
    viewer_frame(pg)
    pg.wait_for_timeout(800)
    pg.screenshot(path=str(out))


def motion_end(browser: Browser, url: str, out: Path) -> None:
    """The story played to its end with loop off: the viewer stops on the last pose."""
    pg = open_page(browser, url)
    set_timeline(pg, STORY)
    frame = generate(pg)
    pg.evaluate("window.scrollTo(0, 0)")
    frame.uncheck("#loop")
    frame.evaluate("viewer.setTime(viewer.duration - 0.5); viewer.play()")
    frame.wait_for_function("!viewer.playing && viewer.time === viewer.duration", timeout=30_000)
    pg.wait_for_timeout(500)
    pg.screenshot(path=str(out))


def first_screen(browser: Browser, url: str, out: Path, at: float = 4.6) -> None:
    """The three-segment story with the preselected method, in the middle of the wave."""
    pg = open_page(browser, url)
    set_timeline(pg, STORY)
    frame = generate(pg)
    pg.evaluate("window.scrollTo(0, 0)")  # Generate scrolled the page to the result
    play_from(frame, at)
    pg.screenshot(path=str(out))


def prompt_guidance(browser: Browser, url: str, out: Path) -> None:
    """An unfamiliar prompt, typed: the warning and nearest phrasings, the known actions open."""
    pg = open_page(browser, url)
    set_timeline(pg, [("", 3)])
    pg.locator("#seg-text-0 textarea").type("make me a cheese sandwich", delay=20)
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('have not learned anything like')")
    frame = generate(pg)
    pg.get_by_text("What the models know (").click()  # the accordion, not the warnings
    pg.locator("#known-actions").get_by_text("jumping jacks", exact=True).wait_for()
    pg.evaluate("window.scrollTo(0, 0)")
    play_from(frame, 1.5)
    pg.screenshot(path=str(out), clip={"x": 0, "y": 0, "width": DESKTOP["width"], "height": 1650}, full_page=True)


def form_error(browser: Browser, url: str, out: Path) -> None:
    """The story generated, then a duration over the limit: one titled message, all else kept."""
    pg = open_page(browser, url)
    set_timeline(pg, STORY)
    frame = generate(pg)
    pg.fill("#seg-sec-1 input", "12")
    pg.locator("#seg-sec-1 input").blur()
    pg.click("#generate")
    wait_toast(pg, "duration 12 s is outside 1-10 s")
    pg.evaluate("window.scrollTo(0, 0)")
    play_from(frame, 4.6)
    pg.screenshot(path=str(out))


def _typed_split(browser: Browser, url: str) -> Page:
    """A clap, then the three-action sentence typed into the second row: the offer shown."""
    pg = open_page(browser, url)
    set_timeline(pg, [("a person claps twice", 2), ("", 3)])
    type_row(pg, 1, SPLIT_SENTENCE)
    pg.locator("#seg-split-btn-1").wait_for(state="visible", timeout=30_000)
    pg.wait_for_timeout(800)
    return pg


def split_offer(browser: Browser, url: str, out: Path) -> None:
    """The row with its one-line reading and "Split into 3 segments"."""
    pg = _typed_split(browser, url)
    shoot_region(pg, out, ["#seg-row-0", "#timeline-strip"])


def split_rows(browser: Browser, url: str, out: Path) -> None:
    """The same timeline after the click: the plan's rows, their seconds estimated."""
    pg = _typed_split(browser, url)
    pg.click("#seg-split-btn-1")
    pg.locator("#seg-row-3").wait_for(state="visible")
    pg.wait_for_function("document.querySelectorAll('#timeline-strip .mms-block').length === 4", timeout=10_000)
    pg.wait_for_timeout(800)
    shoot_region(pg, out, ["#seg-row-0", "#timeline-strip"])


def reader_warning(browser: Browser, url: str, out: Path) -> None:
    """A known and an unknown part in one row, typed and generated: the warning names the
    unknown part and its nearest known action, under the timeline and under the viewer."""
    pg = open_page(browser, url)
    set_timeline(pg, [("", 6)])
    type_row(pg, 0, READER_WARNING)
    pg.wait_for_function("document.querySelector('#prompt-guide').innerText.includes('climbs the stairs')")
    frame = generate(pg)
    pg.wait_for_function("document.querySelector('#timing').innerText.includes('climbs the stairs')")
    pg.evaluate("window.scrollTo(0, 0)")
    play_from(frame, 1.5)
    pg.screenshot(path=str(out))


def top_view_path(browser: Browser, url: str, out: Path) -> None:
    """A circle walked clockwise, seen from the top camera, with the root's path on the floor."""
    pg = open_page(browser, url)
    set_timeline(pg, [("a person walks in a circle clockwise", 8)])
    frame = generate(pg)
    frame.select_option("#view", "top")
    scrub_to(frame, 7.4)  # near the end: most of the path walked
    pg.wait_for_timeout(800)
    pg.locator("iframe.mms-viewer").screenshot(path=str(out))


def phone(browser: Browser, url: str, out: Path) -> None:
    """A wave generated at 390 px: the viewer and its wrapped controls."""
    pg = open_page(browser, url, PHONE, is_mobile=True, has_touch=True)
    set_timeline(pg, [("a person waves with the right hand", 4)])
    pg.locator("#generate").scroll_into_view_if_needed()  # the button is below the viewer
    frame = generate(pg)
    # the page brings the viewer into view with the new motion: no scrolling here
    pg.wait_for_function(
        "() => { const r = document.querySelector('iframe.mms-viewer').getBoundingClientRect();"
        " return r.top > -2 && r.top < window.innerHeight; }",
        timeout=20_000,
    )
    play_from(frame, 1.2)
    pg.screenshot(path=str(out))


def compare(browser: Browser, url: str, out: Path) -> None:
    """Compare all methods: one viewer per method, paused together at the same frame."""
    pg = open_page(browser, url)
    set_timeline(pg, [("a person waves with the right hand", 3)])
    pg.click("#compare")
    frames = grid_frames(pg, 4, "compare")
    pg.wait_for_function("document.querySelector('#multi-view .mms-pending') === null", timeout=10_000)
    scrub_to(frames[0], 1.2)
    wait_paused_at(frames, 1.2)
    pg.wait_for_timeout(500)
    pg.screenshot(path=str(out))  # the window as it is: the page brought the grid into view


def variations(browser: Browser, url: str, out: Path) -> None:
    """4 variations (seeds 0-3) of one prompt; seed 2 picked for the main viewer."""
    pg = open_page(browser, url)
    set_timeline(pg, [("a person kicks with the right foot twice", 4)])
    pg.click("#variations")
    frames = grid_frames(pg, 4, "variations")
    urls = [f.evaluate("viewer.url") for f in frames]
    pg.locator("#pick label", has_text="seed 2").click()
    viewer_frame(pg).wait_for_function("(u) => viewer.url === u && viewer.ready", arg=urls[2], timeout=60_000)
    scrub_to(frames[0], 1.5)
    wait_paused_at(frames, 1.5)
    shoot_region(pg, out, ["#multi-view", "#pick"])


def link_history(browser: Browser, url: str, out: Path) -> None:
    """Two generations in one tab: the link to the second, the first under "Earlier in this tab"."""
    pg = open_page(browser, url)
    set_timeline(pg, [("a person sits down", 3)])
    generate(pg)
    set_timeline(pg, STORY)
    generate(pg)
    pg.wait_for_function("document.querySelector('#mms-history').innerText.includes('Earlier in this tab')")
    pg.locator("#mms-history summary").click()  # the list is folded until opened
    shoot_region(pg, out, ["#timing", "#history-box"])


SHOTS: dict[str, Callable[[Browser, str, Path], None]] = {
    "demo-opened": opened,
    "demo-phone-opened": phone_opened,
    "demo-first-screen": first_screen,
    "demo-motion-end": motion_end,
    "demo-prompt-guidance": prompt_guidance,
    "demo-form-error": form_error,
    "demo-split": split_offer,
    "demo-split-rows": split_rows,
    "demo-reader-warning": reader_warning,
    "viewer-top-view-path": top_view_path,
    "demo-phone": phone,
    "demo-compare": compare,
    "demo-variations": variations,
    "demo-link-history": link_history,
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", default="http://127.0.0.1:7860")
    ap.add_argument("--docs", type=Path, default=Path("docs"), help="where the pictures go (NAME.png)")
    ap.add_argument("--only", nargs="+", choices=list(SHOTS), metavar="NAME", help=f"of: {', '.join(SHOTS)}")
    ap.add_argument("--at", type=float, default=4.6, help="the first screen's seconds into the motion")
    args = ap.parse_args()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--no-sandbox", "--disable-gpu"])
        for name in args.only or list(SHOTS):
            out = args.docs / f"{name}.png"
            if name == "demo-first-screen":
                first_screen(browser, args.url, out, args.at)
            else:
                SHOTS[name](browser, args.url, out)
            for ctx in browser.contexts:  # one page at a time: close what the picture opened
                ctx.close()
            print(out)
        browser.close()


if __name__ == "__main__":
    main()
