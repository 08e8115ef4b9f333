"""The clip library: authored clips by role, checked, conformed, embedded in set-ups, measured once.

- :mod:`~engine.cliplib.roles` — what a clip must be to fill a role, and conforming it;
- :mod:`~engine.cliplib.plant` — pinning a retargeted cycle's planted feet;
- :mod:`~engine.cliplib.library` — the folder and its manifest (``puppetphone clips``);
- :mod:`~engine.cliplib.embed` — the clips in a game's set-up (recordings replay with them);
- :mod:`~engine.cliplib.cache` — the lookup table's measurement cached by content hash;
- :mod:`~engine.cliplib.authored` — the puppet's locomotion set built from them.
"""
