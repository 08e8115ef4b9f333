"""A headless Chromium driven over the DevTools protocol: the web controller's real browser.

The browser test and ``bench input-latency`` open the controller page in Debian's
``chromium``, override the device orientation and motion sensors, press the touch
area and take screenshots, all through a small synchronous DevTools client over the
``websockets`` library (no selenium, no driver binary). Chromium starts with the flags
a closed network needs (without them it stalls on lookups) and, for these tools only,
``--ignore-certificate-errors``: the page's certificate is the engine's self-signed one.
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

__all__ = ["Chromium", "find_chromium", "ChromiumError"]

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--ignore-certificate-errors",
    "--remote-debugging-port=0",
    "--remote-allow-origins=*",
)


SENSORS = ("relative-orientation", "accelerometer", "linear-acceleration", "gyroscope")


class ChromiumError(RuntimeError):
    """The browser did not start, or a DevTools command failed."""


def find_chromium() -> str | None:
    """The Chromium executable (``$CHROMIUM``, ``chromium``, ``chromium-browser``), or ``None``."""
    for name in (os.environ.get("CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if name and (path := shutil.which(name)):
            return path
    return None


class Chromium:
    """One headless browser with one page, and a DevTools session on that page.

    Use as a context manager; :meth:`call` sends a command and returns its result,
    :meth:`evaluate` runs JavaScript in the page.
    """

    def __init__(self, executable: str | None = None, timeout: float = 30.0) -> None:
        exe = executable or find_chromium()
        if exe is None:
            raise ChromiumError("no chromium executable (apt-get install chromium)")
        self._dir = tempfile.mkdtemp(prefix="pp-chromium-")
        self.proc = subprocess.Popen(
            [exe, *FLAGS, f"--user-data-dir={self._dir}", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        self._id = 0
        self._stack = contextlib.ExitStack()
        self.events: list[dict[str, Any]] = []
        try:
            port = self._devtools_port(timeout)
            self._ws = self._connect_page(port, timeout)
        except Exception:
            self.close()
            raise

    def _devtools_port(self, timeout: float) -> int:
        """The port Chromium writes to ``DevToolsActivePort`` in its profile once it listens."""
        marker = Path(self._dir) / "DevToolsActivePort"
        end = time.monotonic() + timeout
        while time.monotonic() < end and self.proc.poll() is None:
            try:
                return int(marker.read_text().split()[0])
            except (OSError, ValueError, IndexError):
                time.sleep(0.05)
        raise ChromiumError("chromium did not open its DevTools port")

    def _connect_page(self, port: int, timeout: float) -> Any:
        from urllib.request import urlopen

        from websockets.sync.client import connect

        end = time.monotonic() + timeout
        while time.monotonic() < end:
            with urlopen(f"http://127.0.0.1:{port}/json/list", timeout=5) as r:
                pages = [t for t in json.load(r) if t.get("type") == "page"]
            if pages:
                return self._stack.enter_context(
                    connect(pages[0]["webSocketDebuggerUrl"], max_size=None, open_timeout=timeout)
                )
            time.sleep(0.1)
        raise ChromiumError("chromium has no page")

    def call(self, method: str, timeout: float = 30.0, **params: Any) -> dict[str, Any]:
        """Send one DevTools command and wait for its result (events meanwhile go to :attr:`events`)."""
        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                raise ChromiumError(f"{method}: no answer in {timeout} s")
            msg = json.loads(self._ws.recv(timeout=left))
            if msg.get("id") == self._id:
                if "error" in msg:
                    raise ChromiumError(f"{method}: {msg['error'].get('message')}")
                return msg.get("result", {})
            self.events.append(msg)

    def send(self, method: str, **params: Any) -> None:
        """Send a command without waiting for its answer (read later by :meth:`call`'s loop)."""
        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (promises awaited)."""
        res = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in res:
            raise ChromiumError(f"page error: {res['exceptionDetails'].get('text')}")
        return res.get("result", {}).get("value")

    def wait_for(self, expression: str, timeout: float = 20.0) -> Any:
        """Poll a JavaScript expression until it is truthy; its value."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.05)
        raise ChromiumError(f"timed out waiting for {expression}")

    def open(self, url: str, width: int = 412, height: int = 860) -> None:
        """Emulate a phone (touch, portrait size) and load ``url``."""
        self.call("Page.enable")
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=True)
        self.call("Emulation.setTouchEmulationEnabled", enabled=True, maxTouchPoints=5)
        self.call("Page.navigate", url=url)
        self.wait_for("document.readyState === 'complete'")

    def centre(self, element_id: str) -> tuple[float, float]:
        """The centre of a page element, in CSS pixels."""
        r = self.evaluate(
            f"(() => {{ const r = document.getElementById({element_id!r}).getBoundingClientRect();"
            " return [r.x + r.width / 2, r.y + r.height / 2]; })()"
        )
        return float(r[0]), float(r[1])

    def click(self, element_id: str) -> None:
        """A mouse click (a user gesture) on an element."""
        x, y = self.centre(element_id)
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)

    def touch(self, element_id: str, kind: str) -> None:
        """``touchStart`` or ``touchEnd`` on an element."""
        x, y = self.centre(element_id)
        points = [] if kind == "touchEnd" else [{"x": x, "y": y, "id": 1}]
        self.call("Input.dispatchTouchEvent", type=kind, touchPoints=points)

    def enable_sensors(self) -> None:
        """Replace the phone's motion sensors by overrides (before the page listens to them).

        Chromium backs ``deviceorientation`` with its relative-orientation sensor and
        ``devicemotion`` with the accelerometer, linear-acceleration and gyroscope; each is
        given a reading of a phone held still, flat, pointing north.
        """
        for kind in SENSORS:
            self.call("Emulation.setSensorOverrideEnabled", enabled=True, type=kind)
        self.orientation(0.0, 0.0, 0.0)
        self.motion((0.0, 0.0, 0.0), (0.0, 0.0, 9.81), (0.0, 0.0, 0.0))

    def orientation(self, alpha: float, beta: float, gamma: float, wait: bool = True) -> None:
        """Set the orientation sensor to DeviceOrientation angles (degrees, W3C Z-X'-Y'')."""
        from input.web.protocol import orientation_to_quat

        w, x, y, z = (float(v) for v in orientation_to_quat(alpha, beta, gamma))
        params: dict[str, Any] = {
            "type": "relative-orientation",
            "reading": {"quaternion": {"x": x, "y": y, "z": z, "w": w}},
        }
        if wait:
            self.call("Emulation.setSensorOverrideReadings", **params)
        else:
            self.send("Emulation.setSensorOverrideReadings", **params)

    def motion(
        self,
        linear: tuple[float, float, float],
        gravity: tuple[float, float, float],
        rotation: tuple[float, float, float],
    ) -> None:
        """Set the motion sensors: linear acceleration and gravity (m/s²), rotation rate (rad/s)."""
        total = tuple(a + g for a, g in zip(linear, gravity, strict=True))
        for kind, v in (("linear-acceleration", linear), ("accelerometer", total), ("gyroscope", rotation)):
            self.call(
                "Emulation.setSensorOverrideReadings", type=kind, reading={"xyz": {"x": v[0], "y": v[1], "z": v[2]}}
            )

    def screenshot(self, path: Path) -> Path:
        """A PNG of the page."""
        data = self.call("Page.captureScreenshot", format="png")["data"]
        path.write_bytes(base64.b64decode(data))
        return path

    def close(self) -> None:
        """Quit the browser and remove its profile."""
        self._stack.close()
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        shutil.rmtree(self._dir, ignore_errors=True)

    def __enter__(self) -> Chromium:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
