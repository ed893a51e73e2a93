"""Issue 20 item 7: a robot written from schemas/README.md alone plays robot a/1 of a real match.

tests/integration/readme_robot.py imports neither the project nor msgspec;
this test starts it with the arguments `arena match --external a/1` prints
and checks that the match accepted its Summary after recomputing its digest.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

from arena.schemas.vocabulary import REF_COMMANDS
from tests.integration.helpers import spawn, wait_for

CLIENT = Path(__file__).with_name("readme_robot.py")


def test_the_readme_client_imports_nothing_of_the_project():
    tree = ast.parse(CLIENT.read_text())
    imported = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module}
    assert imported <= {"__future__", "argparse", "hashlib", "hmac", "json", "os", "queue", "sys", "threading", "time",
                        "msgpack", "zenoh"}, imported  # fmt: skip


def test_a_client_written_from_the_readme_plays_robot_a1_and_its_digest_is_verified(tmp_path, reap):
    endpoint = f"unixsock-stream/{tmp_path}/router.sock"
    match = spawn("match", "--home", "BS", "--away", "BS", "--half-time", "10", "--seed", "4",
                  "--external", "a/1", "--match", "readme", "--listen", endpoint, "--json")  # fmt: skip
    reap.append(match)
    line = ""
    while not line.strip().startswith("arena run robot"):
        line = wait_for(lambda: match.stderr.readline(), 60, "the launcher's instructions")
    robot = subprocess.Popen([sys.executable, str(CLIENT), *line.split()[3:]],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
    reap.append(robot)
    out, err = match.communicate(timeout=240)
    r_out, r_err = robot.communicate(timeout=30)
    assert match.returncode == 0, err
    assert robot.returncode == 0, r_err
    result = json.loads(out)
    client = json.loads(r_out.strip().splitlines()[-1])
    assert result["outcome"] == "completed", result["outcome_reasons"]
    assert result["digests_verified"] == ["robot/a/1"]
    assert result["process_digests"]["robot/a/1"] == client["digest"]
    assert result["forged_summaries"] == {} and result["dead"] == []
    assert client["sent"] == {"robot/a/1/cmd": result["ticks"] + 1, "team/a/report/1": result["ticks"] // 5 + 1}
    assert result["sent_by_key"]["robot/a/1/cmd"] == result["ticks"] + 1
    # The README: the stages that occur on the wire, and only documented command names.
    assert client["stages"] == ["END_GAME", "FIRST_HALF", "SECOND_HALF"]
    assert {"FIRST_HALF", "KICKOFF", "HALF_TIME", "SECOND_HALF", "END_GAME", "GAMEOVER"} <= set(client["commands"])
    assert set(client["commands"]) <= REF_COMMANDS
    # It got `field` with a `get` (served by the engine for late joiners), not from the tick-0 put.
    assert client["field"]["total_ticks"] == result["ticks"] and client["field"]["robots_per_team"] == 3
