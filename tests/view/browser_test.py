#!/usr/bin/env python3
"""The review page of `dispex view` in a real browser: Chromium headless (WebGL on SwiftShader).

Writes a test map on the OpenSubdiv cube (view_test_map: Ptex face 0 a constant +0.1, face 1 a
constant -0.1, faces 2 and 3 of 8 x 8 and 64 x 64 texels), a verify report with an error per
face, a small sculpt, and the page (`dispex view`); opens the page from disk and checks, with
the camera set by the page's URL hash to look at one face straight on:
  - it draws its first frame (window.dispexReady) and throws nothing;
  - the screenshots are not blank (the surface covers part of the canvas, in several colours);
  - colours of known faces at the canvas's centre: displacement (face 0 green, face 1 red, the
    preview's colours), resolution (face 0 stored constant: grey; face 3, the finest: the
    ramp's end), verify error (face 0 within tolerance: green; face 1 three tolerances: red);
  - a click at the centre picks the face there: the panel names it;
  - the sculpt draws;
  - the page made no network request: every request Chromium reports is the page's own file
    or a data: URL (the Chrome DevTools Protocol's Network events).
Exits 77 (ctest's skip) only where Chromium is not installed. Python's standard library only
(scripts/chromium_cdp.py speaks the protocol over --remote-debugging-pipe).
"""

import argparse
import base64
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import chromium_cdp as cdp  # noqa: E402

WIDTH, HEIGHT = 1100, 700
BACKGROUND = (0x3B, 0x3F, 0x46)
FAILURES = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message, flush=True)
    if not condition:
        FAILURES.append(message)


def run(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"{' '.join(command)}: exit {result.returncode}\n{result.stderr}")
    return result


def face_directions(obj_path):
    """Per face of the cage: (azimuth, elevation) in degrees of its centroid seen from the
    centre of the cage's bounding box (the page's azimuth turns about +y from +z to +x)."""
    vertices, faces = [], []
    for line in open(obj_path):
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append([int(p.split("/")[0]) - 1 for p in parts[1:]])
    lo = [min(v[c] for v in vertices) for c in range(3)]
    hi = [max(v[c] for v in vertices) for c in range(3)]
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    directions = []
    for face in faces:
        c = [sum(vertices[i][k] for i in face) / len(face) - centre[k] for k in range(3)]
        length = math.sqrt(sum(x * x for x in c))
        directions.append((math.degrees(math.atan2(c[0], c[2])),
                           math.degrees(math.asin(c[1] / length))))
    return directions


class Page:
    def __init__(self, browser, path):
        self.browser = browser
        self.url = "file://" + os.path.abspath(path)

    def open(self, state):
        self.browser.send("Page.navigate", {"url": self.url + "#" + state})
        ready = self.browser.wait_for(
            "window.dispexReady === true || window.dispexError !== undefined", 180)
        error = self.browser.evaluate("window.dispexError || null")
        return ready and error is None, error

    def show(self, state):
        """Sets the page's state through its URL hash and waits for two frames."""
        self.browser.evaluate(f"location.hash = {json.dumps(state)}; true")
        self.browser.evaluate(
            "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(true))))")

    def canvas(self):
        return self.browser.evaluate(
            "(() => { const r = dispex.canvasRect(); return [r.left, r.top, r.width, r.height]; })()")

    def pixels(self, x, y, width, height, scale=1.0):
        shot = self.browser.send("Page.captureScreenshot", {
            "format": "png",
            "clip": {"x": x, "y": y, "width": width, "height": height, "scale": scale}})
        _, _, rows = cdp.decode_png(base64.b64decode(shot["data"]))
        return [[tuple(row[3 * i:3 * i + 3]) for i in range(len(row) // 3)] for row in rows]

    def centre_colour(self):
        """The median colour of the 5 x 5 pixels at the canvas's centre."""
        left, top, width, height = self.canvas()
        cx, cy = left + width / 2, top + height / 2
        patch = [p for row in self.pixels(cx - 2, cy - 2, 5, 5) for p in row]
        return tuple(sorted(p[c] for p in patch)[len(patch) // 2] for c in range(3))

    def coverage(self):
        """The share of the canvas (at 1/8 scale) that is not background, and how many distinct
        colours (in steps of 32) it shows."""
        left, top, width, height = self.canvas()
        pixels = [p for row in self.pixels(left, top, width, height, 0.125) for p in row]
        drawn = [p for p in pixels if max(abs(a - b) for a, b in zip(p, BACKGROUND)) > 12]
        return len(drawn) / max(1, len(pixels)), len({tuple(c // 32 for c in p) for p in drawn})

    def click_centre(self):
        left, top, width, height = self.canvas()
        self.browser.click(left + width / 2, top + height / 2)
        return self.browser.evaluate("document.getElementById('picked').textContent")


def close_to(colour, expected, tolerance=24):
    return all(abs(a - b) <= tolerance for a, b in zip(colour, expected))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dispex", required=True)
    parser.add_argument("--make-map", required=True, help="the view_test_map program")
    parser.add_argument("--data", required=True, help="tests/data")
    parser.add_argument("--work", required=True, help="a folder for the files (emptied)")
    parser.add_argument("--chromium", help="the browser (default: chromium on PATH)")
    args = parser.parse_args()

    chromium = args.chromium or cdp.find_chromium()
    if not chromium:
        print("skipped: Chromium is not installed (apt-get install chromium; "
              "scripts/install-deps.sh installs it with DISPEX_WITH_BROWSER=1)")
        return 77
    began = time.monotonic()
    shutil.rmtree(args.work, ignore_errors=True)
    os.makedirs(args.work)
    work = lambda name: os.path.join(args.work, name)  # noqa: E731
    cage = os.path.join(args.data, "meshes", "opensubdiv", "catmark_cube.obj")
    run([args.make_map, cage, work("cube.ptx")])
    run([args.dispex, "make-sculpt", cage, "--levels", "3", "--pattern", "smooth", "-q",
         "-o", work("cube_sculpt.obj")])
    tolerance = 0.01
    errors = [0.0, 3 * tolerance, 0.5 * tolerance, 1.5 * tolerance, 0.2 * tolerance, None]
    with open(work("verify.json"), "w") as f:
        json.dump({"ptex_faces": 6, "map": {"tolerance": tolerance}, "passed": False,
                   "failure": "a report written by the test",
                   "per_face": {"map_to_sculpt_max": errors}}, f)
    run([args.dispex, "view", cage, work("cube.ptx"), "--sculpt", work("cube_sculpt.obj"),
         "--verify", work("verify.json"), "-o", work("cube.html"), "--report", work("view.json")])
    report = json.load(open(work("view.json")))
    check(report["verify_per_face"] and report["atlas"],
          "dispex view: per-face errors and the atlas on the page")
    made = time.monotonic()

    directions = face_directions(cage)
    view = lambda face: "azimuth=%.4f&elevation=%.4f" % directions[face]  # noqa: E731
    browser = cdp.Browser(chromium, WIDTH, HEIGHT)
    try:
        for domain in ("Page", "Runtime", "Network", "Log"):
            browser.send(domain + ".enable")
        browser.send("Emulation.setDeviceMetricsOverride",
                     {"width": WIDTH, "height": HEIGHT, "deviceScaleFactor": 1, "mobile": False})
        page = Page(browser, work("cube.html"))
        opened = time.monotonic()
        ready, error = page.open("surface=displaced&colour=displacement&lit=0&" + view(0))
        check(ready, f"the page draws its first frame in {time.monotonic() - opened:.1f} s"
              + (f" (it says: {error})" if error else ""))
        if not ready:
            return 1
        drawn, colours = page.coverage()
        check(drawn > 0.05 and colours >= 2,
              f"not blank: {100 * drawn:.0f}% of the canvas drawn, {colours} colours")

        green = page.centre_colour()
        check(close_to(green, (51, 255, 51)), f"displacement: face 0 (+0.1) is green: {green}")
        picked = page.click_centre()
        check(re.search(r"\bface 0\b", picked or "") is not None and "0.1" in picked,
              f"a click picks face 0: {picked[:80]!r}")
        page.show("surface=displaced&colour=displacement&lit=0&" + view(1))
        red = page.centre_colour()
        check(close_to(red, (255, 51, 51)), f"displacement: face 1 (-0.1) is red: {red}")
        picked = page.click_centre()
        check(re.search(r"\bface 1\b", picked or "") is not None,
              f"a click picks face 1: {picked[:80]!r}")

        page.show("surface=displaced&colour=resolution&lit=0&" + view(0))
        grey = page.centre_colour()
        check(close_to(grey, (140, 140, 140)), f"resolution: face 0 (constant) is grey: {grey}")
        page.show("surface=displaced&colour=resolution&lit=0&" + view(3))
        finest = page.centre_colour()
        check(close_to(finest, (252, 232, 38)),
              f"resolution: face 3 (64 x 64, the finest) is the ramp's end: {finest}")

        page.show("surface=displaced&colour=error&lit=0&" + view(0))
        ok_colour = page.centre_colour()
        check(close_to(ok_colour, (26, 179, 51)), f"verify error: face 0 (0) is green: {ok_colour}")
        page.show("surface=displaced&colour=error&lit=0&" + view(1))
        bad_colour = page.centre_colour()
        check(close_to(bad_colour, (217, 26, 26)),
              f"verify error: face 1 (3 tolerances) is red: {bad_colour}")

        page.show("surface=sculpt&colour=displacement&lit=1&azimuth=30&elevation=25")
        drawn, colours = page.coverage()
        check(drawn > 0.05, f"the sculpt draws: {100 * drawn:.0f}% of the canvas")
        page.show("surface=displaced&colour=displacement&lit=1&azimuth=30&elevation=25")
        drawn, colours = page.coverage()
        check(drawn > 0.05 and colours >= 3,
              f"lit, from another side: {100 * drawn:.0f}% drawn, {colours} colours")
        with open(work("screenshot.png"), "wb") as f:
            f.write(browser.screenshot())

        browser.poll_events(0.3)
        page_url = page.url.split("#")[0]
        requests = [e["params"]["request"]["url"] for e in browser.events
                    if e["method"] == "Network.requestWillBeSent"]
        foreign = [u for u in requests if not (u.split("#")[0] == page_url or u.startswith("data:"))]
        check(requests and not foreign,
              f"no network request: {len(requests)} requests, all the page or data: URLs"
              + (f"; others: {foreign[:5]}" if foreign else ""))
        thrown = [e["params"]["exceptionDetails"].get("text", "") for e in browser.events
                  if e["method"] == "Runtime.exceptionThrown"]
        logged = [e["params"]["entry"]["text"] for e in browser.events
                  if e["method"] == "Log.entryAdded" and e["params"]["entry"]["level"] == "error"]
        check(not thrown and not logged, f"no script error: {(thrown + logged)[:3]}")
    finally:
        browser.close()
    print(f"browser test: {len(FAILURES)} failures; page written in {made - began:.1f} s, "
          f"browser checks {time.monotonic() - made:.1f} s (screenshot: {work('screenshot.png')})")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
