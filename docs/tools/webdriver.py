"""A few WebDriver calls over plain HTTP, for docs/tools/explore_tutorial.py."""
import base64
import json
import socket
import subprocess
import time
import urllib.request


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Browser:
    """Headless Chromium through chromedriver, as tests/it/browser.rs starts it."""

    def __init__(self, profile, width=1366, height=800):
        port = free_port()
        self.driver = subprocess.Popen(["chromedriver", f"--port={port}"],
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.base = f"http://127.0.0.1:{port}"
        for _ in range(200):
            try:
                socket.create_connection(("127.0.0.1", port)).close()
                break
            except OSError:
                time.sleep(0.05)
        args = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--disable-quic", "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync",
                f"--window-size={width},{height}", f"--user-data-dir={profile}"]
        caps = {"capabilities": {"alwaysMatch": {"goog:chromeOptions": {"args": args}}}}
        self.session = self.call("POST", "/session", caps)["sessionId"]

    def call(self, method, path, body=None):
        if path != "/session":
            path = f"/session/{self.session}{path}"
        data = json.dumps(body).encode() if body is not None else None
        request = urllib.request.Request(self.base + path, data=data, method=method,
                                         headers={"content-type": "application/json"})
        with urllib.request.urlopen(request, timeout=120) as response:
            return json.load(response)["value"]

    def go(self, url):
        self.call("POST", "/url", {"url": url})

    def js(self, script, *args):
        return self.call("POST", "/execute/sync", {"script": script, "args": list(args)})

    def until(self, condition, seconds=60):
        started = time.time()
        while not self.js(f"return Boolean({condition});"):
            if time.time() - started > seconds:
                raise TimeoutError(condition + ": " + str(self.js(
                    "return document.getElementById('alert').textContent")))
            time.sleep(0.05)

    def settled(self):
        self.until("!moving && document.getElementById('view').dataset.stage === 'final'"
                   " && Number(document.getElementById('view').dataset.serial) === page.serial")

    def image_point(self, px, py):
        """The window point over pixel (px, py) of the frame shown."""
        return tuple(self.js("""
            const r = document.getElementById('view').getBoundingClientRect();
            const [w, h] = viewSize(), k = Math.min(r.width / w, r.height / h);
            return [Math.round(r.left + (r.width - w * k) / 2 + (arguments[0] + 0.5) * k),
                    Math.round(r.top + (r.height - h * k) / 2 + (arguments[1] + 0.5) * k)];""",
                                 px, py))

    def pointer(self, steps):
        actions = [{"type": "pointerMove", "duration": 40, "x": x, "y": y, "origin": "viewport"}
                   if kind == "move" else {"type": "pointer" + kind.capitalize(), "button": 0}
                   for kind, x, y in steps]
        self.call("POST", "/actions", {"actions": [{"type": "pointer", "id": "mouse",
                  "parameters": {"pointerType": "mouse"}, "actions": actions}]})

    def drag(self, px, py, dx, dy):
        x, y = self.image_point(px, py)
        moves = [("move", x + dx * i // 4, y + dy * i // 4) for i in range(1, 5)]
        self.pointer([("move", x, y), ("down", 0, 0)] + moves + [("up", 0, 0)])

    def click(self, px, py):
        x, y = self.image_point(px, py)
        self.pointer([("move", x, y), ("down", 0, 0), ("up", 0, 0)])

    def wheel(self, px, py, delta_y):
        x, y = self.image_point(px, py)
        self.call("POST", "/actions", {"actions": [{"type": "wheel", "id": "wheel", "actions": [
            {"type": "scroll", "x": x, "y": y, "deltaX": 0, "deltaY": delta_y,
             "origin": "viewport"}]}]})

    def keys(self, element_id, text):
        element = self.call("POST", "/element", {"using": "css selector", "value": "#" + element_id})
        key = next(iter(element.values()))
        self.call("POST", f"/element/{key}/value", {"text": text})

    def press(self, element_id):
        element = self.call("POST", "/element", {"using": "css selector", "value": "#" + element_id})
        key = next(iter(element.values()))
        self.call("POST", f"/element/{key}/click", {})

    def screenshot(self, path):
        with open(path, "wb") as f:
            f.write(base64.b64decode(self.call("GET", "/screenshot")))

    def close(self):
        try:
            self.call("DELETE", "")
        finally:
            self.driver.kill()
