"""The README's first-screen picture, taken from the running demo in Debian's chromium.

    python app.py &                       # or any running demo
    python tools/demo_screenshots.py --url http://127.0.0.1:7860 --out docs/demo-first-screen.png

Composes a three-segment story through the page's own fields, generates it with the
preselected method, lets it play to the middle of the second segment and takes the page.
"""

from __future__ import annotations

import argparse

from playwright.sync_api import sync_playwright

STORY = [
    ("a person walks forward", 3),
    ("a person waves with the right hand", 3),
    ("a person jumps in place twice", 2.5),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", default="http://127.0.0.1:7860")
    ap.add_argument("--out", default="docs/demo-first-screen.png")
    ap.add_argument("--at", type=float, default=4.6, help="seconds into the motion")
    args = ap.parse_args()
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--no-sandbox", "--disable-gpu"])
        pg = browser.new_page(viewport={"width": 1400, "height": 900})
        pg.goto(args.url)
        pg.wait_for_selector("#generate")
        while pg.locator("[id^=seg-row-]:visible").count() < len(STORY):
            pg.click("#seg-add")
            pg.wait_for_timeout(300)
        for i, (text, sec) in enumerate(STORY):
            pg.fill(f"#seg-text-{i} textarea", text)
            pg.fill(f"#seg-sec-{i} input", str(sec))
        pg.locator(f"#seg-sec-{len(STORY) - 1} input").blur()
        frame = pg.wait_for_selector("iframe.mms-viewer", timeout=60_000).content_frame()
        frame.wait_for_function("!!window.viewer")
        old = frame.evaluate("viewer.url")
        pg.click("#generate")
        frame.wait_for_function("(old) => viewer.url !== old && viewer.ready", arg=old, timeout=180_000)
        frame.evaluate(f"viewer.setTime({args.at})")
        pg.evaluate("window.scrollTo(0, 0)")  # Generate scrolled the page to the result
        pg.wait_for_timeout(800)
        pg.screenshot(path=args.out)
        browser.close()
    print(args.out)


if __name__ == "__main__":
    main()
