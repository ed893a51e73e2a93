"""A process started by hand reports the referee's last frame, which may come after its own last tick."""

from __future__ import annotations

import threading
import time

import msgspec

from arena.match.run import await_last_referee
from arena.schemas.messages import Referee


def frame(tick: int, stage: str) -> bytes:
    return msgspec.msgpack.encode(Referee(tick=tick, stage=stage, command="STOP"))


def test_the_last_frame_that_comes_late_is_waited_for():
    last_ref = [frame(295, "SECOND_HALF")]
    late = threading.Timer(0.1, lambda: last_ref[:1].clear() or last_ref.append(frame(300, "END_GAME")))
    late.start()
    t0 = time.monotonic()
    await_last_referee(last_ref, 300, timeout=10.0)
    assert time.monotonic() - t0 < 5.0 and msgspec.msgpack.decode(last_ref[-1], type=Referee).tick == 300
    late.join()


def test_the_wait_is_bounded_and_none_when_the_last_frame_is_there():
    last_ref = [frame(295, "SECOND_HALF")]
    t0 = time.monotonic()
    await_last_referee(last_ref, 300, timeout=0.2)
    assert 0.2 <= time.monotonic() - t0 < 5.0
    last_ref[:] = [frame(300, "END_GAME")]
    t0 = time.monotonic()
    await_last_referee(last_ref, 300, timeout=10.0)
    assert time.monotonic() - t0 < 1.0
