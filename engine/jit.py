"""The numba switch for the crowd kernels, and the scalar quaternion maths they share.

A crowd's animation, leg IK and FK are loops over puppets and joints of a few float
operations each. Written as numpy calls over ``[P, …]`` arrays they cost a microsecond
of dispatch per call for nanoseconds of arithmetic; compiled by numba as plain loops
they cost the arithmetic. Every kernel keeps its pure-numpy twin (the code it replaced):
that path runs when numba is absent or switched off, and the tests run both on the same
input and compare them (see ``tests/engine/test_jit.py`` and the kernels' own tests).

:func:`enabled` says which path runs; ``PUPPETPHONE_NUMPY=1`` in the environment or
:func:`use` (a context manager, for tests and benches) selects the numpy one. Kernels are
compiled on first use and cached on disk (``cache=True``), so a process pays numba's
compile time once per machine, not per start.

The helpers below work on tuples, ``(x, y, z)`` vectors and ``(w, x, y, z)`` quaternions,
with the operation order of :mod:`engine.quat` (a compiled kernel agrees with the numpy
path to rounding, not always bit for bit: numpy's ``norm``/``sum`` may pair terms differently).
"""

from __future__ import annotations

import functools
import importlib.util
import math
import os
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar, cast

__all__ = [
    "AVAILABLE",
    "compile_seconds",
    "enabled",
    "njit",
    "njit_inline",
    "qaxis_angle",
    "qbetween",
    "qconj",
    "qmul",
    "qnormalize",
    "qrot",
    "qarc",
    "qslerp",
    "qslerp_arc",
    "use",
    "vcross",
    "vdot",
    "vnorm",
    "vunit",
]

T = TypeVar("T", bound=Callable[..., Any])

AVAILABLE: bool = importlib.util.find_spec("numba") is not None
_state = {"on": AVAILABLE and os.environ.get("PUPPETPHONE_NUMPY", "") not in ("1", "true", "yes")}
_numba_module: Any = None  # numba, once the first kernel needs it


def enabled() -> bool:
    """Whether the compiled kernels run (numba installed and not switched off)."""
    return _state["on"]


@contextmanager
def use(compiled: bool) -> Iterator[None]:
    """Run the block on the compiled kernels (``True``, needs numba) or the numpy path (``False``)."""
    if compiled and not AVAILABLE:
        raise RuntimeError("numba is not installed: the compiled kernels cannot run")
    before = _state["on"]
    _state["on"] = compiled
    try:
        yield
    finally:
        _state["on"] = before


def _numba() -> Any:
    """numba, imported on first use.

    Importing numba costs about 1.3 s of CPU, and it imports SciPy (0.7 s more): a process that never
    runs a kernel (a command that reads or writes files, a test's helper process) does not pay it."""
    global _numba_module
    if _numba_module is None:
        import numba

        _time_compiles(numba)
        _numba_module = numba
    return _numba_module


_compiling = {"seconds": 0.0, "depth": 0, "since": 0.0}


def compile_seconds() -> float:
    """Wall seconds this process has spent compiling kernels so far.

    A kernel found in numba's disk cache is loaded, not compiled, so this stays near 0 except on a
    first start after an install (every kernel: tens of seconds, inside the first steps) or after a
    kernel's source changed. The window's time keeper leaves these seconds out of its verdict: a
    one-off compile is not a game too slow to keep real time (:mod:`engine.runner`)."""
    return _compiling["seconds"]


def _time_compiles(numba: Any) -> None:
    """Count the wall time of numba's compiles (its ``numba:compile`` events, outermost only: a kernel
    compiles the kernels it calls inside its own)."""
    from numba.core import event

    class CompileTimer(event.Listener):
        def on_start(self, _event: Any) -> None:
            if _compiling["depth"] == 0:
                _compiling["since"] = time.perf_counter()
            _compiling["depth"] += 1

        def on_end(self, _event: Any) -> None:
            _compiling["depth"] -= 1
            if _compiling["depth"] == 0:
                _compiling["seconds"] += time.perf_counter() - _compiling["since"]

    event.register("numba:compile", CompileTimer())


class _Kernel:
    """A function to be compiled by numba, made into numba's dispatcher on its first call.

    Compilation was already lazy (on the first call, or loaded from the disk cache); this defers the
    dispatcher itself, and so numba's import. Once made, the dispatcher replaces this object under the
    function's name in its module, so later calls through the module go to numba directly; other
    references forward to it. Attributes are the dispatcher's, and through them a kernel that calls this
    one (``from engine.jit import qmul``) compiles as if it held the dispatcher: numba types any global by
    its ``_numba_type_`` (a dispatcher's is ``types.Dispatcher``), and inlines by its ``targetoptions``
    and ``py_func``."""

    def __init__(self, fn: Callable[..., Any], options: dict[str, Any]) -> None:
        self._fn, self._options = fn, options
        self._dispatcher: Any = None
        functools.update_wrapper(self, fn)

    def dispatcher(self) -> Any:
        """numba's dispatcher of the function (made, and put in the function's module, on first use)."""
        if self._dispatcher is None:
            self._dispatcher = _numba().njit(**self._options)(self._fn)
            module = sys.modules.get(self._fn.__module__)
            if module is not None and getattr(module, self._fn.__name__, None) is self:
                setattr(module, self._fn.__name__, self._dispatcher)
        return self._dispatcher

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.dispatcher()(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") or name in ("_fn", "_options", "_dispatcher"):
            raise AttributeError(name)
        return getattr(self.dispatcher(), name)


def _compiled(fn: T, **options: Any) -> T:
    """``fn`` compiled by numba with ``options`` when numba is installed; the plain function otherwise
    (never called then)."""
    if not AVAILABLE:
        return fn
    if _numba_module is not None:  # numba already loaded: no reason to defer
        return cast(T, _numba_module.njit(**options)(fn))
    return cast(T, _Kernel(fn, options))  # it calls, and types in numba, as fn's dispatcher


def njit(fn: T) -> T:
    """``numba.njit`` (cached; division by zero gives inf/NaN as numpy does) when numba is installed;
    the plain function otherwise (never called then). numba is imported when the first kernel runs."""
    return _compiled(fn, cache=True, nogil=True, error_model="numpy")


def njit_inline(fn: T) -> T:
    """:func:`njit`, inlined by numba into every kernel that calls it (``inline="always"``): a helper run per
    puppet that takes arrays then costs its callers no call and no reference counting of those arrays."""
    return _compiled(fn, cache=True, nogil=True, error_model="numpy", inline="always")


@njit
def vdot(a: tuple[float, float, float], b: tuple[float, float, float]) -> float:
    """``a · b``."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit
def vcross(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float, float]:
    """``a × b``."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit
def vnorm(a: tuple[float, float, float]) -> float:
    """``|a|``."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@njit
def vunit(a: tuple[float, float, float], eps: float) -> tuple[float, float, float]:
    """``a / max(|a|, eps)``."""
    n = max(vnorm(a), eps)
    return (a[0] / n, a[1] / n, a[2] / n)


@njit
def qmul(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    """Hamilton product ``a * b`` (:func:`engine.quat.mul`)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit
def qconj(q: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """Conjugate: the inverse of a unit quaternion."""
    return (q[0], -q[1], -q[2], -q[3])


@njit
def qnormalize(q: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """Unit quaternion; a zero one becomes the identity (:func:`engine.quat.normalize`)."""
    n = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if n > 1e-12:
        return (q[0] / n, q[1] / n, q[2] / n, q[3] / n)
    return (1.0, 0.0, 0.0, 0.0)


@njit
def qrot(q: tuple[float, float, float, float], v: tuple[float, float, float]) -> tuple[float, float, float]:
    """Rotate ``v`` by the unit quaternion ``q``: ``v + w·t + u×t`` with ``t = 2u×v`` (:func:`engine.quat.rotate`)."""
    w, x, y, z = q
    vx, vy, vz = v
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return (vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx))


@njit
def qaxis_angle(axis: tuple[float, float, float], angle: float) -> tuple[float, float, float, float]:
    """Rotation of ``angle`` about ``axis`` (normalised here; a zero axis is left as is)."""
    n = vnorm(axis)
    if not n > 1e-12:
        n = 1.0
    half = 0.5 * angle
    s = math.sin(half)
    return (math.cos(half), s * (axis[0] / n), s * (axis[1] / n), s * (axis[2] / n))


@njit
def qarc(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[tuple[float, float, float, float], float, float]:
    """The part of :func:`qslerp` that depends only on its ends: ``b`` in ``a``'s hemisphere, the angle
    between them and its sine (a crowd's kernel computes it once per pair of clip frames)."""
    if a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] < 0.0:
        b = (-b[0], -b[1], -b[2], -b[3])
    d = min(max(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], -1.0), 1.0)
    theta = math.acos(d)
    return b, theta, math.sin(theta)


@njit
def qslerp_arc(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float], theta: float, s: float, t: float
) -> tuple[float, float, float, float]:
    """The rest of :func:`qslerp` from :func:`qarc`'s answer: the point at ``t`` on the arc."""
    if s < 1e-6:
        wa, wb = 1.0 - t, t
    else:
        wa, wb = math.sin((1.0 - t) * theta) / s, math.sin(t * theta) / s
    return qnormalize((wa * a[0] + wb * b[0], wa * a[1] + wb * b[1], wa * a[2] + wb * b[2], wa * a[3] + wb * b[3]))


@njit
def qslerp(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float], t: float
) -> tuple[float, float, float, float]:
    """Spherical interpolation along the shorter arc (:func:`engine.quat.slerp`)."""
    b, theta, s = qarc(a, b)
    return qslerp_arc(a, b, theta, s, t)


@njit
def qbetween(u: tuple[float, float, float], v: tuple[float, float, float]) -> tuple[float, float, float, float]:
    """Shortest-arc rotation taking direction ``u`` to ``v`` (:func:`engine.quat.between`)."""
    nu, nv = vnorm(u), vnorm(v)
    u = (u[0] / nu, u[1] / nu, u[2] / nu)
    v = (v[0] / nv, v[1] / nv, v[2] / nv)
    d = vdot(u, v)
    if 1.0 + d < 1e-9:  # opposite: any axis perpendicular to u
        perp = vcross(u, (1.0, 0.0, 0.0))
        if vnorm(perp) < 1e-6:
            perp = vcross(u, (0.0, 1.0, 0.0))
        return qnormalize((0.0, perp[0], perp[1], perp[2]))
    c = vcross(u, v)
    return qnormalize((1.0 + d, c[0], c[1], c[2]))
