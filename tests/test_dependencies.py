"""The dependency set: exact pins for the libraries that change the numbers, honest floors.

``constraints.txt`` pins what the shipped recordings replay with (README's test command and
``.ci/run`` install with it); ``constraints-floor.txt`` is every floor of ``pyproject.toml``
exactly, installed by ``.ci/run`` in a second environment for a smoke run. These tests keep the
three files and the two scripts from drifting apart.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parent.parent
NUMBER_CHANGING = ["numpy", "scipy", "mujoco", "osqp", "daqp"]


def _pins(name: str) -> dict[str, Version]:
    pins = {}
    for line in (ROOT / name).read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            req = Requirement(line)
            spec = list(req.specifier)
            assert len(spec) == 1 and spec[0].operator == "==", f"{name}: {line!r} is not an exact pin"
            pins[canonicalize_name(req.name)] = Version(spec[0].version)
    return pins


def _dependencies() -> list[Requirement]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    return [Requirement(d) for d in project["dependencies"]]


def test_the_number_changing_libraries_are_pinned_within_the_declared_ranges() -> None:
    pins = _pins("constraints.txt")
    for name in NUMBER_CHANGING:
        assert name in pins, f"constraints.txt does not pin {name}"
    for req in _dependencies():
        name = canonicalize_name(req.name)
        if name in pins:
            assert req.specifier.contains(pins[name]), f"constraints.txt pins {name} {pins[name]} outside {req}"


def test_the_floor_file_is_every_declared_floor_exactly() -> None:
    floors = _pins("constraints-floor.txt")
    deps = _dependencies()
    assert set(floors) == {canonicalize_name(r.name) for r in deps}
    for req in deps:
        name = canonicalize_name(req.name)
        lower = [s for s in req.specifier if s.operator == ">="]
        assert len(lower) == 1, f"{req}: a dependency needs one floor (>=)"
        floor = Version(lower[0].version)
        assert name in floors, f"constraints-floor.txt lacks {name}"
        pinned = floors[name]
        # The pin is the floor itself (a wheel's extra build number, 4.8 -> 4.8.0.74, allowed).
        assert pinned.release[: len(floor.release)] == floor.release and req.specifier.contains(pinned), (
            f"constraints-floor.txt pins {name} {pinned}, the declared floor is {floor}"
        )


def test_mujoco_floor_is_one_that_runs_the_ragdoll() -> None:
    """3.2.7-3.10 reject the ragdoll's <orientation> actuator, 3.11-3.12 segfault building it."""
    mujoco = next(r for r in _dependencies() if r.name == "mujoco")
    assert not mujoco.specifier.contains(Version("3.12.0")) and mujoco.specifier.contains(Version("3.13.0"))


def test_readme_and_ci_install_with_the_constraints() -> None:
    readme = (ROOT / "README.md").read_text()
    command = next(line for line in readme.splitlines() if re.match(r"^pip install -e '\.\[test\]'", line))
    assert "-c constraints.txt" in command
    ci = (ROOT / ".ci" / "run").read_text()
    assert "grep -m1 -E \"^pip install -e '\\.\\[test\\]'\" README.md" in ci
    assert "PUPPETPHONE_STRICT_SKIPS=1" in ci
    # the side environments, installed from a copy of the checkout: pose tests and the FK peer; the floors
    assert 'pip install -q -e "$side/src[test,pose,peers]" -c constraints.txt' in ci
    assert 'pip install -q -e "$side/src[test]" -c constraints-floor.txt' in ci
