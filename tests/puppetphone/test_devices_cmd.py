from puppetphone.cli import main


def test_devices_lists_where_to_send_and_draws_a_qr(capsys):
    assert main(["devices", "--osc-port", "9555"]) == 0
    out = capsys.readouterr().out
    assert "send to port 9555" in out and "HID devices:" in out and "Serial ports:" in out
    if ":9555/" in out:  # a LAN address exists: the QR code follows
        assert "Scan to pair" in out and "█" in out


def test_devices_warns_about_a_loopback_bind(capsys):
    assert main(["devices", "--osc-host", "127.0.0.1", "--no-qr"]) == 0
    assert "--osc-host 0.0.0.0" in capsys.readouterr().out
