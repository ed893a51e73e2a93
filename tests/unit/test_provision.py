"""Issues 34 and 36: a credentials directory provisioned once; no secret written unsafely or left behind."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest

from arena.config import ConfigError
from arena.runtime.credentials import OWNER, match_directory, sweep, write_private
from arena.runtime.provision import ROUTER_FILE, provision, rotate, show
from arena.schemas.keys import process_names

NAMES = process_names(2)


def _files(d):
    return {p.name: p.read_bytes() for p in sorted(d.iterdir())}


def test_a_second_provisioning_keeps_every_file_byte_for_byte(tmp_path):
    d = tmp_path / "creds"
    first, made = provision(d, NAMES, 2, "monday")
    assert ROUTER_FILE in made and "robot-a-1.json5" in made and "viewer.json5" in made
    before = _files(d)
    again, made = provision(d, NAMES, 2, "tuesday")  # another match, another id: the same secrets
    assert made == [] and _files(d) == before
    assert again.passwords == first.passwords and again.mac_keys == first.mac_keys
    assert again.ca_pem == first.ca_pem and again.router_key_pem == first.router_key_pem
    assert again.match == "tuesday", "the access control is made for the match that uses the set"
    assert all(p.stat().st_mode & 0o777 == 0o600 for p in d.iterdir()) and d.stat().st_mode & 0o777 == 0o700
    frag = json.loads((d / "robot-a-1.json5").read_text())
    assert frag["metadata"]["arena"]["credentials"] == first.set_id and "match" not in frag["metadata"]["arena"]


def test_only_what_is_missing_is_created(tmp_path):
    d = tmp_path / "creds"
    s, _ = provision(d, NAMES, 2)
    a1 = (d / "robot-a-1.json5").read_bytes()
    (d / "robot-b-0.json5").unlink()
    t, made = provision(d, process_names(3), 3)  # a lost file, and a third robot per team
    # and the files of whoever verifies the new robots' frames (every lockstep frame carries its
    # sender's MAC): the engine (their cmd), the base stations (their reports), recorder and viewer
    assert sorted(made) == [
        *("basestation-a.json5", "basestation-b.json5", "engine.json5", "recorder.json5"),
        *("robot-a-2.json5", "robot-b-0.json5", "robot-b-2.json5", "viewer.json5"),
    ]
    assert (d / "robot-a-1.json5").read_bytes() == a1 and t.passwords["robot/a/1"] == s.passwords["robot/a/1"]
    assert t.passwords["robot/b/0"] != s.passwords["robot/b/0"]


def test_rotate_one_principal_or_the_whole_set(tmp_path):
    d = tmp_path / "creds"
    s, _ = provision(d, NAMES, 2)
    a0, a1 = (d / "robot-a-0.json5").read_bytes(), (d / "robot-a-1.json5").read_bytes()
    assert "robot-a-1.json5" in rotate(d, ["robot/a/1"])
    assert (d / "robot-a-0.json5").read_bytes() == a0 and (d / "robot-a-1.json5").read_bytes() != a1
    rotate(d, [])
    assert (d / "robot-a-0.json5").read_bytes() != a0
    assert json.loads((d / ROUTER_FILE).read_text())["metadata"]["arena"]["credentials"] != s.set_id
    with pytest.raises(ConfigError, match="no credentials for robot/c/9"):
        rotate(d, ["robot/c/9"])
    a1 = (d / "robot-a-1.json5").read_bytes()
    assert "robot-a-1.json5" in rotate(d, ["robot/a/1", "robot/a/1"])  # left the file deleted, and exit 2
    assert (d / "robot-a-1.json5").read_bytes() != a1
    assert any("robot-a-1.json5: robot/a/1" in line for line in show(d))


def test_rotate_says_which_files_to_copy_again(tmp_path, capsys):
    from arena.cli import main

    assert main(["credentials", "init", str(tmp_path / "c"), "--robots", "2"]) == 0
    capsys.readouterr()
    assert main(["credentials", "rotate", str(tmp_path / "c"), "robot/a/1"]) == 0
    out = capsys.readouterr().out  # said "copy each robot's new file" of a rotation that changed base station a's
    assert "; copy basestation-a.json5, robot-a-1.json5 again to the computer each is on" in out, out


def test_a_smaller_match_or_a_rotation_leaves_every_other_robots_file_as_it_was(tmp_path):
    """The files are the set's (6 robots a team), not the match's: a 3v3 match once rewrote robot a/4's
    file without the engine's key, and a rotation (made for 0 robots) every robot's file."""
    d = tmp_path / "creds"
    provision(d, process_names(6), 6)
    before = _files(d)
    assert provision(d, process_names(3), 3, "friendly")[1] == []
    assert _files(d) == before
    made = rotate(d, ["robot/b/4"])
    assert [m for m in made if m.startswith("robot-")] == ["robot-b-4.json5"]
    after = _files(d)
    assert all(after[n] == before[n] for n in before if n.startswith("robot-") and n != "robot-b-4.json5")
    keys = json.loads(after["robot-b-4.json5"])["metadata"]["arena"]["keys"]
    assert {"engine", "basestation/b", "robot/b/4"} <= set(keys), keys


@pytest.mark.parametrize(
    ("spoil", "needle"),
    [
        (lambda d: (d / ROUTER_FILE).unlink(), "no router.json5"),
        (lambda d: (d / "robot-a-1.json5").write_text("{"), "not a credentials file"),
        (lambda d: os.chmod(d, 0o777), "writable by others"),
    ],
)
def test_a_spoilt_directory_is_one_line_naming_it(tmp_path, spoil, needle):
    d = tmp_path / "creds"
    provision(d, NAMES, 2)
    spoil(d)
    with pytest.raises(ConfigError, match=needle):
        provision(d, NAMES, 2)


def test_a_lost_router_file_is_recovered_by_rotate_as_init_says(tmp_path):
    """init said "run rotate" and rotate refused the same directory: now rotate makes the set anew,
    for the principals its files name, and every file changes."""
    d = tmp_path / "creds"
    provision(d, NAMES, 2)
    before = _files(d)
    (d / ROUTER_FILE).unlink()
    with pytest.raises(ConfigError, match="run arena credentials rotate"):
        provision(d, NAMES, 2)
    with pytest.raises(ConfigError, match="run arena credentials rotate"):
        rotate(d, ["robot/a/1"])  # one principal cannot be rotated without the set's router file
    made = rotate(d, [])
    after = _files(d)
    assert set(after) == set(before) == set(made)
    assert all(after[name] != before[name] for name in before)
    provision(d, NAMES, 2)  # whole again


def test_files_of_another_set_are_not_mixed_in(tmp_path):
    provision(tmp_path / "one", NAMES, 2)
    provision(tmp_path / "two", NAMES, 2)
    os.replace(tmp_path / "one" / "robot-a-1.json5", tmp_path / "two" / "robot-a-1.json5")
    with pytest.raises(ConfigError, match="belongs to credentials set"):
        provision(tmp_path / "two", NAMES, 2)


def test_a_private_file_is_new_0600_and_never_follows_a_planted_symlink(tmp_path):
    target = tmp_path / "elsewhere.txt"
    target.write_text("mine")
    path = tmp_path / "robot-a-1.json5"
    os.symlink(target, path)  # planted where the file goes
    (tmp_path / "robot-a-1.json5.part").symlink_to(target)  # and where the old code wrote first
    write_private(path, "secret\n")
    assert target.read_text() == "mine", "the password went through a symlink"
    assert not path.is_symlink() and path.read_text() == "secret\n" and path.stat().st_mode & 0o777 == 0o600
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere.txt", "robot-a-1.json5", "robot-a-1.json5.part"]


def test_the_next_start_removes_what_a_killed_maker_left(tmp_path, monkeypatch):
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    mine = match_directory("arena-t-")
    child = subprocess.Popen(
        [sys.executable, "-c", "from arena.runtime.credentials import match_directory as m; print(m('arena-t-'))"],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "TMPDIR": str(tmp_path)},
    )
    left = child.communicate(timeout=60)[0].strip()  # it exits without removing it: as if killed
    (tmp_path / left.rsplit("/", 1)[-1] / "router-users.txt").write_text("robot-a-1:pw\n")
    foreign = tmp_path / "arena-t-notours"
    foreign.mkdir()
    time.sleep(0.1)
    assert sweep("arena-t-") == [tmp_path / left.rsplit("/", 1)[-1]]
    assert mine.exists() and (mine / OWNER).exists(), "a live owner's directory stays"
    assert foreign.exists(), "a directory without an owner mark is not ours to remove"


def test_rotate_takes_the_short_form_external_takes(tmp_path, capfd):
    """`arena credentials rotate creds/ a/1` said "no credentials for a/1"; --external takes a/1."""
    from tests.integration.helpers import arena_in_process

    d = tmp_path / "creds"
    provision(d, NAMES, 2)
    a0, a1 = (d / "robot-a-0.json5").read_bytes(), (d / "robot-a-1.json5").read_bytes()
    r = arena_in_process(["credentials", "rotate", str(d), "a/1"], capfd)
    assert r.returncode == 0, r.stderr
    assert (d / "robot-a-1.json5").read_bytes() != a1 and (d / "robot-a-0.json5").read_bytes() == a0
    assert "copy basestation-a.json5, robot-a-1.json5 again" in r.stdout, r.stdout
