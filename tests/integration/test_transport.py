"""The zenoh transport itself, in one process over a real session."""

from __future__ import annotations

import threading
import time

from arena.runtime.session import NetConfig, open_session
from arena.runtime.transport import ZenohTransport
from tests.integration.helpers import wait_for


def test_a_callback_thread_keeps_its_python_thread_state(tmp_path):
    """zenoh enters Python from its own thread for every sample; the thread keeps one state.

    Without `keep_thread_state` each callback ran in a fresh thread state (an
    mmap and a munmap per message), and a `threading.local` set in one
    callback was gone in the next.
    """
    local = threading.local()
    seen: list[tuple[int, int]] = []
    done = threading.Event()

    def on_frame(payload: bytes) -> None:
        local.count = getattr(local, "count", 0) + 1
        seen.append((threading.get_native_id(), local.count))
        if len(seen) == 20:
            done.set()

    endpoint = f"unixsock-stream/{tmp_path}/s.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(endpoint,))) as receiver,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as sender,
    ):
        rx, tx = ZenohTransport(receiver), ZenohTransport(sender)
        rx.subscribe_callback("arena/t/x", on_frame)
        put = tx.publisher("arena/t/x")
        deadline = time.monotonic() + 10
        i = 0
        while not done.is_set() and time.monotonic() < deadline:
            put(bytes([i % 256]))
            i += 1
            time.sleep(0.005)
        assert done.is_set(), f"only {len(seen)} samples arrived"
        tx.close()
        rx.close()
    assert threading.get_native_id() not in {t for t, _ in seen}, "delivered on zenoh's own thread"
    counts: dict[int, list[int]] = {}
    for thread, count in seen:
        counts.setdefault(thread, []).append(count)
    for thread, got in counts.items():
        assert got == list(range(1, len(got) + 1)), f"thread {thread} lost its state between callbacks: {got}"


def test_close_while_zenohs_thread_is_inside_a_put_does_not_raise(tmp_path):
    """Issue 20 item 6: SIGTERM during a callback's blocked put crashed with `RuntimeError: Already borrowed`."""
    sock = f"unixsock-stream/{tmp_path}/borrow.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(sock,))) as a,
        open_session(NetConfig(mode="peer", connect=(sock,))) as b,
    ):
        stall, stop = threading.Event(), threading.Event()
        sub = b.declare_subscriber("arena/borrow/k", lambda s: stall.wait(20))
        tr = ZenohTransport(a)
        put = tr.publisher("arena/borrow/k")  # BLOCK, towards a receiver that does not read
        # Its declaration has reached the publisher (else the puts go nowhere and never block).
        wait_for(lambda: tr.has_subscribers("arena/borrow/k"), 30, "the subscriber's declaration")
        puts = [0]

        def flood() -> None:
            while not stop.is_set():
                put(b"x" * 60000)
                puts[0] += 1

        t = threading.Thread(target=flood, daemon=True)
        t.start()
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and puts[0] < 3:
            time.sleep(0.05)
        time.sleep(0.5)  # the queue is full by now: the flood thread sits inside `put`
        try:
            tr.close()  # raised RuntimeError: Already borrowed
        finally:
            stop.set()
            stall.set()
            t.join(timeout=10)
            sub.undeclare()


def test_a_served_key_answers_an_ask_with_its_last_frame_and_nothing_before_one(tmp_path):
    """How the live viewer reads what the teams believe (runtime/node.py `SERVED`, processes/viewer.py)."""
    from arena.runtime.lockstep import Latest

    endpoint = f"unixsock-stream/{tmp_path}/ask.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(endpoint,))) as robot,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as viewer,
    ):
        tx, rx = ZenohTransport(robot), ZenohTransport(viewer)
        latest = Latest().wrap(tx.publisher("arena/t/team/a/report/0"))
        tx.serve("arena/t/team/a/report/0", latest.get)
        querier = viewer.declare_querier("arena/t/team/a/report/0")  # says when the queryable is known
        wait_for(lambda: querier.matching_status.matching, 30, "the queryable's declaration at the viewer")
        querier.undeclare()
        answers: list[bytes] = []
        rx.ask("arena/t/team/a/report/0", answers.append, 2.0)
        time.sleep(0.5)
        assert answers == [], "nothing sent yet: no answer"
        for frame in (b"r1", b"r2"):
            latest(frame)
        got = threading.Event()
        rx.ask("arena/t/team/a/report/0", lambda p: (answers.append(p), got.set()), 2.0)
        assert got.wait(5.0) and answers == [b"r2"]
        tx.close()
        rx.close()


def test_a_query_takes_only_the_answer_with_the_servers_mac_and_counts_every_other(tmp_path):
    """How a process started by hand takes its configuration (match/run.py `fetch_config`): a
    stranger's queryable answered first, and its `"home": "policy:/some/file.pkl"` was played."""
    from arena.runtime.mac import Keyring, new_key

    key = "arena/t/config"
    engine_key = new_key()
    endpoint = f"unixsock-stream/{tmp_path}/q.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(endpoint,))) as engine,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as stranger,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as robot,
    ):
        tx = ZenohTransport(engine, Keyring("engine", {"engine": engine_key}))
        tx.serve(key, b"genuine", sign=tx.keyring.signer(key))
        liar = ZenohTransport(stranger)
        liar.serve(key, b"forged")  # no MAC: it has no key
        liar.serve(key, b"forged", sign=Keyring("engine", {"engine": new_key()}).signer(key))  # a wrong one
        rx = ZenohTransport(robot, Keyring("robot/a/0", {"engine": engine_key}))
        forged: list[int] = []
        verify = rx.keyring.verifier("engine", key)
        deadline = time.monotonic() + 10
        got = None
        # the three queryables reach the robot's session one by one: ask until all three answer
        while not (got == b"genuine" and len(forged) == 2) and time.monotonic() < deadline:
            forged.clear()
            got = rx.query(key, 2.0, verify=verify, on_forged=lambda: forged.append(1))
        assert got == b"genuine" and len(forged) == 2, "both of the stranger's answers were looked at and counted"
        assert rx.query(key, 2.0) in (b"genuine", b"forged"), "without a key: the first answer, whoever's"
        for t in (tx, liar, rx):
            t.close()


def test_a_process_with_the_engines_key_never_takes_a_strangers_configuration(tmp_path):
    """Only strangers answer: the process gives up, and says how many answers it ignored and why."""
    import pytest

    from arena.config import MatchConfig
    from arena.match.run import fetch_config
    from arena.runtime.mac import Keyring, new_key
    from arena.runtime.node import StartupError
    from arena.schemas.keys import Keys

    keys = Keys("t")
    endpoint = f"unixsock-stream/{tmp_path}/c.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(endpoint,))) as stranger,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as robot,
    ):
        liar = ZenohTransport(stranger)
        liar.serve(keys.config(), MatchConfig(home="policy:/some/file.pkl").to_json().encode())
        rx = ZenohTransport(robot, Keyring("robot/a/0", {"robot/a/0": new_key(), "engine": new_key()}))
        forged = [0]
        with pytest.raises(StartupError, match=r"ignored \d+ answer\(s\) without the engine's MAC"):
            fetch_config(rx, keys, 2.5, forged=forged)
        assert forged[0] >= 1
        for t in (liar, rx):
            t.close()


def test_a_viewers_only_key_is_put_only_while_someone_subscribes(tmp_path):
    """`publisher(when_matched=True)` (the engine's `world`): nothing is signed or put while nobody
    subscribes; once a subscriber comes, its frames arrive. zenoh's MatchingStatus object is always
    true: taken for the flag itself, every frame was signed and put to nobody."""
    signed: list[bytes] = []
    got: list[bytes] = []

    def sign(payload: bytes) -> bytes:
        signed.append(payload)
        return b"mac"

    endpoint = f"unixsock-stream/{tmp_path}/s.sock"
    with (
        open_session(NetConfig(mode="peer", listen=(endpoint,))) as sender,
        open_session(NetConfig(mode="peer", connect=(endpoint,))) as viewer,
    ):
        tx, rx = ZenohTransport(sender), ZenohTransport(viewer)
        put = tx.publisher("arena/w/world", when_matched=True, sign=sign)
        time.sleep(0.3)  # the sessions are linked: a subscriber now would be known
        for i in range(20):
            put(bytes([i]))
        assert signed == [], "nobody subscribes: nothing signed, nothing put"
        rx.subscribe_callback("arena/w/world", got.append)

        def arrived() -> bool:
            put(b"x")
            return bool(got)

        wait_for(arrived, 10, "a frame for the subscriber")
        assert signed and got[0] == b"x"
        tx.close()
        rx.close()
