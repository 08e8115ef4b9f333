"""Physics that no input can break: bounded velocities, and recovery when MuJoCo fails.

Ordinary play can feed MuJoCo things it cannot integrate: a flick that asks for a
huge target velocity, two ragdolls placed inside each other (the contact solver
pushes them apart at 10⁵ m/s), a pile of thirty puppets that overflows the contact
arena (``mujoco.FatalError: mj_stackAlloc out of memory``). So each simulation step
runs through :func:`guarded_step`:

- every substep's velocities are clamped to :data:`MAX_LINEAR` m/s and
  :data:`MAX_ANGULAR` rad/s (per degree of freedom), so no impulse can throw a body
  out of the field in one step;
- the state before the step is kept; a MuJoCo warning (unstable acceleration, full
  contact or constraint buffers), a ``FatalError`` or a non-finite number afterwards
  puts that state back with the offending bodies at rest, and the step is reported as
  a recovery (the caller counts them) instead of ending the game.

MuJoCo reports warnings through one process-wide C callback, which would print them;
:func:`collect_warnings` replaces it (once) with one that records them, so they reach
the step that caused them — and, through Python's ``warnings``, the test suite, which
turns them into errors.
"""

from __future__ import annotations

import mujoco
import numpy as np
from numpy.typing import NDArray

__all__ = ["MAX_LINEAR", "MAX_ANGULAR", "velocity_limits", "guarded_step", "collect_warnings", "PhysicsRecovery"]

MAX_LINEAR = 30.0  # m/s: faster than any throw or fall in the field
# rad/s per degree of freedom. An animated target asks for at most pi/dt (188 at 60 Hz, the shortest
# way round in one step). A limp hand (0.5 kg, 4e-4 kg m²) pinched between its own lower arm and head
# in a crowd fall reached 861 rad/s in one substep (1.8 rad per 1/480 s) and the step diverged under
# the old bound of 1000; at 200 it turns at most 0.42 rad per substep and settles. (A foot snapping
# back inside its joint limit on entry, ~550, now takes a few substeps.)
MAX_ANGULAR = 200.0
_BLOWUP = 10.0  # a substep that ends this many times over the bound has exploded
_STATE = mujoco.mjtState.mjSTATE_INTEGRATION
_PENDING: list[str] = []
_HOOKED: list[bool] = []


class PhysicsRecovery(RuntimeWarning):
    """A physics step failed and was undone (the game goes on; tests treat it as an error)."""


def _record(message: str) -> None:
    _PENDING.append(message)


def collect_warnings() -> None:
    """Route MuJoCo's warnings to :func:`guarded_step` instead of stdout (idempotent)."""
    if not _HOOKED:
        mujoco.set_mju_user_warning(_record)
        _HOOKED.append(True)


def velocity_limits(m: mujoco.MjModel) -> NDArray[np.float64]:
    """Per-dof speed bound: linear for the first three dofs of a free joint, angular elsewhere."""
    limit = np.full(m.nv, MAX_ANGULAR)
    for j in np.nonzero(m.jnt_type == int(mujoco.mjtJoint.mjJNT_FREE))[0]:
        a = int(m.jnt_dofadr[j])
        limit[a : a + 3] = MAX_LINEAR
    return limit


def guarded_step(
    m: mujoco.MjModel, d: mujoco.MjData, substeps: int, limit: NDArray[np.float64], owners: NDArray[np.int64]
) -> str | None:
    """Advance ``substeps`` MuJoCo steps with bounded velocities; on failure restore the state
    from before the step, with every body that owns a bad degree of freedom at rest.

    Args:
        limit: ``[nv]`` from :func:`velocity_limits`.
        owners: ``[nv]`` an id per degree of freedom (a ragdoll or a prop), whose dofs rest together.

    Returns:
        ``None``, or why the step was undone.
    """
    saved = np.empty(mujoco.mj_stateSize(m, _STATE))
    mujoco.mj_getState(m, d, saved, _STATE)
    counts = d.warning.number.copy()  # one array read (a loop over the warning structs cost ~0.3 ms)
    del _PENDING[:]
    reason = None
    np.clip(d.qvel, -limit, limit, out=d.qvel)  # commanded (kinematic) velocities too
    try:
        for _ in range(substeps):
            mujoco.mj_step(m, d)
            if (np.abs(d.qvel) > _BLOWUP * limit).any():  # exploded inside the substep
                reason = "velocity blow-up"
                break
            np.clip(d.qvel, -limit, limit, out=d.qvel)
    except mujoco.FatalError as exc:
        reason = f"MuJoCo error: {exc}"
    if reason is None and _PENDING:
        reason = f"MuJoCo warning: {_PENDING[0]}"
    if reason is None and (d.warning.number > counts).any():
        reason = "MuJoCo warning"
    if reason is None and not (np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all()):
        reason = "non-finite state"
    if reason is None:
        return None
    bad = ~np.isfinite(d.qvel) | (np.abs(d.qvel) >= limit) | ~np.isfinite(d.qacc)
    mujoco.mj_setState(m, d, saved, _STATE)
    d.warning.number[:] = counts
    rest = np.isin(owners, owners[bad]) if bad.any() else np.ones(m.nv, dtype=bool)
    d.qvel[rest] = 0.0
    d.qvel[~np.isfinite(d.qvel)] = 0.0
    broken = ~np.isfinite(d.qpos)  # only if something wrote NaN into MuJoCo behind our back
    d.qpos[broken] = m.qpos0[broken]
    d.qacc_warmstart[:] = 0.0
    mujoco.mj_forward(m, d)
    del _PENDING[:]
    return reason
