"""``bench motion``: how the puppet obeys the hand, measured in play through the real input path.

Every case of :data:`bench.motion_play.CASES` (straight drags 0.3–5 m/s, a 1.5 m circle,
stop-and-go, a zigzag, a reversal) is driven by the scripted phone and the scripted
mouse (:func:`bench.motion_play.drive`), once with the locomotion control that plays
(``spring``) and once with the earlier one (``legacy``, the baseline of the same run).
Per case and device it prints:

- ``<device>_<case>_slide_mean`` / ``_slide_p95`` (m/s): planted-foot slide, against the
  legacy controller's, and for straight drags ``blend_alone_<case>_slide_mean`` — the same
  blend played alone, measured the same way;
- ``_lowest_sole`` (m), ``_time_to_90`` (s, straight drags), ``_time_to_rest`` (s),
  ``_fell`` (1 when the puppet dropped into the ragdoll);

and, with CesiumMan (``shared/data/mocap``) as the player's puppet (``play --character``),
``character_<device>_<case>_slide_mean`` / ``_slide_p95`` / ``_lowest_sole`` against the mannequin's of the
same run: a character must keep its feet as planted as the mannequin (the bound ``tests/bench``
holds both to: mean ≤ 0.02 m/s, p95 ≤ 0.05 m/s).

Over the jump sweep (valid flicks at 0–4 m/s, both devices) it prints ``<device>_jump_landed_pct``
against the legacy controller, ``_jump_apex_error`` (m) and ``_jump_takeoff_s``.
``puppetphone bench motion --plot FILE [--case NAME]`` draws foot height and speed over
time for one case (:func:`plot_case`). Simulation only: no timing figures, so the machine's load does not matter.
"""

from __future__ import annotations

import numpy as np

from puppetphone.bench.figures import Figure
from puppetphone.bench.motion_play import CASES, Case, blend_alone_slide, drive, jump, motion_figures

__all__ = ["run", "plot_case", "JUMP_SPEEDS"]

BENCH = "motion"
JUMP_SPEEDS = (0.0, 1.0, 2.0, 3.0, 4.0)


def run() -> list[Figure]:
    """Every case with both devices and both controllers, then the jump sweep."""
    figs: list[Figure] = []
    character = _character()
    for case in CASES:
        alone = blend_alone_slide(case.speed) if case.speed is not None else None
        if alone is not None:
            figs.append(Figure(BENCH, f"blend_alone_{case.name}_slide_mean", alone[0], "m/s"))
        for device in ("phone", "mouse"):
            new = motion_figures(case, drive(case, device, "spring"))
            old = motion_figures(case, drive(case, device, "legacy"))
            key = f"{device}_{case.name}"
            figs += [
                Figure(BENCH, f"{key}_slide_mean", new.slide_mean, "m/s", "legacy controller", old.slide_mean),
                Figure(BENCH, f"{key}_slide_p95", new.slide_p95, "m/s", "legacy controller", old.slide_p95),
                Figure(BENCH, f"{key}_lowest_sole", new.lowest_sole, "m", "legacy controller", old.lowest_sole),
                Figure(BENCH, f"{key}_fell", float(new.fell), "", "legacy controller", float(old.fell)),
            ]
            if new.time_to_90 is not None:
                figs.append(
                    Figure(BENCH, f"{key}_time_to_90", new.time_to_90, "s", "legacy controller", old.time_to_90)
                )
            if new.time_to_rest is not None:
                figs.append(Figure(BENCH, f"{key}_time_to_rest", new.time_to_rest, "s"))
            if character is not None:
                ch = motion_figures(case, drive(case, device, "spring", character=character))
                figs += [
                    Figure(BENCH, f"character_{key}_slide_mean", ch.slide_mean, "m/s", "mannequin", new.slide_mean),
                    Figure(BENCH, f"character_{key}_slide_p95", ch.slide_p95, "m/s", "mannequin", new.slide_p95),
                    Figure(BENCH, f"character_{key}_lowest_sole", ch.lowest_sole, "m", "mannequin", new.lowest_sole),
                    Figure(BENCH, f"character_{key}_fell", float(ch.fell), "", "mannequin", float(new.fell)),
                ]
    for device in ("phone", "mouse"):
        new_jumps = [jump(v, device, "spring") for v in JUMP_SPEEDS]
        old_jumps = [jump(v, device, "legacy") for v in JUMP_SPEEDS]
        apex = [r.apex_error for r in new_jumps if r.apex_error is not None]
        delay = [r.takeoff_delay for r in new_jumps if r.takeoff_delay is not None]
        figs += [
            Figure(
                BENCH,
                f"{device}_jump_landed_pct",
                100.0 * float(np.mean([r.landed for r in new_jumps])),
                "%",
                "legacy controller",
                100.0 * float(np.mean([r.landed for r in old_jumps])),
            ),
            Figure(BENCH, f"{device}_jump_apex_error", float(np.max(apex)) if apex else float("nan"), "m"),
            Figure(BENCH, f"{device}_jump_takeoff_s", float(np.median(delay)) if delay else float("nan"), "s"),
        ]
    return figs


def _character() -> dict[str, object] | None:
    """CesiumMan as a ``play --character`` set-up value, or ``None`` (said in one line) without the data."""
    import sys

    from engine.character.setup import character_setup
    from puppetphone.bench.render_skinned import character_file

    path = character_file()
    if path is None:
        print("motion: CesiumMan.glb not found (set PUPPETPHONE_DATA): no character figures", file=sys.stderr)
        return None
    return character_setup(str(path))


def plot_case(case: Case, path: str, device: str = "mouse") -> None:
    """Foot height and toe speed over time, new controller against legacy (people would rather look)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(12, 6), sharex=True)
    for col, controller in enumerate(("spring", "legacy")):
        run = drive(case, device, controller)
        t = np.arange(len(run.toes)) * run.dt
        speed = np.linalg.norm(np.diff(run.toes[..., [0, 2]], axis=0), axis=-1) / run.dt
        body = np.linalg.norm(np.diff(run.position[:, [0, 2]], axis=0), axis=-1) / run.dt
        for side, name in enumerate(("left", "right")):
            axes[0, col].plot(t, 100 * run.toes[:, side, 1], label=f"{name} toe")
            axes[1, col].plot(t[1:], speed[:, side], label=f"{name} toe")
        axes[1, col].plot(t[1:], body, "k--", label="puppet")
        axes[0, col].set_title(f"{case.name}, {device}, {controller} controller")
        axes[0, col].set_ylabel("height (cm)")
        axes[1, col].set_ylabel("speed (m/s)")
        axes[1, col].set_xlabel("time (s)")
        axes[0, col].legend(loc="upper right")
        axes[1, col].legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
