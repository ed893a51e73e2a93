"""A match's process starts from a typed `Job`: forked children run it directly, exec'd
ones parse `job.argv()` with `arena run`; both must be the same job."""

from __future__ import annotations

import msgspec
import pytest

from arena.config import ProcessId
from arena.match.run import Job, run_job


def parsed(job: Job) -> Job:
    """`arena run` parses `job.argv()` back into a Job (what arena/commands/run.py hands to `start`)."""
    from arena.cli import parser

    a = parser().parse_args(job.argv())
    return Job(
        kind=a.kind,
        match=a.match,
        connect=(a.connect,) if a.connect else (),
        listen=(a.listen,) if a.listen else (),
        mode=a.mode,
        team=a.team,
        robot=a.robot,
        seed=a.seed,
        realtime=a.realtime,
        config=a.config,
        policy=a.policy,
        credentials=a.credentials,
        startup_timeout=a.startup_timeout,
        log_level=a.log_level,
        record=a.record,
        host=a.host,
        port=a.port,
    )


DEFAULTS = dict(mode="peer", startup_timeout=60.0, log_level="WARNING", host="127.0.0.1")


@pytest.mark.parametrize(
    "pid",
    [ProcessId("robot", "a", 0), ProcessId("basestation", "b"), ProcessId("engine"), ProcessId("recorder")],
)
def test_the_launchers_job_and_its_command_line_are_the_same_job(pid):
    job = run_job(pid, "m7-1-abc", "unixsock-stream//tmp/x/router.sock", "/tmp/x/config.json", "/tmp/m.mcap", "", "/c")
    assert parsed(job) == msgspec.structs.replace(job, **DEFAULTS)
    assert job.team == (pid.team or None) and (job.robot is None) == (pid.kind != "robot")
    assert (job.record is not None) == (pid.kind == "recorder")


def test_every_flag_survives_the_command_line():
    job = Job(
        kind="viewer",
        match="demo",
        connect=("tcp/10.0.0.5:7447",),
        mode="client",
        seed=3,
        realtime=True,
        credentials="viewer.json5",
        startup_timeout=5.0,
        log_level="DEBUG",
        host="0.0.0.0",
        port=9000,
    )
    assert parsed(job) == job


def test_a_job_crosses_to_a_zygote_child_unchanged():
    """The zygote gets the job as JSON (match/zygote.py)."""
    job = run_job(ProcessId("robot", "b", 2), "m", "tcp/127.0.0.1:7447", "/c.json", credentials="/k")
    assert msgspec.json.decode(msgspec.json.encode(msgspec.to_builtins(job)), type=Job) == job
