"""The launcher caps numpy's SIMD dispatch at AVX2 before numpy loads, so replays agree across CPUs.

Broken on purpose to see these fail: ``puppetphone/__init__.py`` not calling the cap (the two
launcher tests find no targets in the variable), the cap overwriting a user's variable instead
of adding to it (the user's-setting and merge tests fail), and the cap writing the variable
although numpy is already imported (the in-process test fails).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from puppetphone.simd_ceiling import ABOVE_CEILING, BLAS_CORE, _cpu_flags, cap_numpy_dispatch

ROOT = Path(__file__).resolve().parents[2]
_RAGDOLL_RECORDING = "tests/data/puppet_jump_rise_again.rec"  # Locomotion, Jump@32, Ragdoll@74
_PROBE = (
    "import os, puppetphone, numpy; from input.library_versions import numpy_simd_level; "
    "print(os.environ.get('OPENBLAS_CORETYPE'), file=__import__('sys').stderr); "
    "print(os.environ.get('NPY_DISABLE_CPU_FEATURES')); print(numpy_simd_level())"
)


def _probe(**env: str) -> list[str]:
    base = {k: v for k, v in os.environ.items() if k not in ("NPY_DISABLE_CPU_FEATURES", "OPENBLAS_CORETYPE")}
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", _PROBE],
        env={**base, **env},
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    return done.stdout.split()


def test_the_launcher_disables_the_avx512_targets_before_numpy_loads() -> None:
    *disabled, level = _probe()
    assert disabled == list(ABOVE_CEILING)
    assert not level.startswith(("X86_V4", "AVX512"))  # numpy imported with no warning (-W error) and capped


def test_a_users_own_setting_is_kept_and_numpy_honours_the_whole_variable() -> None:
    *disabled, level = _probe(NPY_DISABLE_CPU_FEATURES="X86_V3")
    assert disabled == ["X86_V3", *ABOVE_CEILING]
    assert level == "baseline"  # the user's X86_V3 reached numpy: the dispatch fell to the x86-64-v2 baseline


def test_the_cap_adds_to_a_variable_and_repeats_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delitem(sys.modules, "numpy")  # as if numpy had not been imported yet
    env = {"NPY_DISABLE_CPU_FEATURES": "AVX2,X86_V4"}
    assert cap_numpy_dispatch(env)
    assert env["NPY_DISABLE_CPU_FEATURES"].split() == ["AVX2", "X86_V4", "AVX512_ICL", "AVX512_SPR"]
    empty: dict[str, str] = {}
    assert cap_numpy_dispatch(empty) and empty["NPY_DISABLE_CPU_FEATURES"].split() == list(ABOVE_CEILING)


def test_blas_kernels_are_held_at_avx2_where_the_cpu_runs_them_and_a_users_choice_is_kept(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """OpenBLAS's AVX-512 kernels parted every shipped recording from the AVX2 machine's at frame 18."""
    monkeypatch.delitem(sys.modules, "numpy")
    avx512 = frozenset({"avx2", "fma", "avx512f"})
    env: dict[str, str] = {}
    assert cap_numpy_dispatch(env, avx512) and env["OPENBLAS_CORETYPE"] == BLAS_CORE
    mine = {"OPENBLAS_CORETYPE": "Zen"}
    cap_numpy_dispatch(mine, avx512)
    assert mine["OPENBLAS_CORETYPE"] == "Zen"
    old: dict[str, str] = {}
    cap_numpy_dispatch(old, frozenset({"sse4_2", "avx"}))  # no AVX2: Haswell kernels would not run
    assert "OPENBLAS_CORETYPE" not in old


def test_the_launcher_sets_the_blas_kernels_on_this_cpu_before_numpy_loads() -> None:
    base = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    done = subprocess.run(
        [sys.executable, "-W", "error", "-c", _PROBE], env=base, cwd=ROOT, capture_output=True, text=True, check=True
    )
    expected = BLAS_CORE if {"avx2", "fma"} <= _cpu_flags() else "None"
    assert done.stderr.split() == [expected]


@pytest.mark.parametrize(
    ("release", "last"),
    [
        ("2.4.6", "AVX512_SPR"),
        ("2.3.5", "AVX512_SPR"),
        ("2.2.6", "AVX512_ICL"),
        ("1.26.0", "AVX512_ICL"),
        ("1.25.2", None),
    ],
)
def test_each_numpy_release_gets_the_avx512_names_it_dispatches(monkeypatch: pytest.MonkeyPatch, release, last) -> None:
    """numpy 1.26 with AVX512_SPR named warns at import (an error under -W error); unnamed, its AVX-512
    arccos parted a compiled slerp from numpy's in the floor environment. Checked against each release's
    ``__cpu_dispatch__``: 1.26, 2.0, 2.1, 2.2 end at AVX512_ICL, 2.3 adds AVX512_SPR, 2.4 names levels."""
    import puppetphone.simd_ceiling as ceiling

    monkeypatch.delitem(sys.modules, "numpy")
    monkeypatch.setattr(ceiling, "version", lambda _name: release)
    env: dict[str, str] = {}
    ceiling.cap_numpy_dispatch(env, frozenset())
    named = env.get("NPY_DISABLE_CPU_FEATURES", "").split()
    assert (named[-1] if named else None) == last
    assert ("X86_V4" in named) == release.startswith("2.4") and ("AVX512F" in named) == (
        last is not None and not release.startswith("2.4")
    )


def test_once_numpy_is_imported_the_cap_says_it_cannot_help_and_changes_nothing() -> None:
    import numpy  # noqa: F401  (already loaded in this process)

    env: dict[str, str] = {}
    assert not cap_numpy_dispatch(env) and env == {}


@pytest.mark.slow
def test_a_ragdoll_recording_replays_bit_for_bit_on_baseline_numpy_kernels_and_generic_numba_code(
    tmp_path: Path,
) -> None:
    """What a CPU without AVX2 would run: numpy at its x86-64-v2 baseline (its AVX2 sin, cos, exp,
    log and tanh off) and numba compiling for a plain x86-64 instead of this CPU. The recording
    was made with both at full width here; every state hash (a fall into the ragdoll at frame 74
    included) must still match. Hashes that parted on the kernels' last bits would fail it."""
    done = subprocess.run(
        [sys.executable, "-m", "puppetphone", "replay", _RAGDOLL_RECORDING, "--verify", "--headless"],
        env={
            **os.environ,
            "SDL_VIDEODRIVER": "dummy",
            "NPY_DISABLE_CPU_FEATURES": "X86_V3",
            "NUMBA_CPU_NAME": "x86-64",
            "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
        },
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
        timeout=900,
    )
    assert done.returncode == 0 and "all 112 state hashes match" in done.stdout, done.stdout + done.stderr
