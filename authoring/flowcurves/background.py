"""A scene's SEcurves found in another process, so the editor's window shows the scene and the progress at once.

The SEcurves of a scene take seconds to find (one contour search per group, §3.4); found
before the window's first frame they left it black for that long. The editor now opens on
the rest scene and finds them here, showing ``SEcurves k/n`` until they are in. A process,
not a thread: the window's rendering holds Python's lock for most of each frame (software
GL does all its work inside those calls), which starved a thread to a standstill. The
search is seeded and the same code runs there, so the SEcurves are the ones a headless run
finds in-process, bit for bit. The session is built from them (quick) in the editor.
"""

from __future__ import annotations

import multiprocessing as mp
import queue as queue_mod
from collections.abc import Callable
from typing import Any

from authoring.flowcurves.scene import FlowScene
from authoring.flowcurves.securves import SECurve
from authoring.flowcurves.session import FlowSession

__all__ = ["BackgroundSession"]


def _find_securves(scene: FlowScene, out: Any) -> None:
    """The child's work: the SEcurves of ``scene``, with progress, sent back through ``out``."""
    from authoring.flowcurves.deform import SceneDeformer
    from authoring.flowcurves.securves import compute_securves

    try:
        found = compute_securves(
            scene, SceneDeformer(scene).rasters, lambda k, n, name: out.put(("progress", k, n, name))
        )
        out.put(("done", found))
    except Exception as exc:  # noqa: BLE001 - sent to the editor, which says it
        out.put(("error", f"{type(exc).__name__}: {exc}"))


class BackgroundSession:
    """The SEcurves of ``scene`` searched in a child process; ``finish(securves)`` makes the session once they are in."""

    def __init__(self, scene: FlowScene, finish: Callable[[list[SECurve]], FlowSession]) -> None:
        self.scene = scene
        self.text = "finding the scene's SEcurves…"
        self._finish = finish
        self._session: FlowSession | None = None
        self._error: str | None = None
        ctx = mp.get_context("spawn")  # a fresh interpreter: nothing of the window's GL state is inherited
        self._queue = ctx.Queue()
        self._process = ctx.Process(target=_find_securves, args=(scene, self._queue), name="securves", daemon=True)
        self._process.start()

    def _poll(self) -> None:
        while self._session is None and self._error is None:
            try:
                msg = self._queue.get_nowait()
            except queue_mod.Empty:
                if not self._process.is_alive() and self._queue.empty():
                    self._error = f"the SEcurve search stopped (exit code {self._process.exitcode})"
                return
            if msg[0] == "progress":
                self.text = f"finding SEcurves: {msg[1] + 1}/{msg[2]} ({msg[3]})…"
            elif msg[0] == "done":
                self._session = self._finish(msg[1])
                self._process.join(5)
            else:
                self._error = str(msg[1])

    def done(self) -> bool:
        """Whether the search has ended (with a session or an error); reads its progress."""
        self._poll()
        return self._session is not None or self._error is not None

    def result(self) -> FlowSession:
        """The session; ``RuntimeError`` with the search's error if it failed."""
        if self._error is not None:
            raise RuntimeError(self._error)
        assert self._session is not None
        return self._session

    def stop(self) -> None:
        """End the search (the editor closed before it was done)."""
        if self._process.is_alive():
            self._process.terminate()
            self._process.join(5)
