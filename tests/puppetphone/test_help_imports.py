"""``puppetphone --help`` builds every sub-command's parser without loading numpy, GL, the hub or a device server.

Broken on purpose to see it fail: ``from engine.runner import RunOptions`` back at the top of
``puppetphone/runargs.py`` (engine.runner, numpy and moderngl appear in the list).
"""

import subprocess
import sys

HEAVY = (
    "numpy",
    "pygame",
    "moderngl",
    "scipy",
    "mujoco",
    "engine.runner",
    "engine.render",
    "input.hub",
    "input.osc",
    "input.web",
    "authoring",
    "games",
    "puppetphone.bench",
)


def test_help_imports_no_heavy_module():
    code = (
        "import contextlib, io, sys\n"
        "from puppetphone.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    try:\n        main(['--help'])\n    except SystemExit:\n        pass\n"
        "print('\\n'.join(sorted(sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    loaded = [m for m in out if any(m == h or m.startswith(h + ".") for h in HEAVY)]
    assert not loaded, f"--help imported {loaded}"


def test_parse_time_constants_agree_with_their_owners():
    """The defaults and choices spelled in the argument helpers are the ones the modules use."""
    from engine.io.units import UNITS
    from engine.io.up_axis import AXES
    from input import factory
    from input.osc import DEFAULT_PORT
    from input.web.server import DEFAULT_WEB_PORT
    from puppetphone.motion_args import UNIT_NAMES, UP_AXES

    assert (factory.DEFAULT_PORT, factory.DEFAULT_WEB_PORT) == (DEFAULT_PORT, DEFAULT_WEB_PORT)
    assert set(UNIT_NAMES) == set(UNITS) and set(UP_AXES) == set(AXES)
    from engine.render.quality import QUALITY_NAMES, parse_quality
    from puppetphone import runargs

    assert runargs.QUALITY_NAMES == QUALITY_NAMES
    assert [runargs.quality_name(t) for t in (" Low", "AUTO")] == [parse_quality(t) for t in (" Low", "AUTO")]
