"""A minimal W3C WebDriver client over chromedriver's HTTP API (the standard library only): enough to open a page in
headless Chromium (Debian's chromium + chromium-driver), click, switch into an iframe, run a script and take a
screenshot."""
from __future__ import annotations

import base64
import json
import shutil
import socket
import subprocess
import time
import urllib.request
from pathlib import Path

CHROMIUM, CHROMEDRIVER = shutil.which("chromium"), shutil.which("chromedriver")
# no background networking: this machine's closed network refuses it (and it slows every start)
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync", "--window-size=1400,1000",
        "--enable-unsafe-swiftshader", "--use-angle=swiftshader"]  # WebGL (the room viewer) on the CPU
ELEMENT = "element-6066-11e4-a52e-4f735466cecf"  # the W3C key of an element reference


class Browser:
    def __init__(self, profile: Path):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        self.driver = subprocess.Popen([CHROMEDRIVER, f"--port={port}"], stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL)
        self.base = f"http://127.0.0.1:{port}"
        for _ in range(100):
            try:
                self._call("GET", "/status")
                break
            except OSError:
                time.sleep(0.1)
        caps = {"browserName": "chrome", "goog:chromeOptions": {"binary": CHROMIUM,
                                                                 "args": [*ARGS, f"--user-data-dir={profile}"]}}
        self.session = "/session/" + self._call("POST", "/session", {"capabilities": {"alwaysMatch": caps}})["sessionId"]

    def _call(self, method: str, path: str, body: dict | None = None):
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(self.base + path, data=data, method=method,
                                     headers={"Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=60) as r:
            return json.loads(r.read())["value"]

    def do(self, method: str, path: str, body: dict | None = None):
        return self._call(method, self.session + path, body)

    def open(self, url: str) -> None:
        self.do("POST", "/url", {"url": url})

    def elements(self, css: str) -> list[str]:
        return [next(iter(e.values())) for e in self.do("POST", "/elements", {"using": "css selector", "value": css})]

    def find(self, xpath: str) -> str:
        """The first element matching ``xpath`` (an error when none does)."""
        return next(iter(self.do("POST", "/element", {"using": "xpath", "value": xpath}).values()))

    def frame(self, element: str | None) -> None:
        """Switch into an iframe (one of :meth:`elements`), or back to the top-level page with None."""
        self.do("POST", "/frame", {"id": None if element is None else {ELEMENT: element}})

    def click_text(self, text: str) -> None:
        self.click(self.find(f"//*[normalize-space(text())='{text}']"))

    def click(self, element: str) -> None:
        self.do("POST", f"/element/{element}/click", {})
        time.sleep(0.3)  # the report's React app re-renders

    @staticmethod
    def wait_for(probe, timeout: float = 10.0, step: float = 0.2):
        """``probe()``'s first truthy value, polled every ``step`` s, or its last value after ``timeout`` s."""
        end = time.monotonic() + timeout
        while True:
            value = probe()
            if value or time.monotonic() > end:
                return value
            time.sleep(step)

    def run(self, script: str):
        return self.do("POST", "/execute/sync", {"script": script, "args": []})

    def screenshot(self, path: Path) -> Path:
        path.write_bytes(base64.b64decode(self.do("GET", "/screenshot")))
        return path

    def close(self) -> None:
        try:
            self.do("DELETE", "")
        finally:
            self.driver.terminate()
            self.driver.wait(timeout=30)
