"""The real-world pictures of a session: the backdrop photo (or webcam), the selfie, the cut-outs.

:class:`Reality` is a world resource that is *not* simulation state: it is built once
at setup from files (deterministic), may be fed by a webcam in a live session, and is
only read by the view. It caches the expensive work — cutting out the marked objects
and filling their holes — per set of marks, so that happens once per stage change,
not per frame.
"""

from __future__ import annotations

import threading
from pathlib import Path

import numpy as np
from PIL import Image

from games.tasbada.compositor import Layers, Sprites, build_sprites, compose
from games.tasbada.images import PHOTO_SIZE, clothes_color, fit_photo, load_image
from games.tasbada.quest import MIXED, REAL, Mark, Quest
from games.tasbada.webcam import Webcam

__all__ = ["Reality", "SHIPPED_PHOTO", "SHIPPED_SELFIE"]

SHIPPED_PHOTO = Path(__file__).with_name("assets") / "room.jpg"
SHIPPED_SELFIE = Path(__file__).with_name("assets") / "selfie.jpg"


class Reality:
    """Photo, selfie, avatar colour, optional webcam, and the cut-out cache.

    Args:
        photo: the backdrop picture file (16:9 crop is taken from its centre).
        selfie: the selfie picture file.
        webcam: a started webcam, or ``None`` to use the files only.
        message: what to tell the person about the camera.
    """

    SIM_STATE = False

    def __init__(
        self,
        photo: str | Path = SHIPPED_PHOTO,
        selfie: str | Path = SHIPPED_SELFIE,
        webcam: Webcam | None = None,
        message: str = "",
        light_deg: float | None = None,
    ) -> None:
        self.photo_path = str(photo)
        self.photo = fit_photo(load_image(photo))
        self.selfie_img = load_image(selfie)
        self.color = clothes_color(self.selfie_img)
        self.webcam = webcam
        self.message = message
        self.light_deg = light_deg
        self.pose_note = ""
        """What the pose estimator said about the selfie (shown in the status lines)."""
        """Where the props' shadows fall (degrees; ``None``: as found in the photo)."""
        self.frozen = webcam is None
        self.selfie_taken = webcam is None
        self._sprites: tuple[bytes, Sprites] | None = None
        self._building: tuple[bytes, threading.Thread, list[Sprites | BaseException]] | None = None
        self._photo_pil = Image.fromarray(self.photo)
        self._selfie_pil = Image.fromarray(self.selfie_img)

    def _live(self, q: Quest) -> None:
        """Webcam: keep the backdrop live until marking starts; take the selfie when the count-down ends."""
        if self.webcam is None:
            return
        if not self.frozen:
            frame = self.webcam.frame()
            if frame is not None:
                self.photo = fit_photo(frame, PHOTO_SIZE)
                self._photo_pil = Image.fromarray(self.photo)
            if q.down or q.marks or q.stage != REAL:
                self.frozen = True
        if q.script == "selfie" and not self.selfie_taken:
            frame = self.webcam.frame()
            if frame is not None:
                self._selfie_pil = Image.fromarray(frame)
                if q.stage == MIXED or q.line >= 3:
                    self.selfie_img = frame
                    self.color = clothes_color(frame)
                    self.selfie_taken = True

    def sprites(self, q: Quest, wait: bool = False) -> Sprites | None:
        """The living props for ``q``'s marks, or ``None`` while they are still being built.

        Matting, shadows and inpainting take seconds, so they run on a worker thread
        (OpenCV releases the GIL) and the window keeps drawing the plain photo meanwhile;
        ``wait`` blocks until they are ready (screenshots, tests).
        """
        if not q.marks:
            return None
        key = b"".join(m.kind.encode() + np.ascontiguousarray(m.points).tobytes() for m in q.marks)
        key += np.float64(q.ground_v).tobytes()
        if self._sprites is not None and self._sprites[0] == key:
            return self._sprites[1]
        if self._building is None or self._building[0] != key:
            job: list[Sprites | BaseException] = []
            args = (self.photo.copy(), [Mark(m.kind, m.points.copy()) for m in q.marks], q.ground_v, self.light_deg)

            def run() -> None:
                try:
                    job.append(build_sprites(*args))
                except BaseException as exc:  # handed to the drawing thread below
                    job.append(exc)

            worker = threading.Thread(target=run, name="tasbada-props", daemon=True)
            worker.start()
            self._building = (key, worker, job)
        _, worker, job = self._building
        if wait:
            worker.join()
        if not job:
            return None
        self._building = None
        if isinstance(job[0], BaseException):
            raise job[0]
        self._sprites = (key, job[0])
        return job[0]

    def frame(self, q: Quest, now: float, gaze: float, wait: bool = False) -> Layers:
        """This frame's backdrop, living props and interface (``wait``: the props even if they must be built now)."""
        self._live(q)
        sprites = None if q.stage == REAL else self.sprites(q, wait)
        return compose(self._photo_pil, sprites, q, now, self._selfie_pil, self.color, gaze)

    def close(self) -> None:
        """Wait for the props being built (a process ending under a running OpenCV call aborts); free the webcam."""
        if self._building is not None:
            self._building[1].join()
            self._building = None
        if self.webcam is not None:
            self.webcam.close()
            self.webcam = None
