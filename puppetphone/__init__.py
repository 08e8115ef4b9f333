"""The launcher: command line and the wiring of games, authoring scenes and benches.

The only package that sees everything (DESIGN: imports go downwards from here).
"""

__version__ = "0.1.0"
