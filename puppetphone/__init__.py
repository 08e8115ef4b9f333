"""The launcher: command line and the wiring of games, authoring scenes and benches.

The only package that sees everything (DESIGN: imports go downwards from here).
"""

from puppetphone.simd_ceiling import cap_numpy_dispatch

cap_numpy_dispatch()  # before anything imports numpy: the same kernels on every x86-64 CPU (replays agree)

__version__ = "0.1.0"
