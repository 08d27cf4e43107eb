#!/usr/bin/env python3
"""Opens HTML reports in headless Chromium and fails on anything a reader would see broken.

usage: scripts/check-html.py [--screenshots DIR] [--tiles PX] [--browser PATH] REPORT.html [REPORT.html ...]

For each page: every console message of level error (a failed load, a blocked resource, a
script error), every picture that did not decode, and every video that could not be read are
reported, and a full-page screenshot is saved as DIR/<n>-<parent folder>.png (default
DIR: ./html-screenshots). Exit 0 when every page is clean, 1 when one is not, 2 when the
browser cannot be started.

Chromium is driven over the DevTools protocol on a pipe (--remote-debugging-pipe), so the
check needs nothing but the Python standard library and a Chromium binary (`chromium`,
`chromium-browser` or `google-chrome` on PATH, or --browser).
"""

import argparse
import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PAGE_TIMEOUT_S = 60
WIDTH = 1280
MAX_HEIGHT = 16000

# What the page looks like to a reader once it has loaded: pictures that did not decode and
# videos the browser could not read (or has not read even their size from).
INSPECT = """JSON.stringify({
  images: [...document.images]
    .filter(i => !i.complete || i.naturalWidth === 0)
    .map(i => i.alt || i.currentSrc.slice(0, 80)),
  videos: [...document.querySelectorAll('video')]
    .filter(v => v.error || v.readyState < 1 || v.videoWidth === 0)
    .map(v => (v.getAttribute('src') || '?') + (v.error ? ' (error ' + v.error.code + ')' : ' (not loaded)')),
  height: Math.ceil(document.documentElement.scrollHeight)
})"""


class Browser:
    """Chromium with its DevTools protocol on file descriptors 3 (to it) and 4 (from it)."""

    def __init__(self, binary):
        self.profile = tempfile.mkdtemp(prefix="nesy-check-html-")
        to_browser_r, self.to_browser = os.pipe()
        self.from_browser, from_browser_w = os.pipe()
        # The child reads commands on fd 3 and writes replies on fd 4.
        def child_fds():
            os.dup2(to_browser_r, 3)
            os.dup2(from_browser_w, 4)

        self.process = subprocess.Popen(
            [
                binary,
                "--headless=new",
                "--remote-debugging-pipe",
                "--no-sandbox",  # runs as root in containers and CI
                "--disable-gpu",
                "--no-first-run",
                "--no-default-browser-check",
                "--disable-extensions",
                "--mute-audio",
                f"--user-data-dir={self.profile}",
                "about:blank",
            ],
            pass_fds=(3, 4),
            preexec_fn=child_fds,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_browser_r)
        os.close(from_browser_w)
        self.buffer = b""
        self.next_id = 0
        self.events = []

    def send(self, method, params=None, session=None):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.to_browser, json.dumps(message).encode() + b"\0")
        return self.wait_for(lambda m: m.get("id") == self.next_id, f"the reply to {method}")

    def wait_for(self, matches, what, timeout=PAGE_TIMEOUT_S):
        deadline = time.monotonic() + timeout
        for event in list(self.events):
            if matches(event):
                self.events.remove(event)
                return event
        while time.monotonic() < deadline:
            while b"\0" not in self.buffer:
                chunk = os.read(self.from_browser, 1 << 16)
                if not chunk:
                    raise RuntimeError(f"the browser closed its pipe while waiting for {what}")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            message = json.loads(raw)
            if "error" in message:
                raise RuntimeError(f"{what}: {message['error'].get('message')}")
            if matches(message):
                return message
            self.events.append(message)
        raise RuntimeError(f"timed out after {timeout} s waiting for {what}")

    def close(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def check_page(browser, page, screenshot, tile_height=0):
    """The problems found on `page`; saves its screenshot."""
    target = browser.send("Target.createTarget", {"url": "about:blank"})["result"]["targetId"]
    session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})["result"]["sessionId"]
    for domain in ("Page", "Runtime", "Log"):
        browser.send(f"{domain}.enable", session=session)
    browser.send(
        "Emulation.setDeviceMetricsOverride",
        {"width": WIDTH, "height": 900, "deviceScaleFactor": 1, "mobile": False},
        session=session,
    )
    browser.events.clear()
    browser.send("Page.navigate", {"url": page.resolve().as_uri()}, session=session)
    browser.wait_for(
        lambda m: m.get("method") == "Page.loadEventFired" and m.get("sessionId") == session,
        f"{page} to load",
    )
    # Give videos time to read their headers.
    deadline = time.monotonic() + 10
    while True:
        found = json.loads(
            browser.send("Runtime.evaluate", {"expression": INSPECT, "returnByValue": True}, session=session)[
                "result"
            ]["result"]["value"]
        )
        if not found["videos"] or time.monotonic() > deadline:
            break
        time.sleep(0.5)
    problems = [f"picture did not load: {name}" for name in found["images"]]
    problems += [f"video could not be read: {name}" for name in found["videos"]]
    for event in browser.events:
        if event.get("sessionId") != session:
            continue
        method, params = event.get("method"), event.get("params", {})
        if method == "Runtime.exceptionThrown":
            problems.append("script error: " + params["exceptionDetails"].get("text", "?"))
        elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            problems.append("console error: " + " ".join(str(a.get("value", "")) for a in params.get("args", [])))
        elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
            entry = params["entry"]
            problems.append(f"console error: {entry.get('text')} {entry.get('url', '')}".strip())
    height = max(600, min(MAX_HEIGHT, int(found["height"])))
    browser.send(
        "Emulation.setDeviceMetricsOverride",
        {"width": WIDTH, "height": height, "deviceScaleFactor": 1, "mobile": False},
        session=session,
    )
    shot = browser.send("Page.captureScreenshot", {"format": "png"}, session=session)["result"]["data"]
    screenshot.write_bytes(base64.b64decode(shot))
    # Tiles of a long page, each small enough to look at on a screen.
    for k, top in enumerate(range(0, height, tile_height) if tile_height else []):
        clip = {"x": 0, "y": top, "width": WIDTH, "height": min(tile_height, height - top), "scale": 1}
        tile = browser.send("Page.captureScreenshot", {"format": "png", "clip": clip}, session=session)
        screenshot.with_name(f"{screenshot.stem}-{k + 1}.png").write_bytes(base64.b64decode(tile["result"]["data"]))
    browser.send("Target.closeTarget", {"targetId": target})
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("pages", nargs="+", type=Path)
    parser.add_argument("--screenshots", type=Path, default=Path("html-screenshots"))
    parser.add_argument("--browser")
    parser.add_argument("--tiles", type=int, default=0, metavar="PX", help="also save the page in tiles PX tall")
    args = parser.parse_args()
    binary = args.browser or next(
        (b for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None
    )
    if not binary:
        print("check-html: no Chromium found (install `chromium`, or pass --browser PATH)", file=sys.stderr)
        return 2
    for page in args.pages:
        if not page.is_file():
            print(f"check-html: {page}: no such file", file=sys.stderr)
            return 2
    args.screenshots.mkdir(parents=True, exist_ok=True)
    try:
        browser = Browser(binary)
    except OSError as e:
        print(f"check-html: could not start {binary}: {e}", file=sys.stderr)
        return 2
    failed = 0
    try:
        for n, page in enumerate(args.pages, 1):
            screenshot = args.screenshots / f"{n}-{page.resolve().parent.name}.png"
            problems = check_page(browser, page, screenshot, args.tiles)
            status = "ok" if not problems else f"{len(problems)} problem(s)"
            print(f"{page}: {status}; screenshot {screenshot}")
            for problem in problems:
                print(f"  {problem}")
            failed += bool(problems)
    except RuntimeError as e:
        print(f"check-html: {e}", file=sys.stderr)
        return 2
    finally:
        browser.close()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
