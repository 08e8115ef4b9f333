"""Tasbada: the multi-reality quest, from a photo of your room to a virtual world (thesis §6.4).

Modules, each one job:

- :mod:`~games.tasbada.game` — the launcher's ``GAME`` and the plugin that assembles it;
- :mod:`~games.tasbada.quest` — the hashed quest state and the stage names;
- :mod:`~games.tasbada.flow` — the rules system: pointer, stages, narration clock, menu, save trigger;
- :mod:`~games.tasbada.marking` — box/lasso gestures, the floor line, buttons;
- :mod:`~games.tasbada.objects` — creatures, crystals, the gate and their milestones;
- :mod:`~games.tasbada.narrator` — the narrator's script and squash-and-stretch motion;
- :mod:`~games.tasbada.view` — the game camera and the image ↔ floor mapping;
- :mod:`~games.tasbada.images` — photo crop, clothes colour by k-means;
- :mod:`~games.tasbada.matting` — a prop's GrabCut matte (feathered) and its inpainted hole;
- :mod:`~games.tasbada.shadow` — a prop's real shadow found, lit out, and re-cast as it moves;
- :mod:`~games.tasbada.propmesh` — the prop as a deformable photo surface (squash, stretch, lean, mouth);
- :mod:`~games.tasbada.pose`, :mod:`~games.tasbada.posing`, :mod:`~games.tasbada.picker` — the player's
  pose from the selfie (MediaPipe's bundled model), lifted by IK, held then eased into the idle; the
  pose picker when there is none;
- :mod:`~games.tasbada.compositor`, :mod:`~games.tasbada.reality`, :mod:`~games.tasbada.draw` — the view;
- :mod:`~games.tasbada.webcam` — the optional live camera;
- :mod:`~games.tasbada.save` — atomic progress files;
- ``python -m tools.regen demos`` (:mod:`tools.tasbada_demo`) rebuilds ``demo.rec``.
"""

from games.tasbada.quest import MIXED, PROPS_ALIVE, REAL, STAGES, VIRTUAL, Mark, Quest

__all__ = ["STAGES", "REAL", "PROPS_ALIVE", "MIXED", "VIRTUAL", "Quest", "Mark"]
