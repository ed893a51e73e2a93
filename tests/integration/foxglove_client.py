"""A Foxglove WebSocket client written from the protocol, for the viewer's tests.

It implements the `foxglove.websocket.v1` subprotocol itself on the
`websockets` package: JSON text ops (`serverInfo`, `advertise`, `subscribe`,
`setParameters`, `parameterValues`) and binary server frames (opcode 0x01
message data: u32 subscription id, u64 log time, payload; opcode 0x02 time).
Payloads are decoded by a small protobuf wire-format reader, enough to count a
`foxglove.SceneUpdate`'s entities and read a `foxglove.Log`: no foxglove code
is used on this side, so the server is checked against the protocol.

Also a command, to keep a viewer busy while a match is measured:

    python -m tests.integration.foxglove_client ws://127.0.0.1:8765 --topic /scene
"""

from __future__ import annotations

import argparse
import json
import struct
import time

from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

# The protocol is foxglove.websocket.v1. foxglove-sdk 0.30's server accepts it only under its newer
# name `foxglove.sdk.v1` (measured: a handshake offering only `foxglove.websocket.v1` gets HTTP 400
# "Missing expected sec-websocket-protocol header"), so the client offers both, the old name first.
SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]


def pb_fields(buf: bytes) -> list[tuple[int, int, object]]:
    """(field number, wire type, value) of one protobuf message; length-delimited values stay bytes."""
    out, i, n = [], 0, len(buf)
    while i < n:
        key, i = _varint(buf, i)
        num, wt = key >> 3, key & 7
        if wt == 0:
            v, i = _varint(buf, i)
        elif wt == 1:
            v, i = struct.unpack_from("<d", buf, i)[0], i + 8
        elif wt == 2:
            ln, i = _varint(buf, i)
            v, i = buf[i : i + ln], i + ln
        elif wt == 5:
            v, i = struct.unpack_from("<f", buf, i)[0], i + 4
        else:
            raise ValueError(f"protobuf wire type {wt}")
        out.append((num, wt, v))
    return out


def _varint(buf: bytes, i: int) -> tuple[int, int]:
    shift = result = 0
    while True:
        b = buf[i]
        i += 1
        result |= (b & 0x7F) << shift
        if not b & 0x80:
            return result, i
        shift += 7


def scene_entities(payload: bytes) -> list[str]:
    """The entity ids of a foxglove.SceneUpdate (entities = field 2, SceneEntity.id = field 3)."""
    ids = []
    for num, _, v in pb_fields(payload):
        if num == 2:
            ids += [e.decode() for n, _, e in pb_fields(v) if n == 3]
    return ids


def log_entry(payload: bytes) -> dict:
    """A foxglove.Log: level (2), message (3), name (4)."""
    d = {num: v for num, _, v in pb_fields(payload)}
    return {"level": d.get(2, 0), "message": d.get(3, b"").decode(), "name": d.get(4, b"").decode()}


class FoxgloveClient:
    def __init__(self, url: str, timeout: float = 30.0):
        deadline = time.monotonic() + timeout
        while True:
            try:
                self.ws = connect(url, subprotocols=SUBPROTOCOLS, max_size=None, open_timeout=5, legacy=True)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        assert self.ws.subprotocol in SUBPROTOCOLS
        self.info: dict = {}
        self.channels: dict[str, dict] = {}
        self.topic_of: dict[int, str] = {}  # subscription id -> topic
        self.parameters: dict[str, object] = {}
        self.time_ns = 0
        self._next_sub = 1
        while "/scene" not in self.channels or not self.info:
            self._handle(self.ws.recv(timeout=timeout))

    def _handle(self, frame):
        """One frame in: JSON ops update the client's state; message data is returned."""
        if isinstance(frame, str):
            op = json.loads(frame)
            if op["op"] == "serverInfo":
                self.info = op
            elif op["op"] == "advertise":
                for ch in op["channels"]:
                    self.channels[ch["topic"]] = ch
            elif op["op"] == "parameterValues":
                for p in op["parameters"]:
                    self.parameters[p["name"]] = p.get("value")
            return None
        if frame[0] == 0x01:
            sub, ts = struct.unpack_from("<IQ", frame, 1)
            return self.topic_of.get(sub, "?"), ts, bytes(frame[13:])
        if frame[0] == 0x02:
            self.time_ns = struct.unpack_from("<Q", frame, 1)[0]
        return None

    def subscribe(self, *topics: str) -> None:
        subs = []
        for t in topics:
            subs.append({"id": self._next_sub, "channelId": self.channels[t]["id"]})
            self.topic_of[self._next_sub] = t
            self._next_sub += 1
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def set_parameters(self, **values) -> None:
        params = [{"name": k, "value": v} for k, v in values.items()]
        self.ws.send(json.dumps({"op": "setParameters", "parameters": params, "id": f"set-{time.monotonic_ns()}"}))

    def advertise(self, topic: str, schema_name: str = "") -> int:
        """Advertise a client channel (the server's ClientPublish); returns its id."""
        cid = self._next_sub
        self._next_sub += 1
        ch = {"id": cid, "topic": topic, "encoding": "json", "schemaName": schema_name}
        self.ws.send(json.dumps({"op": "advertise", "channels": [ch]}))
        return cid

    def publish(self, channel_id: int, payload: bytes) -> None:
        """Client message data: opcode 0x01, the channel id, the payload."""
        self.ws.send(struct.pack("<BI", 0x01, channel_id) + payload)

    def messages(self, seconds: float, until=None):
        """Yield (topic, log time, payload) for `seconds`, or until the server closes, or until
        `until()` holds after a frame has been handled (a `parameterValues` reply, say)."""
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            try:
                got = self._handle(self.ws.recv(timeout=left))
            except TimeoutError:
                return
            except ConnectionClosed:
                return
            if got is not None:
                yield got
            if until is not None and until():
                return

    def close(self) -> None:
        self.ws.close()


def main() -> int:
    ap = argparse.ArgumentParser(description="subscribe to a Foxglove server's topics and count what comes")
    ap.add_argument("url")
    ap.add_argument("--topic", action="append", default=[])
    ap.add_argument("--seconds", type=float, default=3600.0)
    args = ap.parse_args()
    c = FoxgloveClient(args.url, timeout=120.0)
    c.subscribe(*(args.topic or ["/scene"]))
    n = sum(1 for _ in c.messages(args.seconds))
    print(json.dumps({"messages": n}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
