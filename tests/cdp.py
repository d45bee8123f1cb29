"""A small Chrome DevTools Protocol client for the browser tests: headless Chromium over one websocket.

Starts the system's headless Chromium with a debugging port (no browser download), opens a page
target, and speaks the protocol directly: navigate, evaluate JavaScript, dispatch real mouse and
keyboard input, record network requests, take screenshots.
"""

from __future__ import annotations

import base64
import json
import shutil
import subprocess
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: the browsers tried, headless shell first (what .ci/run installs)
BROWSERS = ("chromium-headless-shell", "chromium", "chromium-browser", "google-chrome")


def find_browser() -> str | None:
    """The first headless-capable Chromium on PATH, or None."""
    for name in BROWSERS:
        exe = shutil.which(name)
        if exe:
            return exe
    return None


class Browser:
    """One headless Chromium process and a websocket to it; use as a context manager."""

    def __init__(self, exe: str, *, width: int = 1400, height: int = 1000) -> None:
        import websocket  # websocket-client

        self._profile = tempfile.TemporaryDirectory(prefix="cdp-")
        self.proc = subprocess.Popen(
            [
                exe,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--no-first-run",
                "--no-default-browser-check",
                "--remote-debugging-port=0",
                f"--user-data-dir={self._profile.name}",
                f"--window-size={width},{height}",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        port_file = Path(self._profile.name) / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not (port_file.is_file() and len(port_file.read_text().splitlines()) >= 2):
            if self.proc.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"{exe} did not open its DevTools port")
            time.sleep(0.05)
        port, path = port_file.read_text().splitlines()[:2]
        self.ws = websocket.create_connection(
            f"ws://127.0.0.1:{port}{path}", timeout=60, suppress_origin=True
        )
        self._id = 0
        self.events: list[dict[str, Any]] = []
        self.size = (width, height)

    def send(self, method: str, params: dict[str, Any] | None = None, session: str | None = None) -> dict:
        """Call a protocol method and wait for its answer; events arriving meanwhile are kept."""
        self._id += 1
        msg: dict[str, Any] = {"id": self._id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        while True:
            reply = json.loads(self.ws.recv())
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_event(
        self,
        method: str,
        session: str,
        timeout: float = 20,
        where: Callable[[dict], bool] | None = None,
        forget: tuple[str, ...] = (),
    ) -> dict:
        """The first (kept or new) event `method` of the session whose params pass `where`; kept
        events of the `forget` methods that arrived before it are dropped as stale."""
        deadline = time.monotonic() + timeout
        while True:
            for i, e in enumerate(self.events):
                if e.get("method") == method and e.get("sessionId") == session:
                    if where is not None and not where(e.get("params", {})):
                        continue
                    stale = [
                        j
                        for j, k in enumerate(self.events[:i])
                        if k.get("method") in forget and k.get("sessionId") == session
                    ]
                    event = self.events.pop(i)
                    for j in reversed(stale):
                        self.events.pop(j)
                    return event
            if time.monotonic() > deadline:
                raise TimeoutError(method)
            self.events.append(json.loads(self.ws.recv()))

    def new_page(self) -> Page:
        target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        page = Page(self, session)
        page.call("Page.enable")
        page.call("Runtime.enable")
        page.call("Network.enable")
        w, h = self.size
        page.call("Emulation.setDeviceMetricsOverride", width=w, height=h, deviceScaleFactor=1, mobile=False)
        return page

    def close(self) -> None:
        if getattr(self, "ws", None) is not None:
            try:
                self.send("Browser.close")
            except Exception:  # the browser may close the socket before answering
                pass
            self.ws.close()
            self.ws = None
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        self._profile.cleanup()

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Page:
    """A page target attached with a flat session."""

    def __init__(self, browser: Browser, session: str) -> None:
        self.browser, self.session = browser, session

    def call(self, method: str, **params: Any) -> dict:
        return self.browser.send(method, params, self.session)

    def requests(self) -> list[str]:
        """URLs of every request the page made so far (Network.requestWillBeSent)."""
        return [
            e["params"]["request"]["url"]
            for e in self.browser.events
            if e.get("sessionId") == self.session and e.get("method") == "Network.requestWillBeSent"
        ]

    def goto(self, url: str) -> float:
        """Navigate and wait for the load event; returns the wall time it took, seconds."""
        t0 = time.perf_counter()
        loader = self.call("Page.navigate", url=url).get("loaderId")
        # the load event of this navigation: its document committed first (a load event kept from an
        # earlier one, such as the about:blank of a new tab, is stale and was raced against)
        self.browser.wait_event(
            "Page.frameNavigated",
            self.session,
            where=lambda p: p.get("frame", {}).get("loaderId") == loader,
            forget=("Page.loadEventFired",),
        )
        self.browser.wait_event("Page.loadEventFired", self.session)
        return time.perf_counter() - t0

    def js(self, expression: str) -> Any:
        """Evaluate JavaScript in the page and return its (JSON) value; page errors raise."""
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(r["exceptionDetails"].get("exception", {}).get("description", str(r)))
        return r["result"].get("value")

    def box(self, selector: str) -> dict[str, float]:
        """The element's bounding box in CSS pixels, scrolled into view."""
        return self.js(
            f"(() => {{ const e = document.querySelector({json.dumps(selector)});"
            " e.scrollIntoView({block: 'center'}); const r = e.getBoundingClientRect();"
            " return {x: r.x, y: r.y, w: r.width, h: r.height}; })()"
        )

    def click_at(self, x: float, y: float) -> None:
        """A real left click (press and release) at viewport coordinates."""
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)

    def click(self, selector: str, fraction: float = 0.5) -> None:
        """Click the element at `fraction` of its width, mid-height (a slider's track position)."""
        b = self.box(selector)
        self.click_at(b["x"] + fraction * b["w"], b["y"] + b["h"] / 2)

    def key(self, key: str, code: int) -> None:
        """Press and release one key (e.g. "ArrowRight", 39) in the focused element."""
        for kind in ("rawKeyDown", "keyUp"):
            self.call("Input.dispatchKeyEvent", type=kind, key=key, code=key, windowsVirtualKeyCode=code)

    def backspace(self) -> None:
        """Press and release Backspace in the focused element (empties a selected box)."""
        self.key("Backspace", 8)

    def type_text(self, text: str) -> None:
        """Type text into the focused element as a keyboard would (one input event)."""
        self.call("Input.insertText", text=text)

    def viewport(self, width: int, height: int, *, mobile: bool = False) -> None:
        """Emulate a screen of width x height CSS pixels (a phone's when `mobile`)."""
        self.call(
            "Emulation.setDeviceMetricsOverride",
            width=width,
            height=height,
            deviceScaleFactor=1,
            mobile=mobile,
        )

    def ax_tree(self) -> list[dict[str, Any]]:
        """The browser's accessibility tree, flat: what a screen reader is given (role, name, ...)."""
        self.call("Accessibility.enable")
        return self.call("Accessibility.getFullAXTree")["nodes"]

    def screenshot(self, path: Path) -> Path:
        data = self.call("Page.captureScreenshot", format="png", captureBeyondViewport=True)["data"]
        path.write_bytes(base64.b64decode(data))
        return path
