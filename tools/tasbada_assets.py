"""The photos shipped with Tasbada, drawn procedurally (no downloads, no camera needed).

``room.jpg`` stands in for the camera in the demo and when no webcam is present: a
living-room corner (back wall, window, picture, wooden floor, rug) with three things
worth marking — an orange clay pot, a potted plant and a floor lamp — drawn with a fixed
seed, so running ``python -m tools.regen assets`` again rebuilds the very same file.
:func:`draw_selfie` draws a person in a sweater for the clothes-colour test; the shipped
``selfie.jpg`` is a real photo (a pose estimator needs one; origin and licence in
``assets/README.md``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFilter

import games.tasbada

__all__ = ["ASSETS", "ROOM_SIZE", "draw_room", "draw_selfie", "main"]

ASSETS = Path(games.tasbada.__file__).with_name("assets")
ROOM_SIZE = (960, 540)


def _noise(rng: np.random.Generator, shape: tuple[int, int], sigma: float) -> NDArray[np.float64]:
    return rng.normal(0.0, sigma, shape + (1,))


def _grad(h: int, w: int, top: tuple[float, ...], bottom: tuple[float, ...]) -> NDArray[np.float64]:
    t = np.linspace(0.0, 1.0, h)[:, None, None]
    return (1 - t) * np.array(top) + t * np.array(bottom) + np.zeros((h, w, 3))


def _shadow(img: Image.Image, box: tuple[int, int, int, int], strength: int = 90, blur: int = 9) -> Image.Image:
    """Darken an ellipse under an object (its contact shadow in the photo)."""
    mask = Image.new("L", img.size, 0)
    ImageDraw.Draw(mask).ellipse(box, fill=strength)
    mask = mask.filter(ImageFilter.GaussianBlur(blur))
    dark = Image.new("RGB", img.size, (20, 14, 10))
    return Image.composite(dark, img, mask)


def draw_room(seed: int = 7) -> Image.Image:
    """The living-room photo, ``ROOM_SIZE``; the floor meets the wall at row 300."""
    rng = np.random.default_rng(seed)
    w, h = ROOM_SIZE
    wall_line = 300
    img = np.zeros((h, w, 3))
    img[:wall_line] = _grad(wall_line, w, (222, 214, 196), (196, 186, 166))[:, :, :]
    # Light falls from the window on the left: a broad horizontal gradient on the wall.
    img[:wall_line] *= np.linspace(1.08, 0.86, w)[None, :, None]
    floor = _grad(h - wall_line, w, (128, 88, 58), (160, 112, 72))
    # Planks converge towards a vanishing point above the centre.
    ys, xs = np.mgrid[wall_line:h, 0:w].astype(np.float64)
    depth = (ys - wall_line + 40.0) / (h - wall_line + 40.0)
    u = (xs - w * 0.5) / depth
    plank = np.floor(u / 70.0)
    tone = (np.sin(plank * 12.9898) * 43758.5453) % 1.0
    floor *= (0.9 + 0.16 * tone)[:, :, None]
    floor *= np.where((np.abs(u / 70.0 - np.round(u / 70.0)) < 0.018 / depth * 2.0), 0.72, 1.0)[:, :, None]
    img[wall_line:] = floor
    img += _noise(rng, (h, w), 3.0)
    room = Image.fromarray(np.clip(img, 0, 255).astype(np.uint8), "RGB")
    d = ImageDraw.Draw(room)
    d.rectangle((0, wall_line - 10, w, wall_line + 2), fill=(238, 232, 220))  # skirting board
    # Window with a sky and a frame.
    d.rectangle((70, 40, 300, 230), fill=(246, 244, 236))
    sky = Image.fromarray(_grad(174, 214, (120, 170, 225), (200, 222, 240)).astype(np.uint8), "RGB")
    room.paste(sky, (78, 48))
    d.rectangle((183, 48, 189, 222), fill=(246, 244, 236))
    d.rectangle((78, 132, 292, 138), fill=(246, 244, 236))
    # A picture on the wall.
    d.rectangle((560, 70, 720, 180), fill=(70, 52, 40))
    d.rectangle((570, 80, 710, 170), fill=(92, 140, 120))
    d.polygon([(570, 170), (620, 110), (660, 150), (690, 120), (710, 170)], fill=(60, 96, 84))
    d.ellipse((670, 88, 692, 110), fill=(240, 214, 120))
    # Rug.
    d.polygon([(270, 400), (700, 400), (800, 520), (170, 520)], fill=(150, 52, 60))
    d.polygon([(290, 410), (684, 410), (774, 508), (196, 508)], outline=(222, 190, 120), width=4)
    room = _shadow(room, (140, 360, 300, 395))  # plant
    room = _shadow(room, (470, 425, 620, 460))  # pot
    room = _shadow(room, (760, 330, 880, 352), 80)  # lamp
    d = ImageDraw.Draw(room)
    # Potted plant (left).
    d.polygon([(170, 300), (270, 300), (255, 380), (185, 380)], fill=(180, 180, 186))
    for k in range(9):
        ang = -2.6 + k * 0.28
        cx, cy = 220 + 95 * np.cos(ang), 300 + 120 * np.sin(ang)
        d.ellipse((cx - 34, cy - 15, cx + 34, cy + 15), fill=(46 + 9 * k, 118 + 4 * k, 52))
        d.line((220, 300, cx, cy), fill=(40, 96, 40), width=3)
    # Orange clay pot (the narrator in the demo): body, rim, handle, a highlight.
    d.ellipse((478, 318, 612, 446), fill=(216, 110, 44))
    d.rectangle((500, 300, 590, 330), fill=(200, 98, 40))
    d.ellipse((496, 292, 594, 312), fill=(170, 80, 32))
    d.arc((588, 330, 640, 400), -80, 80, fill=(200, 98, 40), width=10)
    d.ellipse((500, 336, 526, 372), fill=(242, 170, 110))
    # Floor lamp (right).
    d.ellipse((780, 328, 860, 346), fill=(50, 50, 56))
    d.rectangle((816, 120, 824, 338), fill=(60, 60, 66))
    d.polygon([(770, 130), (870, 130), (846, 60), (794, 60)], fill=(246, 230, 180))
    room = room.filter(ImageFilter.GaussianBlur(0.8))
    arr = np.asarray(room).astype(np.float64) + _noise(rng, (h, w), 2.0)
    return Image.fromarray(np.clip(arr, 0, 255).astype(np.uint8), "RGB")


def draw_selfie(seed: int = 11, sweater: tuple[int, int, int] = (34, 138, 146)) -> Image.Image:
    """A head-and-shoulders photo of a person in a teal sweater (640x480)."""
    rng = np.random.default_rng(seed)
    w, h = 640, 480
    img = Image.fromarray(_grad(h, w, (205, 210, 214), (170, 176, 182)).astype(np.uint8), "RGB")
    d = ImageDraw.Draw(img)
    shade = tuple(int(c * 0.78) for c in sweater)
    d.ellipse((150, 300, 490, 640), fill=sweater)  # shoulders and torso
    d.polygon([(300, 310), (340, 310), (320, 350)], fill=shade)  # collar
    d.rectangle((292, 240, 348, 320), fill=(224, 176, 146))  # neck
    d.ellipse((250, 90, 390, 270), fill=(232, 186, 154))  # face
    d.chord((240, 70, 400, 210), 180, 360, fill=(70, 46, 30))  # hair
    for ex in (292, 348):
        d.ellipse((ex - 9, 168, ex + 9, 182), fill=(250, 250, 250))
        d.ellipse((ex - 4, 170, ex + 4, 180), fill=(40, 30, 20))
    d.arc((290, 200, 350, 236), 20, 160, fill=(150, 70, 70), width=4)
    img = img.filter(ImageFilter.GaussianBlur(1.0))
    arr = np.asarray(img).astype(np.float64) + _noise(rng, (h, w), 4.0)
    return Image.fromarray(np.clip(arr, 0, 255).astype(np.uint8), "RGB")


def main() -> None:
    """Write ``assets/room.jpg`` (the selfie is a photo of a person: see ``assets/README.md``)."""
    ASSETS.mkdir(exist_ok=True)
    draw_room().save(ASSETS / "room.jpg", quality=92)


if __name__ == "__main__":
    main()
