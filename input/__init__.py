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

from input.factory import add_source_arguments, make_hub
from input.hub import InputHub
from input.motionstick import StickConfig, StickState, motionstick_system, spawn_stick
from input.plugin import input_plugin, install_input
from input.recording import Recorder, Recording, RecordingError, RecordingHeader, read_recording
from input.replay import HashCheck, ReplaySource, replay_hub, verify
from input.sample import InputFrame, PoseSample, SourceStatus
from input.source import PoseSource

__all__ = [
    "PoseSample", "InputFrame", "SourceStatus", "PoseSource", "InputHub",
    "StickConfig", "StickState", "motionstick_system", "spawn_stick",
    "install_input", "input_plugin",
    "Recorder", "RecordingHeader", "Recording", "RecordingError", "read_recording",
    "ReplaySource", "HashCheck", "replay_hub", "verify",
    "add_source_arguments", "make_hub",
]
