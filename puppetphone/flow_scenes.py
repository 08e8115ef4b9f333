"""The flow tool wired to the scenes games offer: the snowman field and tasbada's crystal forest
(``author flow [snowman|tasbada|FILE]``).

The tool lives in :mod:`authoring.flow_tool` and never imports a game (imports go downwards);
the launcher, which sees both, hands it the scenes by name here.
"""

from __future__ import annotations

from authoring.flow_tool import flow_tool
from games.snowman.bent_scenery import flow_scene
from games.tasbada.flow_scene import flow_scene as tasbada_flow_scene

__all__ = ["SCENES", "TOOL"]

#: The scenes ``author flow`` opens by name.
SCENES = {"snowman": flow_scene, "tasbada": tasbada_flow_scene}
TOOL = flow_tool(SCENES)
