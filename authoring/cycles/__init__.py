"""Motion cycles by performance (paper §4, thesis §5.3): act a loop out several times, get one clean loop.

    traj = Trajectory(times, values, items)        # what was performed
    result = extract_cycle(traj, rng)              # period, aligned cycles, closed loop, Bézier fits
    result.loop, result.period, result.curves

Modules, in the order the algorithm runs: :mod:`.trajectory` (validated input),
:mod:`.descriptor` (``d_D`` rows), :mod:`.period` (the period search), :mod:`.average`
(correspondences, alignment, mean), :mod:`.stitch` (closing the loop), :mod:`.spline`
(Bézier fit), :mod:`.extract` (all of it, and the refusal when there is no good cycle).
Beside them: :mod:`.formats` (files in and out), :mod:`.plot` (the ``--plot`` figure),
:mod:`.baseline` (the FFT/autocorrelation estimator the benchmark compares against) and
:mod:`.synthetic` (performances with a known answer).
"""

from authoring.cycles.extract import CycleError, CycleOptions, CycleResult, extract_cycle
from authoring.cycles.period import PeriodSearch
from authoring.cycles.spline import BezierLoop
from authoring.cycles.trajectory import Item, Trajectory, TrajectoryError

__all__ = [
    "BezierLoop",
    "CycleError",
    "CycleOptions",
    "CycleResult",
    "Item",
    "PeriodSearch",
    "Trajectory",
    "TrajectoryError",
    "extract_cycle",
]
