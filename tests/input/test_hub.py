import numpy as np
import pytest

from input.hub import InputHub
from input.sample import DISCONNECT, TOUCH_DOWN, TOUCH_UP, PoseSample
from input.source import PoseSource


class Fed(PoseSource):
    threaded = False


def _s(i, touch=None, src="dev"):
    return PoseSample(time=float(i), source=src, orientation=[1.0, 0, 0, 0], position=[i / 100, 0, 0], touch=touch)


def test_touch_transitions_become_events_once():
    src = Fed("dev")
    hub = InputHub([src])
    src.push(_s(0, touch=True))
    src.push(_s(1, touch=True))
    f = hub.drain(0)
    assert f.events == ((TOUCH_DOWN, "dev"),) and len(f.samples) == 2
    src.push(_s(2, touch=False))
    assert hub.drain(1).events == ((TOUCH_UP, "dev"),)
    assert hub.drain(2).samples == () and hub.drain(2).events == ()


def test_flood_is_coalesced_keeping_newest_and_touch_changes():
    src = Fed("dev", capacity=100_000)
    hub = InputHub([src], max_samples=8)
    for i in range(10_000):
        src.push(_s(i, touch=True if i == 5000 else None))
    f = hub.drain(0)
    xs = [s.time for s in f.samples]
    assert len(f.samples) == 9 and xs[0] == 5000 and xs[-8:] == [float(i) for i in range(9992, 10000)]
    assert hub.coalesced == 10_000 - 9
    assert f.has_event(TOUCH_DOWN, "dev")


def test_bounded_queue_counts_drops():
    src = Fed("dev", capacity=16)
    for i in range(100):
        src.push(_s(i))
    st = src.status()
    assert st.dropped == 84 and st.drop_reasons == {"queue full": 84} and st.packets == 100
    assert len(src.drain()) == 16


def test_disconnect_while_touching_adds_touch_up():
    src = Fed("dev")
    hub = InputHub([src])
    src.push(_s(0, touch=True))
    hub.drain(0)
    src.disconnected("dev")
    f = hub.drain(1)
    assert f.events == ((DISCONNECT, "dev"), (TOUCH_UP, "dev"))


def test_live_frame_is_codec_round_tripped():
    src = Fed("dev")
    hub = InputHub([src])
    src.push(_s(0))
    f = hub.drain(0)
    assert isinstance(f.samples[0].position, np.ndarray) and f.samples[0].position.dtype == np.float64
    assert not hub.live  # fed from the main thread only


def test_tool_operations_round_trip_and_malformed_ones_are_named():
    from input.sample import TOOL, InputFrame, decode_tool, encode_tool

    hub = InputHub()
    hub.tool("press", 512, 300, True)
    hub.tool("key", "s", True, False)
    frame = hub.drain(0)
    assert frame.tool_operations() == [("press", 512, 300, True), ("key", "s", True, False)]
    assert hub.drain(1).tool_operations() == []
    for bad in ("{", "[]", "[3, 1]", '["move", NaN, 1]', '{"press": 1}', '["key", [1]]'):
        with pytest.raises(ValueError, match="malformed tool operation"):
            InputFrame(frame=0, events=((TOOL, bad),)).tool_operations()
    with pytest.raises(ValueError, match="too long"):
        encode_tool(("key", "x" * 300))
    assert decode_tool(encode_tool(("zoom", 0.9))) == ("zoom", 0.9)


@pytest.mark.parametrize("frame", [0, 1, 4321, 0xFFFFFFFF])
def test_an_empty_step_is_the_frame_the_codec_gives_back(frame, monkeypatch):
    """A step with no input skips the codec round trip: what it drains must be what the round
    trip gives, field for field and in the state hash. Broken once by draining ``frame + 1`` there."""
    import hashlib

    from engine.hashing import feed
    from input import hub as hub_module
    from input.codec import decode_frame, encode_frame
    from input.sample import InputFrame

    calls = []
    monkeypatch.setattr(hub_module, "decode_frame", lambda data: calls.append(data) or decode_frame(data))
    hub = InputHub([Fed("dev")])
    got = hub.drain(frame)
    want = decode_frame(encode_frame(InputFrame(frame=frame)))
    assert calls == [] and hub.last_frame is got
    assert (got.frame, got.samples, got.events) == (want.frame, want.samples, want.events)
    assert type(got.frame) is type(want.frame) and type(got.samples) is type(want.samples)
    a, b = hashlib.sha256(), hashlib.sha256()
    feed(a, got)
    feed(b, want)
    assert a.digest() == b.digest()


def test_a_frame_number_the_codec_cannot_store_still_fails_on_an_empty_step():
    with pytest.raises(Exception, match="format|argument|range"):
        InputHub([Fed("dev")]).drain(0x100000000)
