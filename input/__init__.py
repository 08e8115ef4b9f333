"""Input: pose sources, the MotionStick, recording and bit-exact replay.

Devices (mouse, phone over OSC, HID, serial IMU) run their I/O on their own
threads and fill queues (:mod:`input.source`); once per fixed step the
:class:`InputHub` drains them into one :class:`InputFrame`, the only
non-deterministic input of the simulation. The MotionStick system turns it into
the engine's ``Stick`` component. A :class:`Recorder` writes every frame with the
step's state hash; a :class:`ReplaySource` feeds them back and :func:`verify`
checks every hash. ``install_input(app, hub)`` wires it all into an app.

Submodules with device specifics are imported lazily by :func:`make_hub`:
``input.osc``, ``input.hid``, ``input.serial_source``, ``input.mouse``.
"""

from importlib import import_module
from typing import Any

# Each public name → its submodule, imported on first use (PEP 562): parsing ``puppetphone --help``
# reads ``input.factory`` without loading the hub, numpy or the device servers.
_WHERE = {
    "add_source_arguments": "factory",
    "make_hub": "factory",
    "InputHub": "hub",
    "StickConfig": "motionstick",
    "StickState": "motionstick",
    "motionstick_system": "motionstick",
    "spawn_stick": "motionstick",
    "input_plugin": "plugin",
    "install_input": "plugin",
    "Recorder": "recording",
    "Recording": "recording",
    "RecordingError": "recording",
    "RecordingHeader": "recording",
    "read_recording": "recording",
    "HashCheck": "replay",
    "ReplaySource": "replay",
    "replay_hub": "replay",
    "verify": "replay",
    "InputFrame": "sample",
    "PoseSample": "sample",
    "SourceStatus": "sample",
    "PoseSource": "source",
}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(f"input.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'input' has no attribute {name!r}")


__all__ = [
    "HashCheck",
    "InputFrame",
    "InputHub",
    "PoseSample",
    "PoseSource",
    "Recorder",
    "Recording",
    "RecordingError",
    "RecordingHeader",
    "ReplaySource",
    "SourceStatus",
    "StickConfig",
    "StickState",
    "add_source_arguments",
    "input_plugin",
    "install_input",
    "make_hub",
    "motionstick_system",
    "read_recording",
    "replay_hub",
    "spawn_stick",
    "verify",
]
