"""The window tests' fixture: a fresh Xvfb display (see :mod:`tests.puppetphone.xvfb`)."""

from tests.puppetphone.xvfb import display  # noqa: F401 - a fixture, found by name
