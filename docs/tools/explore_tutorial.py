"""The README's tutorial zoom, made in the explorer by a script: headless
Chromium through chromedriver does what the tutorial tells a user to do.

    cargo build --release && python3 docs/tools/explore_tutorial.py

writes docs/explore.png (the page at the end) and docs/explore_tutorial.ron
(the timeline it saved). Needs chromium, chromedriver and Pillow.
"""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
from webdriver import Browser  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
ENTER, CLEAR = "\ue007", "\ue003\ue003\ue003\ue003"


def tutorial(b):
    b.settled()
    # 1. Orbit to look from above, and click a bud to aim at it.
    b.drag(160, 90, -100, 80)
    b.settled()
    b.click(128, 106)
    b.settled()
    # 2. Type the start distance and iterations, and key them with K.
    typed(b, "camera.distance", "2.8")
    typed(b, "fractal.iterations", "10")
    key(b)
    # 3. At the last frame, wheel in towards the bud, aim at its star, closer.
    go_to(b, 95)
    for _ in range(4):
        b.wheel(160, 90, -400)
        b.settled()
    b.click(165, 100)
    b.settled()
    b.wheel(160, 90, -400)
    b.settled()
    typed(b, "fractal.iterations", "14")
    key(b)
    # 4. Play it small, then save it under a name.
    b.press("play")
    b.until("page.playCache.size >= 40", 120)
    b.press("play")
    go_to(b, 60)
    b.js("document.activeElement.blur()")
    b.press("save-as")
    b.call("POST", "/alert/text", {"text": "myzoom.ron"})
    b.call("POST", "/alert/accept", {})
    b.until("!page.state.dirty && page.state.name === 'myzoom.ron'")
    b.settled()


def typed(b, name, text):
    field = b.call("POST", "/element", {"using": "css selector",
                                        "value": f".param[data-name='{name}'] input"})
    element = next(iter(field.values()))
    b.call("POST", f"/element/{element}/clear", {})
    b.call("POST", f"/element/{element}/value", {"text": text + ENTER})
    b.settled()


def key(b):
    count = "page.state.tracks.reduce((s, t) => s + t.keys.length, 0)"
    before = b.js(f"return {count}")
    b.js("document.getElementById('viewport').focus()")
    b.keys("viewport", "k")
    b.until(f"{count} > {before} && !Object.keys(page.overrides).length")
    b.settled()


def go_to(b, frame):
    b.keys("frame", CLEAR + str(frame) + ENTER)
    b.until(f"page.frame === {frame}")
    b.settled()


def main():
    binary = os.path.join(ROOT, "target", "release", "mandelreel")
    work = tempfile.mkdtemp()
    server = subprocess.Popen([binary, "explore"], stdout=subprocess.PIPE, text=True, cwd=work)
    browser = None
    try:
        url = server.stdout.readline().split()[-1]
        browser = Browser(os.path.join(work, "profile"))
        browser.go(url)
        tutorial(browser)
        browser.screenshot(os.path.join(ROOT, "docs", "explore.png"))
        shutil.copy(os.path.join(work, "myzoom.ron"), os.path.join(ROOT, "docs", "explore_tutorial.ron"))
    finally:
        if browser:
            browser.close()
        server.kill()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
