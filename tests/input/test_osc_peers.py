"""Stale and forged OSC peers: a silent phone gives its slot up; a forger of its address cannot starve it."""

from __future__ import annotations

from input.osc import ADMIT_AFTER, OscSource
from input.sample import CONNECT, DISCONNECT, PoseSample

PHONE = "osc:192.168.1.23"


def _samples(items: list) -> list[PoseSample]:  # type: ignore[type-arg]
    return [i for i in items if isinstance(i, PoseSample)]


def test_a_forger_of_the_phones_address_does_not_starve_it(osc) -> None:  # type: ignore[no-untyped-def]
    """Readings per step stay 1.0 (they fell to 0.12 when the forger spent the phone's budget)."""
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0)
    try:
        pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
        per_step = []
        for step in range(120):  # 2 s of a 60 Hz phone, one datagram a step, from its one UDP port
            now = step / 60
            if step >= 10:  # then a forger on the LAN: the phone's IP, other ports, 3,600 datagrams/s
                for k in range(60):
                    src.handle_datagram(b"\x00garbage", PHONE, now + k * 1e-5, 40000 + k % 7)
            src.handle_datagram(pose, PHONE, now + 1e-3, 50123)
            per_step.append(len(_samples(src.drain())))
        assert per_step[ADMIT_AFTER - 1 :] == [1] * (120 - ADMIT_AFTER + 1)
        assert src.status().drop_reasons["over budget"] > 0  # the forger spent a budget of its own
    finally:
        src.stop()


def test_a_silent_phone_gives_its_slot_to_the_next_valid_phone(osc) -> None:  # type: ignore[no-untyped-def]
    message, _ = osc
    src = OscSource(host="127.0.0.1", port=0, timeout=2.0)
    pose = message("/puppetphone/orientation", 1.0, 0.0, 0.0, 0.0)
    try:
        items = []
        for i in range(ADMIT_AFTER + 2):  # one datagram a step
            src.handle_datagram(pose, "osc:10.0.0.1", i / 60, 5000)
            items += src.drain()
        assert (CONNECT, "osc:10.0.0.1") in items
        src.handle_datagram(pose, "osc:10.0.0.2", 1.0, 5000)  # while the first phone plays: locked out
        assert src.status().locked_out == ["osc:10.0.0.2"]
        src._expire(0.1 + 2.01)  # the first phone froze: 2 s of silence
        assert (DISCONNECT, "osc:10.0.0.1") in src.drain()
        items = []
        for i in range(ADMIT_AFTER + 2):
            src.handle_datagram(pose, "osc:10.0.0.2", 2.2 + i / 60, 6000)
            items += src.drain()
        assert items[0] == (CONNECT, "osc:10.0.0.2") and {s.source for s in _samples(items)} == {"osc:10.0.0.2"}
        src.handle_datagram(pose, "osc:10.0.0.1", 2.4, 5000)  # the frozen phone comes back: now it waits
        assert "osc:10.0.0.1" in src.status().locked_out
    finally:
        src.stop()
