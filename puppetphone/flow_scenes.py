"""The flow tool wired to the scenes games offer: the snowman field (``author flow [snowman|FILE]``).

The tool lives in :mod:`authoring.flow_tool` and never imports a game (imports go downwards);
the launcher, which sees both, hands it the scenes by name here.
"""

from __future__ import annotations

from authoring.flow_tool import flow_tool
from games.snowman.bent_scenery import flow_scene

__all__ = ["TOOL"]

TOOL = flow_tool({"snowman": flow_scene})
