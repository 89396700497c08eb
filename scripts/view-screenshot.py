#!/usr/bin/env python3
"""A screenshot of a page `dispex view` wrote, as Chromium headless draws it (WebGL on SwiftShader).

Usage: scripts/view-screenshot.py PAGE.html OUT.png [--state 'colour=resolution&azimuth=30']
       [--size 960x540] [--chromium PATH]

--state is the page's URL hash (surface, colour, azimuth, elevation, zoom, lit, face: the
controls of src/view/page/viewer.js). Waits for the page's first frame (window.dispexReady);
fails with the page's own message (window.dispexError) when it cannot draw, and exits 77 when
Chromium is not installed. Python's standard library only (scripts/chromium_cdp.py).
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import chromium_cdp as cdp  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page")
    parser.add_argument("output")
    parser.add_argument("--state", default="", help="the page's URL hash")
    parser.add_argument("--size", default="960x540", help="WxH, CSS pixels")
    parser.add_argument("--chromium", help="the browser (default: chromium on PATH)")
    args = parser.parse_args()
    chromium = args.chromium or cdp.find_chromium()
    if not chromium:
        print("view-screenshot: Chromium is not installed (apt-get install chromium)", file=sys.stderr)
        return 77
    if not os.path.isfile(args.page):
        print(f"view-screenshot: {args.page}: no such file", file=sys.stderr)
        return 1
    width, height = (int(x) for x in args.size.lower().split("x"))
    browser = cdp.Browser(chromium, width, height)
    try:
        browser.send("Page.enable")
        browser.send("Emulation.setDeviceMetricsOverride",
                     {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})
        url = "file://" + os.path.abspath(args.page) + ("#" + args.state if args.state else "")
        browser.send("Page.navigate", {"url": url})
        if not browser.wait_for("window.dispexReady === true || window.dispexError !== undefined",
                                180):
            print(f"view-screenshot: {args.page}: no frame drawn in 180 s", file=sys.stderr)
            return 1
        error = browser.evaluate("window.dispexError || null")
        if error:
            print(f"view-screenshot: {args.page}: {error}", file=sys.stderr)
            return 1
        png = browser.screenshot()
    finally:
        browser.close()
    with open(args.output + ".tmp", "wb") as f:
        f.write(png)
    os.replace(args.output + ".tmp", args.output)
    return 0


if __name__ == "__main__":
    sys.exit(main())
