"""eyeview's web server: Python's http.server on 127.0.0.1, one thread per request. It serves the page
(view_page.html), the render's state as Server-Sent Events (/events), its latest image as a tone-mapped PNG
(/frame.png, by the package's PNG writer) and takes the page's requests (/edit, /aov, /pause, /save) to the render
thread (viewer.Viewer.ask). It never touches the stage itself. A client that goes away (a closed tab) only ends its
own request; bad input is a 400 with one line."""
import http.server
import json
import os
import pathlib
import tempfile
import threading
import urllib.parse

from ._hdeye import write_png_preview

PAGE = pathlib.Path(__file__).with_name("view_page.html")
EVENT_HEARTBEAT = 2.0  # seconds between events when nothing changes (so a dead server is noticed)
MAX_BODY = 4096  # bytes of a request body


class _Handler(http.server.BaseHTTPRequestHandler):
    server_version = "eyeview"

    def log_message(self, *args):  # the terminal keeps eyeview's own lines only
        pass

    def do_GET(self):
        url = urllib.parse.urlsplit(self.path)
        query = dict(urllib.parse.parse_qsl(url.query))
        if url.path in ("/", "/index.html"):
            self._send(200, PAGE.read_bytes(), "text/html; charset=utf-8")
        elif url.path == "/state":
            self._send_json(200, self._state())
        elif url.path == "/events":
            self._events()
        elif url.path == "/frame.png":
            self._frame(query.get("exposure", "0"))
        else:
            self._send_json(404, {"ok": False, "message": f"no page {url.path}"})

    def do_POST(self):
        url = urllib.parse.urlsplit(self.path)
        kinds = {"/edit": "edit", "/aov": "aov", "/pause": "pause", "/save": "save"}
        if url.path not in kinds:
            self._send_json(404, {"ok": False, "message": f"no request {url.path}"})
            return
        try:
            body = self._body()
            payload = {"edit": lambda: (str(body["name"]), body["value"]), "aov": lambda: str(body["aov"]),
                       "pause": lambda: bool(body["paused"]), "save": lambda: self.server.save_path}[kinds[url.path]]()
        except (ValueError, KeyError, TypeError) as e:
            self._send_json(400, {"ok": False, "message": f"bad request: {e}"})
            return
        ok, message = self.server.viewer.ask(kinds[url.path], payload)
        self._send_json(200 if ok else 400, {"ok": ok, "message": message})

    def _body(self):
        length = int(self.headers.get("Content-Length") or 0)
        if not 0 < length <= MAX_BODY:
            raise ValueError(f"a JSON body of 1 to {MAX_BODY} bytes is needed")
        body = json.loads(self.rfile.read(length).decode("utf-8"))
        if not isinstance(body, dict):
            raise ValueError("the body must be a JSON object")
        return body

    def _state(self):
        viewer = self.server.viewer
        return {**viewer.snapshot.state(), **viewer.editor.describe(), "aovs": list(self.server.aovs),
                "save_path": self.server.save_path}

    def _events(self):
        self.send_response(200)
        self.send_header("Content-Type", "text/event-stream")
        self.send_header("Cache-Control", "no-cache")
        self.end_headers()
        version = -1
        try:
            while not self.server.closing.is_set():
                state = self.server.viewer.snapshot.wait(version, EVENT_HEARTBEAT)
                version = state["version"]
                self.wfile.write(f"data: {json.dumps(self._state())}\n\n".encode())
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError, TimeoutError):
            pass  # the tab was closed: only this request ends

    def _frame(self, exposure):
        try:
            stops = float(exposure)
            if not -20 <= stops <= 20:
                raise ValueError
        except ValueError:
            self._send_json(400, {"ok": False, "message": f"exposure '{exposure}' is not a number in [-20, 20]"})
            return
        pixels = self.server.viewer.snapshot.pixels
        if pixels is None:
            self._send_json(404, {"ok": False, "message": "no image yet"})
            return
        self._send(200, encode_png(pixels, stops), "image/png")

    def _send_json(self, status, value):
        self._send(status, json.dumps(value).encode(), "application/json")

    def _send(self, status, body, content_type):
        try:
            self.send_response(status)
            self.send_header("Content-Type", content_type)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            pass


def encode_png(rgb, exposure):
    """PNG bytes of linear RGB (h, w, 3) after `exposure` stops, as eyerecord --png writes it (clamped sRGB)."""
    import numpy as np

    with tempfile.TemporaryDirectory(prefix="eyeview-") as folder:
        path = os.path.join(folder, "frame.png")
        write_png_preview(path, np.ascontiguousarray(rgb, dtype=np.float32), exposure)
        return pathlib.Path(path).read_bytes()


class ViewServer(http.server.ThreadingHTTPServer):
    """The server of one Viewer; serve_forever runs on a thread of its own (start())."""

    daemon_threads = True

    def __init__(self, viewer, port, save_path, aovs):
        super().__init__(("127.0.0.1", port), _Handler)
        self.viewer, self.save_path, self.aovs = viewer, save_path, aovs
        self.closing = threading.Event()

    @property
    def url(self):
        return f"http://127.0.0.1:{self.server_address[1]}/"

    def start(self):
        thread = threading.Thread(target=self.serve_forever, name="eyeview-server", daemon=True)
        thread.start()
        return thread

    def close(self):
        self.closing.set()
        self.shutdown()
        self.server_close()


__all__ = ["ViewServer", "encode_png"]
