"""The curated public surface of authoring.mocurves."""

import authoring.mocurves as mocurves


def test_everything_exported_exists_and_nothing_private_leaks():
    assert len(set(mocurves.__all__)) == len(mocurves.__all__)
    for name in mocurves.__all__:
        assert hasattr(mocurves, name), name
        assert not name.startswith("_")
    assert {"EditSession", "TimeWarp", "solve_contacts", "save_session", "export_clip"} <= set(mocurves.__all__)
