"""Opening a character: refusals a user understands, a joint map, and the set-up value a recording carries."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from engine.character.load import CharacterError, read_character
from engine.character.setup import character_setup, decode, encode


def test_a_four_legged_fox_is_refused_naming_the_roles_and_the_joint_map(mocap_dir: Path) -> None:
    """Broken by dropping the shape guess's reason from the message: the 'wider or longer' check fails."""
    with pytest.raises(CharacterError) as err:
        read_character(mocap_dir / "Fox.glb")
    text = str(err.value)
    assert "\n" not in text and text.startswith("Fox: not a humanoid")
    assert "all 17 roles without a joint" in text and "--joint-map FILE" in text and "l_upper_leg" in text
    assert "wider or longer than tall" in text and "b_Hip_01" in text


def test_a_gltf_with_outside_buffers_is_refused_saying_to_export_a_glb(mocap_dir: Path) -> None:
    with pytest.raises(CharacterError, match="one .glb file"):
        read_character(mocap_dir / "Fox.gltf")


def test_a_joint_map_names_the_roles_by_hand(mocap_dir: Path, tmp_path: Path) -> None:
    """The map a user writes (file joint → role) gives the same rig as the shape guess; one role left out is
    named. Broken by ignoring the map (the guess then fills it): the missing role is not reported."""
    guessed, _ = read_character(mocap_dir / "CesiumMan.glb")
    path = tmp_path / "map.json"
    path.write_text(json.dumps({v: k for k, v in guessed.roles.items()}))
    value = character_setup(str(mocap_dir / "CesiumMan.glb"), str(path))
    assert np.array_equal(decode(value).rig.skeleton.offsets, guessed.rig.skeleton.offsets)
    path.write_text(json.dumps({v: k for k, v in guessed.roles.items() if k != "neck"}))
    with pytest.raises(CharacterError, match="the roles neck without a joint"):
        character_setup(str(mocap_dir / "CesiumMan.glb"), str(path))
    path.write_text(json.dumps({"no_such_joint": "hips"}))
    with pytest.raises(CharacterError, match="does not have: no_such_joint"):
        character_setup(str(mocap_dir / "CesiumMan.glb"), str(path))


def test_the_setup_value_rebuilds_the_character_and_refuses_an_altered_one(mocap_dir: Path) -> None:
    """Broken by skipping the hash check: the altered bytes decode (or fail elsewhere) and the match fails."""
    data = (mocap_dir / "CesiumMan.glb").read_bytes()
    value = encode(data, "CesiumMan")
    character = decode(json.loads(json.dumps(value)))  # as a recording's JSON header carries it
    assert character.name == "CesiumMan" and len(character.binding.drivers) == 19
    import base64

    altered = dict(value, glb=base64.b64encode(data[:-4] + b"\0\0\0\0").decode())
    with pytest.raises(CharacterError, match="does not match its hash"):
        decode(altered)
    for bad in (
        [1],
        {"name": 1, "sha256": "", "glb": ""},
        dict(value, joint_map={"tail": "x"}),
        dict(value, glb="not base64!"),
    ):
        with pytest.raises(CharacterError):
            decode(bad)
