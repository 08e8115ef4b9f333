"""Start-up: ``play snowman --headless --frames 1`` against importing the libraries it stands on.

A start is mostly imports (numpy, SciPy, MuJoCo, moderngl, numba…) plus our own set-up; the issue asks
that our share be at most the libraries' own: ``startup_s_play_snowman`` ≤ 2 × the import of
those heavy libraries alone. :data:`HEAVY` is what a plain snowman start really imports (a test
runs the start and checks each one is loaded): a library we stopped importing leaves the
baseline too. Both run as fresh processes (``sys.executable``), timed in process CPU time of the
child (user + system, from ``os.wait4``: the machine is shared), median of :data:`REPEATS`.
The built-in clips and lookup table are read from the user cache (a first run fills it and is not
counted). Both children may write bytecode, into a temporary ``PYTHONPYCACHEPREFIX`` (also filled
by the uncounted first run): as after any install, our modules start from ``.pyc`` as the
libraries' do, even where the environment sets ``PYTHONDONTWRITEBYTECODE`` (it would otherwise
compile our ~200 modules from source on every start, half a second the libraries never pay).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

import numpy as np

from puppetphone.bench.figures import Figure

__all__ = ["run", "child_cpu_s", "HEAVY", "REPEATS"]

REPEATS = 3
# the third-party packages `play snowman --headless` imports (SciPy by the subpackages it loads)
HEAVY = (
    "numpy",
    "scipy.spatial",
    "scipy.sparse",
    "scipy.linalg",
    "scipy.special",
    "mujoco",
    "moderngl",
    "numba",
    "daqp",
)


def child_cpu_s(args: list[str], pycache: str | None = None) -> float:
    """Process CPU seconds (user + system) of one child process running ``args`` (bytecode kept in ``pycache``)."""
    env = dict(os.environ, SDL_VIDEODRIVER="dummy")
    if pycache is not None:
        env.pop("PYTHONDONTWRITEBYTECODE", None)
        env["PYTHONPYCACHEPREFIX"] = pycache
    with tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=err, env=env)
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)  # reaped here: tell Popen
        if proc.returncode != 0:
            err.seek(0)
            raise RuntimeError(f"{' '.join(args)} failed: {err.read().decode(errors='replace').strip()[-300:]}")
    return usage.ru_utime + usage.ru_stime


def run() -> list[Figure]:
    """``startup_s_play_snowman`` beside the heavy libraries' import, same run."""
    play = [sys.executable, "-m", "puppetphone", "play", "snowman", "--headless", "--frames", "1"]
    imports = [sys.executable, "-c", "import " + ", ".join(HEAVY)]
    with tempfile.TemporaryDirectory(prefix="puppetphone-pyc-") as pycache:
        child_cpu_s(play, pycache)  # fills the clip and lookup caches, the bytecode and the OS file cache
        child_cpu_s(imports, pycache)
        starts, libs = [], []
        for _ in range(REPEATS):  # interleaved: a change in the machine's load hits both alike
            starts.append(child_cpu_s(play, pycache))
            libs.append(child_cpu_s(imports, pycache))
    return [
        Figure(
            "startup",
            "startup_s_play_snowman",
            float(np.median(starts)),
            "s",
            "import of its heavy libraries",
            float(np.median(libs)),
        ),
    ]
