"""The view's HTTP + WebSocket server, on its own thread with its own asyncio loop.

aiohttp serves both the static page and the WebSockets from one well-kept asyncio library (no framing or
HTTP written here), and its per-message size limit and heartbeats bound what one page can cost.

The simulation thread never waits on this one: it hands over actions through a bounded deque it drains
between steps, and frames through :meth:`ViewServer.publish`, which keeps only the newest frame per page
(a slow page loses frames, it never queues them).
"""

from __future__ import annotations

import asyncio
import contextlib
import errno
import json
import logging
import threading
import time
from collections import deque
from pathlib import Path

from aiohttp import WSMsgType, web
from aiohttp.typedefs import Handler

from stage_sim.view.messages import Action, BadMessage, MessageReader, Strikes
from stage_sim.view.options import LOOPBACK_HOSTS, ViewSettings
from stage_sim.view.scene import Scene

PAGE_DIR = Path(__file__).parent / "page"
PORT_TRIES = 50
"""From the asked-for port up, how many ports are tried before giving up."""
MAX_FRAME_BYTES = 64 * 1024
"""Larger WebSocket messages close the connection (aiohttp's limit; page messages are a few hundred bytes)."""
MAX_PENDING_ACTIONS = 1024
WARNING_THROTTLE_S = 5.0

log = logging.getLogger(__name__)


class _Page:
    """One connected page: the newest frame not yet sent (older ones are dropped) and a wake-up."""

    def __init__(self, socket: web.WebSocketResponse) -> None:
        self.socket = socket
        self.pending: str | None = None
        self.wake = asyncio.Event()
        self.strikes = Strikes()

    def offer(self, frame: str) -> None:
        self.pending = frame
        self.wake.set()


class ViewServer:
    """Serves the page, the scene, the map and the frame stream of one simulation."""

    def __init__(self, scene: Scene, reader: MessageReader, settings: ViewSettings) -> None:
        self.scene = scene
        self.reader = reader
        self.settings = settings
        self.actions: deque[Action] = deque(maxlen=MAX_PENDING_ACTIONS)
        self.url = ""
        self.port = 0
        self.rejected = 0
        """Page messages dropped as malformed since the start (read by tests and benchmarks)."""
        self.accepted = 0
        """Valid page messages queued for the simulation since the start."""
        self._scene_text = json.dumps(scene.description, separators=(",", ":"))
        self._pages: set[_Page] = set()
        self._latest: str | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self._stop: asyncio.Event | None = None
        self._thread: threading.Thread | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._last_warning: dict[str, float] = {}

    @property
    def viewers(self) -> int:
        """Pages connected now."""
        return len(self._pages)

    # -- the simulation thread's side ----------------------------------------------------------------------

    def start(self) -> str:
        """Bind (the asked-for port, else the next free one) and serve on a daemon thread; returns the URL."""
        self._thread = threading.Thread(target=self._run, name="stage_sim-view", daemon=True)
        self._thread.start()
        self._ready.wait()
        if self._error is not None:
            raise self._error
        return self.url

    def publish(self, frame: str) -> None:
        """Hand a frame to every page (thread-safe, never blocks)."""
        loop = self._loop
        if loop is not None and not loop.is_closed():
            with contextlib.suppress(RuntimeError):  # the loop closed meanwhile
                loop.call_soon_threadsafe(self._offer, frame)

    def close(self) -> None:
        """Close every page and stop serving."""
        if self._loop is not None and self._stop is not None and not self._loop.is_closed():
            with contextlib.suppress(RuntimeError):
                self._loop.call_soon_threadsafe(self._stop.set)
        if self._thread is not None:
            self._thread.join(timeout=5.0)

    # -- the server thread ---------------------------------------------------------------------------------

    def _run(self) -> None:
        loop = self._loop = asyncio.new_event_loop()
        try:
            loop.run_until_complete(self._serve())
        except BaseException as error:  # reported to start(), which re-raises it on the caller's thread
            self._error = error
        finally:
            self._ready.set()
            loop.close()

    async def _serve(self) -> None:
        self._stop = asyncio.Event()
        app = web.Application(middlewares=[self._check_host] if self.settings.loopback else [])
        app.router.add_get("/", self._index)
        app.router.add_get("/map.png", self._map)
        app.router.add_get("/ws", self._socket)
        app.router.add_static("/static/", PAGE_DIR)
        runner = web.AppRunner(app, handle_signals=False, access_log=None)
        await runner.setup()
        try:
            await self._bind(runner)
            self._ready.set()
            await self._stop.wait()
            for page in list(self._pages):
                await page.socket.close()
        finally:
            await runner.cleanup()

    async def _bind(self, runner: web.AppRunner) -> None:
        first = self.settings.port
        ports = [0] if first == 0 else range(first, min(first + PORT_TRIES, 65536))
        for port in ports:
            site = web.TCPSite(runner, self.settings.host, port)
            try:
                await site.start()
            except OSError as error:
                if error.errno == errno.EADDRINUSE:
                    continue
                raise
            self.port = runner.addresses[-1][1]
            host = "127.0.0.1" if self.settings.host in ("0.0.0.0", "::", "") else self.settings.host
            self.url = f"http://{'[' + host + ']' if ':' in host else host}:{self.port}/"
            return
        raise OSError(errno.EADDRINUSE, f"ports {first}-{first + PORT_TRIES - 1} on {self.settings.host} are all taken")

    @web.middleware
    async def _check_host(self, request: web.Request, handler: Handler) -> web.StreamResponse:
        """Bound to loopback, answer only requests for a loopback name (no DNS rebinding from a web page)."""
        if request.url.host not in LOOPBACK_HOSTS:
            raise web.HTTPForbidden(text="this view answers on 127.0.0.1 and localhost only")
        return await handler(request)

    async def _index(self, request: web.Request) -> web.FileResponse:
        return web.FileResponse(PAGE_DIR / "index.html")

    async def _map(self, request: web.Request) -> web.Response:
        return web.Response(body=self.scene.map_png, content_type="image/png")

    async def _socket(self, request: web.Request) -> web.WebSocketResponse:
        origin = request.headers.get("Origin")
        if origin is not None and origin != f"{request.scheme}://{request.host}":
            self._warn("origin", f"view: refused a WebSocket from a page at {origin[:80]} (not this view's page)")
            raise web.HTTPForbidden(text="cross-origin WebSocket refused")
        socket = web.WebSocketResponse(max_msg_size=MAX_FRAME_BYTES, heartbeat=10.0)
        await socket.prepare(request)
        page = _Page(socket)
        sender: asyncio.Task | None = None
        try:
            await socket.send_str(self._scene_text)  # the scene first, then frames
            if self._latest is not None:
                page.offer(self._latest)
            self._pages.add(page)
            sender = asyncio.create_task(self._send(page))
            async for message in socket:
                if message.type in (WSMsgType.TEXT, WSMsgType.BINARY) and not self._receive(page, message.data):
                    await socket.close(code=1008, message=b"too many malformed messages")
                    break
        except ConnectionError:  # the page went away mid-message: nothing to clean up beyond the finally
            pass
        finally:
            self._pages.discard(page)
            if sender is not None:
                sender.cancel()
        return socket

    async def _send(self, page: _Page) -> None:
        """Send each page the newest frame whenever it can take one."""
        with contextlib.suppress(ConnectionError, asyncio.CancelledError):
            while not page.socket.closed:
                await page.wake.wait()
                page.wake.clear()
                frame, page.pending = page.pending, None
                if frame is not None:
                    await page.socket.send_str(frame)

    def _offer(self, frame: str) -> None:
        self._latest = frame
        for page in self._pages:
            page.offer(frame)

    def _receive(self, page: _Page, data: str | bytes) -> bool:
        """Queue a valid action; drop anything else. False when the page has sent too much garbage."""
        try:
            action = self.reader.read(data)
        except BadMessage as error:
            self.rejected += 1
            self._warn("bad", f"view: dropped a page message: {error}")
            return not page.strikes.add()
        if self.settings.readonly:
            self._warn("readonly", "view: read-only (--view-readonly); ignoring a page's control message")
            return True
        self.actions.append(action)
        self.accepted += 1
        return True

    def _warn(self, kind: str, text: str) -> None:
        """One warning of each kind per :data:`WARNING_THROTTLE_S`."""
        now = time.monotonic()
        if now - self._last_warning.get(kind, -WARNING_THROTTLE_S) >= WARNING_THROTTLE_S:
            self._last_warning[kind] = now
            log.warning(text)
