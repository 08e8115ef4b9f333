"""``puppetphone author record``: a take at real tempo, recorded and replayed through the CLI."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from engine.clipfile import load_clip
from input.recording import read_recording


def puppetphone(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    return subprocess.run(
        [sys.executable, "-m", "puppetphone", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600
    )


@pytest.fixture(scope="module")
def take(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, subprocess.CompletedProcess[str]]:
    """One scripted take of the arm (``author record``, 600 steps), recorded once for the tests below that
    need a real ``author-record`` recording: its own replay, a tempo edit of it and forged copies of it
    (each of those used to record a take of its own, ~2 s of CPU each for the same command).
    Its folder holds ``take.rec`` and the saved ``loop.ppclip``; the tests write their edits elsewhere."""
    folder = tmp_path_factory.mktemp("take")
    done = puppetphone(
        "author",
        "record",
        "--script",
        "loops",
        "--headless",
        "--frames",
        "600",
        "--countdown",
        "1",
        "--seconds",
        "6",
        "--record",
        "take.rec",
        "-o",
        "loop.ppclip",
        cwd=folder,
    )
    return folder, done


def test_a_recorded_take_replays_to_the_same_loop_without_writing(
    take: tuple[Path, subprocess.CompletedProcess[str]],
) -> None:
    folder, done = take
    assert done.returncode == 0, done.stderr
    loop = load_clip(folder / "loop.ppclip")
    assert loop.loop and loop.num_frames > 10  # the scripted performer's take became a clean loop
    header = read_recording(folder / "take.rec").header
    assert header.game == "author-record" and header.setup["item"] == "r_upper_arm"
    (folder / "loop.ppclip").unlink()
    done = puppetphone("replay", "take.rec", "--verify", "--headless", cwd=folder)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "replayed 600 frames, all 600 state hashes match" in done.stdout
    assert not (folder / "loop.ppclip").exists()  # a replay saves nothing


def test_a_take_of_another_tempo_is_a_divergence(
    take: tuple[Path, subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    """The recording pins the take: replayed with a shorter countdown the state differs, and says where."""
    folder, done = take
    assert done.returncode == 0, done.stderr
    from input.recording import Recorder

    rec = read_recording(folder / "take.rec")
    rec.header.setup["countdown"] = 0.5
    with Recorder(tmp_path / "edited.rec", rec.header) as out:
        for frame, digest, parts in zip(rec.frames, rec.hashes, rec.parts, strict=True):
            out.write(frame, digest, parts)
    done = puppetphone("replay", "edited.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 1
    assert "differs at frame 0 in scene " in done.stdout  # the countdown timer is the first thing that differs


def test_a_recording_with_a_malformed_tool_operation_is_refused_in_one_line(
    take: tuple[Path, subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    from input.recording import Recorder
    from input.sample import TOOL, InputFrame

    folder, done = take
    assert done.returncode == 0, done.stderr
    rec = read_recording(folder / "take.rec")
    with Recorder(tmp_path / "forged.rec", rec.header) as out:
        for i, (frame, digest, parts) in enumerate(zip(rec.frames, rec.hashes, rec.parts, strict=True)):
            if i == 5:
                frame = InputFrame(frame=frame.frame, events=((TOOL, '["zoom", "far"'),))
            out.write(frame, digest, parts)
    done = puppetphone("replay", "forged.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip() == 'error: forged.rec: step 5: malformed tool operation \'["zoom", "far"\''
    with Recorder(tmp_path / "short.rec", rec.header) as out:  # well-formed, but missing its arguments
        for i, (frame, digest, parts) in enumerate(zip(rec.frames, rec.hashes, rec.parts, strict=True)):
            out.write(InputFrame(frame=frame.frame, events=((TOOL, '["press"]'),)) if i == 3 else frame, digest, parts)
    done = puppetphone("replay", "short.rec", "--headless", cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.strip().endswith(
        "is not one a session knows (press, move, release, orbit, zoom, key, size with their arguments)"
    )


def test_a_scripted_pose_take_of_a_foot_records_and_replays(tmp_path: Path) -> None:
    """``--drive pose`` on a foot: position (by IK) and rotation in one take; the recording replays it."""
    done = puppetphone(
        "author",
        "record",
        "--item",
        "l_foot",
        "--drive",
        "pose",
        "--script",
        "loops",
        "--headless",
        "--frames",
        "600",
        "--countdown",
        "1",
        "--seconds",
        "6",
        "--record",
        "take.rec",
        "-o",
        "loop.ppclip",
        cwd=tmp_path,
    )
    assert done.returncode == 0, done.stderr
    loop = load_clip(tmp_path / "loop.ppclip")
    import numpy as np

    from engine import quat
    from engine.fk import forward_kinematics

    foot = loop.skeleton.index("l_foot")
    wpos, _ = forward_kinematics(loop.skeleton, loop.root, loop.rotations)
    assert 0.2 < float(np.ptp(wpos[:, foot, 0])) < 0.4  # the scripted figure is 0.3 m wide
    turned = quat.angle_between(loop.rotations[:, foot], quat.identity(1)[0])
    assert turned.max() > 0.2  # and the foot's own rotation was performed with it
    done = puppetphone("replay", "take.rec", "--verify", "--headless", cwd=tmp_path)
    assert done.returncode == 0 and "all 600 state hashes match" in done.stdout, done.stdout + done.stderr


def test_a_six_dof_device_drives_position_and_rotation_together() -> None:
    """A tracked phone's samples through the hub: position relative to the take's start, rotation likewise."""
    import numpy as np

    from authoring.record_scene import RecordScene
    from authoring.record_tool import RecordTool
    from authoring.session import Session
    from engine import quat
    from engine.humanoid import humanoid_skeleton
    from input.hub import InputHub
    from input.sample import PoseSample
    from input.source import PoseSource

    class Phone(PoseSource):
        threaded = False

        def __init__(self) -> None:
            super().__init__("phone")
            self._status.connected = True

    phone = Phone()
    scene = RecordScene(humanoid_skeleton(), "r_hand", "pose", countdown=0.1, take_seconds=30.0)
    activity = Session(RecordTool(scene), InputHub([phone]))
    rest = scene.rest_value()
    start = np.array([0.3, 1.2, 0.4])  # where the phone happens to be: only its motion counts
    scene.key("r")
    steps = int(7.0 / activity.dt) + 12
    for k in range(steps):
        t = max(k - 12, 0) * activity.dt
        p = 2 * np.pi * t
        position = start + np.array([0.0, 0.06 * (1 - np.cos(p)), 0.1 * np.sin(p)])  # a hanging arm swings
        orientation = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.float64(0.5 * np.sin(p)))
        phone.push(PoseSample(time=k * activity.dt, source="phone", orientation=orientation, position=position))
        activity.step()
    scene.key("space")
    assert scene.result is not None, scene.message
    clip = scene.accept()
    assert clip is not None and clip.duration == np.float64(clip.duration) and abs(clip.duration - 1.0) < 0.03
    from engine.fk import forward_kinematics

    hand = clip.skeleton.index("r_hand")
    wpos, _ = forward_kinematics(clip.skeleton, clip.root, clip.rotations)
    assert abs(float(np.ptp(wpos[:, hand, 2])) - 0.2) < 0.02 and abs(float(np.ptp(wpos[:, hand, 1])) - 0.12) < 0.015
    assert np.allclose(wpos[:, hand].min(axis=0)[[0, 1]], rest[:2], atol=0.02)  # from where the hand was
    twist = quat.angle_between(clip.rotations[:, hand], rest[3:])
    assert abs(float(twist.max()) - 0.5) < 0.05
