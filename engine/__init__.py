"""The engine: ECS world, fixed-step app, skeletons, poses, clips, FK, rendering.

Imports nothing from ``input``, ``authoring``, ``games`` or ``puppetphone`` (the layering
test in ``tests/test_layering.py`` keeps it so).
"""

__version__ = "0.1.0"
