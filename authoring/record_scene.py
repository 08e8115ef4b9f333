"""The recording scene (``puppetphone author record``): act a loop out, get a clean cycle (SCA 2017 §3–4).

Workflow, as in the paper: pick a character, an item (a joint) and what to drive; a
countdown; perform several loops while the layers already authored play back in
sync; the loop is extracted at once (:func:`~authoring.cycles.extract_cycle`) and
previewed — the performance in orange, the extracted cycle in green (Fig. 9) — then
accepted (it stacks onto the motion cycle) or retried. The stacked cycle is a looping
:class:`~engine.clip.Clip`, saved as ``.ppclip``.

What can be driven (paper §3: any item's translation and rotation):

- a joint's **rotation** (any joint: its local rotation);
- an item's **translation**: the root's position, or a hand or foot (any item MoCurves can
  position, :func:`~authoring.mocurves.curves.item_chain`) as an IK target: each frame the
  two-bone chain above it bends so the item is where it was performed (character space);
- its **pose**, both at once from a 6-DoF device (a phone's tracked position and
  orientation, a SpaceMouse): one take, one extracted loop of 7 numbers, so position and
  rotation stay in step; the position is reached by the IK, the rotation is the item's own.

- a joint's **scale** (uniform, the clip's scale channel: a head that swells on every step).

An item whose position only follows its parents (the spine, the chest) cannot take a
translation: it is refused with the reason.

Layers are synchronised by phase: the scene knows where the playing cycle was when
each performed cycle started, so a new layer is placed at that phase (the performer
acted it against what they saw) and time-scaled to the cycle's duration.

Like the edit scene, this class does not know pygame: the command loop feeds it one
performance value per step (:func:`mouse_point`, :func:`drag_rotation` or a device's
orientation), key names, and asks it to draw into a :class:`RenderScene`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from authoring.cycles import CycleError, CycleResult, Item, Trajectory, extract_cycle
from authoring.joint_pick import joint_at
from authoring.mocurves.curves import item_chain
from engine import quat
from engine.camera import OrbitCamera
from engine.character.load import Character
from engine.character.view import character_instance
from engine.clip import Clip
from engine.fk import forward_kinematics
from engine.ik import two_bone_ik
from engine.pose import Pose
from engine.render.extract import puppet_capsules
from engine.render.scene import RenderScene
from engine.root_curve import RootCurve
from engine.skeleton import Skeleton

__all__ = ["DRIVES", "PERFORM", "READY_HINT", "RecordScene", "drag_rotation", "mouse_point"]

from engine.arrays import F64 as F

DRIVES = ("translation", "rotation", "pose", "scale")
_WIDTH = {"translation": 3, "rotation": 4, "pose": 7, "scale": 1}  # numbers in one performed value
PERFORMANCE = (0.95, 0.55, 0.1)  # orange: what was performed
CYCLE = (0.1, 0.75, 0.25)  # green: the extracted cycle (paper Fig. 9)
#: How a take is performed (the first take of a newcomer who did not hold the button did not move).
PERFORM = "hold the left button and drag (or move the device)"
READY_HINT = f"R records: a count-down, then {PERFORM}; click a joint of the figure to drive it"


def mouse_point(camera: OrbitCamera, px: float, py: float, size: tuple[int, int], through: F) -> F:
    """Where the cursor's ray meets the plane through ``through`` facing the camera."""
    origin, direction = camera.ray(px, py, size[0], size[1])
    normal = np.asarray(camera.forward, dtype=np.float64)
    denom = float(np.dot(direction, normal))
    if abs(denom) < 1e-9:
        return np.asarray(through, dtype=np.float64).copy()
    s = float(np.dot(np.asarray(through) - origin, normal)) / denom
    return np.asarray(origin + s * np.asarray(direction), dtype=np.float64)


def drag_rotation(dx: float, dy: float, height: int, gain: float = np.pi) -> F:
    """A local rotation from a mouse drag (pixels from the press point): down pitches, right yaws."""
    return quat.exp(np.array([dy / height * gain, dx / height * gain, 0.0]))


@dataclass
class _Take:
    times: list[float]
    values: list[F]
    base_time: float  # playback time of the cycle when the take started


class RecordScene:
    """Record, extract, preview, accept or retry; layers stack into one looping clip.

    Args:
        skeleton: the character.
        item: the joint to drive.
        drive: ``"rotation"``, ``"translation"`` (the root, or a hand or foot by IK) or ``"pose"``
            (translation and rotation together, from a 6-DoF device); ``"scale"`` (any joint, uniform).
        base: a looping clip already authored (its layers play back while performing).
        countdown: seconds before the take starts.
        take_seconds: the take stops by itself after this long (or on :meth:`stop`).
        rng: seeded generator for the extractor's probe points.
        root_curve: the base clip's root curve (from its ``.ppclip``), kept while no layer moves the root.
        character: a skinned character drawn in the puppet's pose instead of the mannequin.
    """

    def __init__(
        self,
        skeleton: Skeleton,
        item: str,
        drive: str = "rotation",
        base: Clip | None = None,
        countdown: float = 3.0,
        take_seconds: float = 8.0,
        rng: np.random.Generator | None = None,
        root_curve: RootCurve | None = None,
        character: Character | None = None,
    ) -> None:
        if drive not in DRIVES:
            raise ValueError(f"drive must be one of {DRIVES}, got {drive!r}")
        joint, self.chain = _drivable(skeleton, item, drive)
        if base is not None and (base.skeleton.names != skeleton.names or not base.loop):
            raise ValueError("the base clip must be a looping clip of the same skeleton")
        self.skeleton = skeleton
        self.character = character  # drawn instead of the mannequin (``author record --character``)
        self.joint = joint
        self.drive = drive
        self.clip = base
        self.countdown = float(countdown)
        self.take_seconds = float(take_seconds)
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.camera = OrbitCamera(target=np.array([0.0, 1.0, 0.0]), distance=2.8, pitch=0.25, yaw=-0.6)
        self.phase = "ready"
        self.time = 0.0  # playback time of the cycle
        self.timer = 0.0
        self.message = READY_HINT
        self.result: CycleResult | None = None
        self.candidate: Clip | None = None
        self.root_curve = root_curve if base is not None else None
        """The extractor's fitted curve of the root position, when a root layer set it (saved with the clip)."""
        self._candidate_curve: RootCurve | None = None
        self._take: _Take | None = None
        self._value: F | None = None
        self._performed: F = np.zeros((0, 4))

    @property
    def take(self) -> _Take | None:
        """The take being recorded (``None`` outside one)."""
        return self._take

    @property
    def value(self) -> F | None:
        """The performer's value fed this step (``None``: at rest)."""
        return self._value

    # -- the performance ---------------------------------------------------------------
    def rest_value(self) -> F:
        """The driven channel at the current playback time (what the take starts from).

        A translation is the item's position in character space (the root's: the root
        track); a pose is that position followed by the item's local rotation.
        """
        root, rot = self._pose(self.time, None)
        if self.drive == "scale":
            return np.array([self._scales(self.time, None)[self.joint]])
        position = root if self.joint == 0 else forward_kinematics(self.skeleton, root, rot)[0][self.joint]
        if self.drive == "rotation":
            return rot[self.joint].copy()
        if self.drive == "translation":
            return np.array(position)
        return np.concatenate([position, rot[self.joint]])

    def item_position(self) -> F:
        """World position of the driven joint now (where the mouse plane goes through)."""
        root, rot = self._pose(self.time, self.candidate)
        wpos, _ = forward_kinematics(self.skeleton, root, rot, scales=self._scales(self.time, self.candidate))
        return wpos[self.joint]

    def feed(self, value: F | None) -> None:
        """The performed value for this step (a point, a unit quaternion or a scale), or ``None`` if unchanged."""
        if value is None:
            return
        v = np.asarray(value, dtype=np.float64).reshape(-1)
        want = _WIDTH[self.drive]
        if (
            v.shape != (want,)
            or not np.isfinite(v).all()
            or (want > 3 and np.linalg.norm(v[-4:]) < 1e-9)
            or (self.drive == "scale" and v[0] <= 0)
        ):
            raise ValueError(
                f"a {self.drive} performance value is {want} finite numbers"
                f"{' (positive)' * (self.drive == 'scale')}, got {v.tolist()}"
            )
        if want > 3:
            v = np.concatenate([v[:-4], quat.normalize(v[-4:])])
        self._value = v

    def choose(self, px: float, py: float, size: tuple[int, int]) -> bool:
        """A click on the figure while ready: drive the joint under the cursor; whether one was there."""
        if self.phase != "ready":
            return False
        root, rot = self._pose(self.time, None)
        wpos, wrot = forward_kinematics(self.skeleton, root, rot, scales=self._scales(self.time, None))
        ends = np.array(
            [
                wpos[kids[0]]
                if (kids := self.skeleton.children(j))
                else wpos[j] + quat.rotate(wrot[j], self.skeleton.tips[j])
                for j in range(len(wpos))
            ]
        )
        picked = joint_at(self.camera, wpos, ends, px, py, size)
        if picked is None:
            return False
        name = self.skeleton.names[picked]
        try:
            self.joint, self.chain = _drivable(self.skeleton, name, self.drive)
        except ValueError as exc:
            self.message = str(exc)
            return True
        self.message = f"driving {name} by {self.drive}. {READY_HINT}"
        return True

    # -- the workflow ------------------------------------------------------------------
    def start(self) -> None:
        """Start the countdown (from ready or preview)."""
        self.phase, self.timer, self.result, self.candidate = "countdown", self.countdown, None, None
        self.message = ""

    def stop(self) -> None:
        """End the take now and extract the loop."""
        if self.phase == "recording":
            self._extract()

    def accept(self) -> Clip | None:
        """Stack the previewed layer onto the cycle; returns the new clip."""
        if self.phase != "preview" or self.candidate is None:
            return None
        self.clip, self.candidate, self.phase = self.candidate, None, "ready"
        self.root_curve = self._candidate_curve
        self.message = f"layer accepted: {self.skeleton.names[self.joint]} {self.drive}; R records another"
        return self.clip

    def retry(self) -> None:
        """Drop the previewed take and count down again."""
        self.start()

    def key(self, name: str) -> None:
        """Keyboard: R record, Space stop the take, Enter accept, Backspace retry."""
        if name == "r" and self.phase in ("ready", "preview"):
            self.start()
        elif name == "space":
            self.stop()
        elif name in ("return", "enter"):
            self.accept()
        elif name == "backspace" and self.phase == "preview":
            self.retry()

    def step(self, dt: float) -> None:
        """Advance playback, the countdown and the take by one fixed step."""
        self.time += dt
        if self.phase == "countdown":
            self.timer -= dt
            if self.timer <= 0.0:
                self.phase = "recording"
                self._take = _Take([], [], self.time)
                self.timer = 0.0
        elif self.phase == "recording" and self._take is not None:
            self.timer += dt
            self._take.times.append(self.timer)
            self._take.values.append((self._value if self._value is not None else self.rest_value()).copy())
            if self.timer >= self.take_seconds:
                self._extract()

    def _extract(self) -> None:
        take = self._take
        self._take = None
        self.phase = "preview"
        assert take is not None
        values = np.asarray(take.values)
        if len(values) and np.ptp(values, axis=0).max() < 1e-9:
            self.result, self.candidate = None, None
            self.message = f"the performance did not move: {PERFORM} while it records — R to retry"
            return
        item = self.skeleton.names[self.joint]
        items = {
            "translation": (Item(f"{item}.translation", "position", 0, 3),),
            "rotation": (Item(f"{item}.rotation", "rotation", 0, 4),),
            "scale": (Item(f"{item}.scale", "scale", 0, 1),),
            "pose": (Item(f"{item}.translation", "position", 0, 3), Item(f"{item}.rotation", "rotation", 3, 7)),
        }
        try:
            traj = Trajectory(np.asarray(take.times), values, items[self.drive])
            self.result = extract_cycle(traj, self.rng)
        except (CycleError, ValueError) as exc:
            self.result, self.candidate = None, None
            self.message = f"no clean loop: {exc} — Backspace/R to retry"
            return
        self.candidate = self._stack(self.result, take)
        self._candidate_curve = self._root_curve(self.result, self.candidate)
        self._performed = values
        self.message = (
            f"loop of {self.result.period:.2f} s from {self.result.cycles} cycles "
            f"(spread {self.result.spread:.0%}) — Enter accepts, Backspace retries"
        )

    # -- layering ----------------------------------------------------------------------
    def _stack(self, result: CycleResult, take: _Take) -> Clip:
        """The cycle with this layer: the first layer sets the duration; later ones are phase-aligned to it."""
        loop = result.closed()
        if self.clip is None:
            frames = len(result.loop)
            fps = frames / result.period
            base_rot = np.broadcast_to(
                quat.identity(self.skeleton.num_joints), (frames, self.skeleton.num_joints, 4)
            ).copy()
            base_root = np.broadcast_to(self.skeleton.offsets[0], (frames, 3)).copy()
            base_scales = None
            shift = 0.0
        else:
            frames, fps = self.clip.num_frames, self.clip.fps
            base_root, base_rot = np.array(self.clip.root), np.array(self.clip.rotations)
            base_scales = None if self.clip.scales is None else np.array(self.clip.scales)
            # Where the playing cycle was when each performed cycle began: the layer starts there.
            starts = result.aligned.knots_time[:, 0] + take.base_time
            ang = 2 * np.pi * np.mod(starts / self.clip.duration, 1.0)
            shift = float(np.mod(np.arctan2(np.sin(ang).mean(), np.cos(ang).mean()) / (2 * np.pi), 1.0))
        phase = np.mod(np.arange(frames) / frames - shift, 1.0)
        values = _sample_loop(loop, phase, self.drive)
        if self.drive == "scale":
            base_scales = np.ones((frames, self.skeleton.num_joints)) if base_scales is None else base_scales
            base_scales[:, self.joint] = np.maximum(values[:, 0], 1e-3)
        else:
            base_root, base_rot = self._driven(base_root, base_rot, values)
        name = self.clip.name if self.clip is not None else "performed_cycle"
        return Clip(name, self.skeleton, fps, base_root, base_rot, loop=True, scales=base_scales)

    def _root_curve(self, result: CycleResult, candidate: Clip) -> RootCurve | None:
        """The root curve that goes with ``candidate``: the extracted one when this is the first, root-driving layer.

        A later root layer is phase-shifted and resampled onto the cycle, which no control
        points follow exactly: MoCurves then fit their own. Other layers leave the root as it was.
        """
        if self.joint != 0 or self.drive not in ("translation", "pose"):
            return self.root_curve
        if self.clip is not None:
            return None
        fitted = result.curves.get(f"{self.skeleton.names[0]}.translation")
        if fitted is None or fitted.segments > candidate.num_frames:
            return None
        curve = RootCurve(fitted.closed_control(), np.zeros(3))
        misfit = float(np.max(np.abs(curve.positions(candidate.num_frames) - candidate.root)))
        return curve if misfit <= 2.0 * fitted.max_error + 1e-9 else None

    def _driven(self, root: F, rot: F, values: F) -> tuple[F, F]:
        """Poses ``root [N,3]``, ``rot [N,J,4]`` with the driven channel set to ``values [N,d]``.

        A position goes to the root track, or to the item through two-bone IK on its chain
        (a pose's rotation is then set as the item's local rotation, exactly as performed).
        """
        root, rot = np.array(root), np.array(rot)
        if self.drive in ("translation", "pose"):
            target = values[:, :3]
            if self.joint == 0:
                root = np.array(target)
            else:
                assert self.chain is not None
                # A translation keeps the item's world orientation from before (as a MoCurves drag does).
                keep = forward_kinematics(self.skeleton, root, rot)[1][:, self.joint]
                pose = Pose(root, rot)
                two_bone_ik(self.skeleton, pose, self.chain, target, end_rotation=keep)
                rot = np.asarray(pose.rotations)
        if self.drive in ("rotation", "pose"):
            rot[:, self.joint] = values[:, -4:]
        return root, rot

    def _pose(self, t: float, clip: Clip | None) -> tuple[F, F]:
        c = clip if clip is not None else self.clip
        if c is None:
            return self.skeleton.offsets[0].copy(), quat.identity(self.skeleton.num_joints)
        pose = c.sample(t)
        return np.asarray(pose.root), np.asarray(pose.rotations)

    def _scales(self, t: float, clip: Clip | None) -> F:
        """``[J]`` joint scales of the playing (or candidate) cycle at ``t``: its scale channel, else ones."""
        c = clip if clip is not None else self.clip
        if c is None or c.scales is None:
            return np.ones(self.skeleton.num_joints)
        return np.asarray(c.sample(t).scales)

    # -- drawing -----------------------------------------------------------------------
    def _joint_path(self, values: F, rotation: bool) -> F:
        """World path of the driven joint's child (or the root) when the values drive it, over the base pose.

        A translation or pose draws the performed positions themselves (the item's path).
        """
        if not rotation:
            return np.asarray(values, dtype=np.float64)[:, :3]
        n = len(values)
        root, rot = self._pose(self.time, None)
        roots = np.broadcast_to(root, (n, 3)).copy()
        rots = np.broadcast_to(rot, (n, *rot.shape)).copy()
        scales = np.broadcast_to(self._scales(self.time, None), (n, self.skeleton.num_joints)).copy()
        if self.drive == "scale":
            scales[:, self.joint] = values[:, 0]
        else:
            rots[:, self.joint] = values
        wpos, wrot = forward_kinematics(self.skeleton, roots, rots, scales=scales)
        kids = self.skeleton.children(self.joint)
        if rotation and kids:
            return wpos[:, kids[0]]
        if rotation:
            return wpos[:, self.joint] + quat.rotate(wrot[:, self.joint], self.skeleton.tips[self.joint])
        return wpos[:, 0]

    def draw(self, scene: RenderScene) -> None:
        """The puppet (candidate layer applied in preview), the take in orange, the loop in green, the overlay."""
        clip = self.candidate if self.phase == "preview" and self.candidate is not None else None
        root, rot = self._pose(self.time, clip)
        scales = self._scales(self.time, clip)
        if self.phase == "recording" and self._value is not None:
            if self.drive == "scale":
                scales = scales.copy()
                scales[self.joint] = self._value[0]
            else:
                roots, rots = self._driven(root[None], rot[None], self._value[None])
                root, rot = roots[0], rots[0]
        wpos, wrot = forward_kinematics(self.skeleton, root, rot, scales=scales)
        if self.character is not None:
            scene.skinned.append(character_instance(self.character, self.skeleton, root, rot))
        else:
            a, b, r, owner = puppet_capsules(self.skeleton, wpos, wrot)
            colors = np.tile(np.array([0.82, 0.8, 0.76]), (len(a), 1))
            colors[owner == self.joint] = PERFORMANCE
            scene.add_capsules(a, b, r, colors)
        rotation = self.drive in ("rotation", "scale")  # both show the driven bone's end
        if self._take is not None and len(self._take.values) > 1:
            scene.add_polyline(self._joint_path(np.asarray(self._take.values), rotation), PERFORMANCE, 2.0)
        if self.phase == "preview" and self.result is not None:
            scene.add_polyline(self._joint_path(np.asarray(self._performed), rotation), PERFORMANCE, 1.5)
            scene.add_polyline(self._joint_path(self.result.loop, rotation), CYCLE, 4.0, closed=True)
        title = {
            "ready": "ready",
            "countdown": f"get ready… {max(self.timer, 0.0):.0f} — then {PERFORM}",
            "recording": f"recording {self.timer:4.1f} s — {PERFORM}, several loops; Space stops",
            "preview": "preview",
        }[self.phase]
        scene.add_text(f"{self.skeleton.names[self.joint]} · {self.drive} · {title}", size=22)
        if self.message:
            scene.add_text(self.message, size=16)


def _drivable(skeleton: Skeleton, item: str, drive: str) -> tuple[int, tuple[int, int, int] | None]:
    """``item``'s joint index and IK chain, or ``ValueError`` when ``drive`` cannot move it."""
    if item not in skeleton.names:
        raise ValueError(f"no joint {item!r}; the character has {', '.join(skeleton.names)}")
    joint = skeleton.index(item)
    chain = item_chain(skeleton, joint)
    if drive in ("translation", "pose") and joint != 0 and chain is None:
        raise ValueError(
            f"{item}'s position follows its parents: drive the root, a hand or a foot by "
            f"{drive}, or {item!r} by rotation"
        )
    return joint, chain


def _sample_loop(loop: F, phase: F, drive: str) -> F:
    """Values of a closed loop ``[S+1, d]`` (end = start) at phases in ``[0, 1)``, interpolated.

    Positions linearly, rotations (a rotation, or a pose's last four numbers) by nlerp.
    """
    s = len(loop) - 1
    x = phase * s
    i = np.minimum(np.floor(x).astype(np.int64), s - 1)
    w = x - i
    out = loop[i] * (1.0 - w)[:, None] + loop[i + 1] * w[:, None]
    if drive in ("rotation", "pose"):
        out[:, -4:] = quat.nlerp(loop[i, -4:], loop[i + 1, -4:], w)
    return out
