"""Open a local HTML file in headless Chromium and report what a reader would meet.

Talks the Chrome DevTools Protocol over ``--remote-debugging-pipe`` (file descriptors 3
and 4, NUL-separated JSON), so that it needs nothing but the standard library and the
browser: no driver, no websocket package.  :func:`load_page` returns the console errors,
uncaught exceptions, failed or network loads, a per-figure measurement of every inline
SVG (its rendered size and element count) and a full-page screenshot (PNG bytes).
"""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

#: flags of a quiet, offline headless Chromium (as the machines' notes advise for root)
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-extensions", "--disable-dev-shm-usage", "--hide-scrollbars",
         "--window-size=1200,900"]

FIGURES_JS = """JSON.stringify(Array.from(document.querySelectorAll('figure')).map(f => {
  const s = f.querySelector('svg');
  if (!s) return {svg: false};
  const b = s.getBoundingClientRect();
  return {svg: true, width: b.width, height: b.height,
          elements: s.querySelectorAll('*').length,
          text: s.querySelectorAll('text').length};
}))"""


def find_chromium() -> str | None:
    """The Chromium executable, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


class _Pipe:
    def __init__(self, proc, write_fd: int, read_fd: int):
        self.proc, self.write_fd, self.read_fd = proc, write_fd, read_fd
        self.buffer = b""
        self.next_id = 0
        self.events: list[dict] = []

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> int:
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.write_fd, json.dumps(msg).encode() + b"\0")
        return self.next_id

    def _read(self, deadline: float) -> dict:
        while b"\0" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("Chromium did not answer in time")
            ready, _, _ = select.select([self.read_fd], [], [], left)
            if ready:
                chunk = os.read(self.read_fd, 1 << 20)
                if not chunk:
                    raise RuntimeError("Chromium closed the DevTools pipe")
                self.buffer += chunk
        raw, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(raw)

    def call(self, method: str, params: dict | None = None, session: str | None = None,
             timeout: float = 60.0) -> dict:
        want = self.send(method, params, session)
        deadline = time.monotonic() + timeout
        while True:
            msg = self._read(deadline)
            if msg.get("id") == want:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self.events.append(msg)

    def wait_event(self, method: str, timeout: float = 60.0) -> dict:
        deadline = time.monotonic() + timeout
        for i, ev in enumerate(self.events):
            if ev.get("method") == method:
                return self.events.pop(i)
        while True:
            msg = self._read(deadline)
            if msg.get("method") == method:
                return msg
            self.events.append(msg)


def load_page(path: Path, chromium: str, timeout: float = 90.0) -> dict:
    """Load ``path`` and return ``{"console_errors", "exceptions", "failed_loads",
    "network_requests", "figures", "screenshot"}``."""
    to_browser_r, to_browser_w = os.pipe()
    from_browser_r, from_browser_w = os.pipe()

    def child_fds():  # the browser reads commands on fd 3 and writes answers on fd 4
        r, w = os.dup(to_browser_r), os.dup(from_browser_w)  # out of the way of 3 and 4
        os.dup2(r, 3)
        os.dup2(w, 4)
        os.set_inheritable(3, True)
        os.set_inheritable(4, True)

    profile = tempfile.mkdtemp(prefix="torquesplit-chromium-")
    log = open(os.path.join(profile, "stderr.txt"), "wb")  # noqa: SIM115 - closed below
    proc = subprocess.Popen([chromium, *FLAGS, "--remote-debugging-pipe",
                             f"--user-data-dir={profile}", "about:blank"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=log, preexec_fn=child_fds, close_fds=False)
    os.close(to_browser_r)
    os.close(from_browser_w)
    pipe = _Pipe(proc, to_browser_w, from_browser_r)
    try:
        target = pipe.call("Target.createTarget", {"url": "about:blank"}, timeout=timeout)
        session = pipe.call("Target.attachToTarget",
                            {"targetId": target["targetId"], "flatten": True})["sessionId"]
        for domain in ("Runtime", "Log", "Page", "Network"):
            pipe.call(f"{domain}.enable", session=session)
        pipe.call("Page.navigate", {"url": Path(path).resolve().as_uri()}, session=session)
        pipe.wait_event("Page.loadEventFired", timeout=timeout)
        time.sleep(0.3)  # late console messages
        figures = json.loads(pipe.call("Runtime.evaluate", {"expression": FIGURES_JS,
                                                            "returnByValue": True},
                                       session=session)["result"]["value"])
        shot = pipe.call("Page.captureScreenshot", {"format": "png",
                                                    "captureBeyondViewport": True},
                         session=session, timeout=timeout)
        try:
            pipe.call("Browser.close", timeout=10)
        except (RuntimeError, TimeoutError):
            pass
    finally:
        os.close(to_browser_w)
        try:
            proc.wait(timeout=15)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
        os.close(from_browser_r)
        log.close()
        stderr = Path(profile, "stderr.txt").read_text(errors="replace")
        shutil.rmtree(profile, ignore_errors=True)
    events = pipe.events
    console = [e["params"] for e in events if e.get("method") == "Runtime.consoleAPICalled"
               and e["params"].get("type") in ("error", "assert")]
    logs = [e["params"]["entry"] for e in events if e.get("method") == "Log.entryAdded"
            and e["params"]["entry"].get("level") == "error"]
    exceptions = [e["params"] for e in events if e.get("method") == "Runtime.exceptionThrown"]
    failed = [e["params"] for e in events if e.get("method") == "Network.loadingFailed"]
    requests = [e["params"]["request"]["url"] for e in events
                if e.get("method") == "Network.requestWillBeSent"]
    return {"stderr": stderr, "console_errors": console + logs, "exceptions": exceptions, "failed_loads": failed,
            "network_requests": [u for u in requests if not u.startswith(("file:", "data:",
                                                                          "about:"))],
            "figures": figures, "screenshot": base64.b64decode(shot["data"])}
