from input.pairing import PairingInfo, lan_addresses, pairing_info, qr_ascii


def test_lines_name_addresses_devices_and_the_bind_warning():
    info = PairingInfo(
        port=9000,
        bind_host="127.0.0.1",
        addresses=["192.168.1.5"],
        hid_devices=[{"name": "DualSense", "vendor_id": 0x054C, "product_id": 0x0CE6, "kind": "dualsense"}],
        serial_ports=[{"device": "/dev/ttyUSB0", "description": "CP2102"}],
    )
    text = "\n".join(info.lines())
    assert "192.168.1.5" in text and "osc.udp://192.168.1.5:9000/" in text
    assert "DualSense [054c:0ce6]" in text and "/dev/ttyUSB0" in text
    assert "--osc-host 0.0.0.0" in text
    assert PairingInfo(port=9000, bind_host="0.0.0.0", addresses=[]).note == ""


def test_pairing_info_and_qr_are_real():
    info = pairing_info(port=9123)
    assert info.port == 9123 and all(not a.startswith("127.") for a in info.addresses)
    assert info.addresses == lan_addresses()
    qr = qr_ascii("osc.udp://10.0.0.2:9000/")
    rows = qr.splitlines()
    assert len(rows) > 10 and len({len(r) for r in rows if r}) == 1 and "█" in qr
