"""Fixtures for input tests: a small app (engine + input plugin) and OSC packet builders."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np
import pytest
from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message_builder import OscMessageBuilder

from engine.app import App
from engine.components import Grabbable, Obstacle, Transform
from input.hub import InputHub
from input.osc import OscSource
from input.plugin import install_input


def build_app(hub: InputHub, seed: int = 7) -> App:
    """One grabbable puppet stand-in at the origin and a post to bump into."""
    app = App(seed=seed)
    install_input(app, hub)
    app.world.spawn(Transform(position=np.array([0.0, 0.95, 0.0])), Grabbable(radius=0.6))
    app.world.spawn(Transform(position=np.array([2.0, 0.0, 2.0])), Obstacle(radius=0.3, height=1.5))

    def wander(world) -> None:  # a little rule that uses the RNG and the stick, so hashes carry state
        from engine.components import Stick

        for _, stick in world.query(Stick):
            if stick.grabbed is not None:
                world.get(stick.grabbed, Transform).position = stick.tip + world.rng.normal(0, 1e-3, 3)

    app.add_system("rules", wander)
    return app


@pytest.fixture
def make_app() -> Callable[[InputHub], App]:
    return build_app


def message(address: str, *args: object) -> bytes:
    """One OSC message as bytes."""
    b = OscMessageBuilder(address)
    for a in args:
        b.add_arg(a)
    return b.build().dgram


def bundle(*messages: tuple) -> bytes:
    """An OSC bundle (timetag immediate) of ``(address, *args)`` tuples."""
    bb = OscBundleBuilder(IMMEDIATELY)
    for address, *args in messages:
        b = OscMessageBuilder(address)
        for a in args:
            b.add_arg(a)
        bb.add_content(b.build())
    return bb.build().dgram


@pytest.fixture
def osc() -> tuple[Callable[..., bytes], Callable[..., bytes]]:
    return message, bundle


@pytest.fixture
def source() -> Iterator[Callable[..., OscSource]]:
    """Makes OSC sources on 127.0.0.1 and a free port (keyword overrides per test), stopped after the test."""
    made: list[OscSource] = []

    def make(**kw: object) -> OscSource:
        src = OscSource(host="127.0.0.1", port=0, **kw)  # type: ignore[arg-type]  # keyword overrides per test
        made.append(src)
        return src

    yield make
    for s in made:
        s.stop()


@pytest.fixture
def pose(osc: tuple[Callable[..., bytes], Callable[..., bytes]]) -> bytes:
    """One identity orientation message, as a phone sends it."""
    return osc[0]("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
