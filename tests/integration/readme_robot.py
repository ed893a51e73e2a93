"""A robot written from schemas/README.md alone: plain msgpack and zenoh, no arena imports.

It stands in for a C++ or Rust client and so must not import the project:
what it needs to know is what the README says (joining, the schedule, QoS,
the wheels, the configuration, the Summary, its digest and its MAC). It
drives every wheel at 0 rad/s, reports its sensed pose at every comm tick,
and publishes its Summary until the collector acknowledges it.

    python readme_robot.py --team a --robot 1 --match M --connect EP --credentials FILE

(the arguments of the command `arena match --external a/1` prints; others are ignored).
"""

from __future__ import annotations

import argparse
import hashlib
import hmac
import json
import os
import queue
import sys
import threading
import time

import msgpack
import zenoh

WHEELS = {"omni4": 4, "omni3": 3, "diff": 2}  # README, "Wheels"


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--team", required=True)
    ap.add_argument("--robot", type=int, required=True)
    ap.add_argument("--match", required=True)
    ap.add_argument("--connect", required=True)
    ap.add_argument("--credentials", required=True)
    args, _ = ap.parse_known_args(argv)
    me = f"robot/{args.team}/{args.robot}"
    prefix = f"arena/{args.match}/"

    # Security: the credentials file is a zenoh configuration; add only the router's endpoint.
    with open(args.credentials) as f:
        creds = json.load(f)
    keys = {p: bytes.fromhex(k) for p, k in creds["metadata"]["arena"]["keys"].items()}
    mac_key = keys[me]
    conf = zenoh.Config.from_file(args.credentials)
    conf.insert_json5("mode", '"client"')
    conf.insert_json5("connect/endpoints", json.dumps([args.connect]))
    conf.insert_json5("scouting/multicast/enabled", "false")

    def mac(key: str, payload: bytes, sender_key: bytes = mac_key) -> bytes:
        return hashlib.blake2b(key.encode() + b"\x00" + payload, key=sender_key, digest_size=16).digest()

    sense_key = f"{prefix}robot/{args.team}/{args.robot}/sense"
    forged = [0]

    def on_sense(sample: zenoh.Sample) -> None:
        """Only the engine's frames: a sense whose MAC is not the engine's is dropped and counted."""
        payload = sample.payload.to_bytes()
        attachment = sample.attachment.to_bytes() if sample.attachment is not None else b""
        if hmac.compare_digest(attachment, mac(sense_key, payload, keys["engine"])):
            senses.put(payload)
        else:
            forged[0] += 1

    session = zenoh.open(conf)
    try:
        senses: queue.Queue[bytes] = queue.Queue()
        acked = threading.Event()
        collector = threading.Event()

        def on_collector(sample: zenoh.Sample) -> None:
            (collector.set if sample.kind == zenoh.SampleKind.PUT else collector.clear)()

        stages: set[str] = set()
        commands: set[str] = set()

        ended = threading.Event()  # the referee's frame of tick total_ticks: END_GAME

        def on_referee(sample: zenoh.Sample) -> None:
            ref = msgpack.unpackb(sample.payload.to_bytes())
            stages.add(ref["stage"])
            if ref["stage"] == "END_GAME":
                ended.set()
            commands.update(c["name"] for c in ref.get("commands", []))

        keep = [
            session.declare_subscriber(f"{prefix}referee", on_referee),  # public: what the README says occurs
            session.declare_subscriber(sense_key, on_sense),
            session.declare_subscriber(f"{prefix}ack/{me}", lambda s: acked.set()),
            session.liveliness().declare_subscriber(f"{prefix}collector", on_collector, history=True),
        ]
        qos = {
            "encoding": zenoh.Encoding("application/msgpack"),
            "congestion_control": zenoh.CongestionControl.BLOCK,
            "reliability": zenoh.Reliability.RELIABLE,
            "priority": zenoh.Priority.DATA,
            "express": False,
        }
        cmd_key = f"robot/{args.team}/{args.robot}/cmd"
        report_key = f"team/{args.team}/report/{args.robot}"
        pubs = {k: session.declare_publisher(prefix + k, **qos) for k in (cmd_key, report_key)}
        summary_key = f"{prefix}summary/{me}"
        summary_pub = session.declare_publisher(summary_key, **qos)

        # Configuration: the engine's queryable.
        cfg = None
        deadline = time.monotonic() + 60
        while cfg is None and time.monotonic() < deadline:
            for reply in session.get(f"{prefix}config", timeout=2.0):
                if reply.ok is not None:
                    cfg = json.loads(reply.ok.payload.to_bytes().decode())
                    break
            else:
                time.sleep(0.2)
        if cfg is None:
            print("readme_robot: no configuration", file=sys.stderr)
            return 1
        total_ticks = 2 * round(cfg["half_time"] / cfg["timing"]["dt"])
        # `field` is also served (what a late joiner does): its total_ticks must agree.
        field = None
        for reply in session.get(f"{prefix}field", timeout=5.0):
            if reply.ok is not None:
                field = msgpack.unpackb(reply.ok.payload.to_bytes())
        if field is None or field["total_ticks"] != total_ticks:
            print(f"readme_robot: field {field} disagrees with the configuration", file=sys.stderr)
            return 1
        comm = cfg["timing"]["comm_period"]
        wheels = [0.0] * WHEELS[cfg["robot"]["model"]]
        keep.append(session.liveliness().declare_token(f"{prefix}alive/{me}"))

        digest = hashlib.blake2b(digest_size=16)
        sent = {cmd_key: 0, report_key: 0}

        def put(key: str, msg: dict) -> None:
            payload = msgpack.packb(msg)
            digest.update(key.encode())
            digest.update(len(payload).to_bytes(4, "little"))
            digest.update(payload)
            sent[key] += 1
            pubs[key].put(payload, attachment=mac(prefix + key, payload))  # README, "Message authentication"

        latency = cfg["timing"]["perception_latency"]  # L: at tick k the robot sees the sense of tick k - L
        wait = cfg["timing"]["startup_timeout"] + cfg["timing"]["wait_timeout"]
        rejected: dict[str, int] = {}

        def bad(reason: str) -> None:
            rejected[reason] = rejected.get(reason, 0) + 1

        pose = {"x": 0.0, "y": 0.0, "theta": 0.0}  # no sense before tick L
        expected = 0  # the tick of the next sense frame
        for k in range(total_ticks + 1):
            while expected <= k - latency:
                try:
                    raw = senses.get(timeout=wait)
                except queue.Empty:
                    print(f"readme_robot: no sense for tick {expected}", file=sys.stderr)
                    return 1
                try:
                    got = msgpack.unpackb(raw)
                    # A batch: an array of the frames' bytes; a frame: a map.
                    frames = [msgpack.unpackb(f) for f in got] if isinstance(got, list) else [got]
                    ticks = [f["tick"] for f in frames]
                except Exception:
                    bad("malformed")
                    continue
                for sense, tick in zip(frames, ticks):
                    if tick != expected:
                        bad("out_of_sequence")
                        continue
                    pose = sense["pose"]
                    expected += 1
            put(cmd_key, {"tick": k, "mode": "wheels", "wheels": wheels})
            if k % comm == 0:
                put(report_key, {"tick": k, "robot": args.robot, "pose": pose, "role": "readme"})

        summary = {
            "tick": total_ticks,
            "process": me,
            "pid": os.getpid(),
            "digest": digest.hexdigest(),
            "sent": sum(sent.values()),
            "rejected": sum(rejected.values()) + forged[0],
            "rejected_reasons": rejected | ({"forged": forged[0]} if forged[0] else {}),
            "sent_by_key": sent,
            "extra": {"client": "readme_robot"},
        }
        payload = msgpack.packb(summary)
        attachment = mac(summary_key, payload)
        give_up = time.monotonic() + 5.0
        while True:
            summary_pub.put(payload, attachment=attachment)
            if not collector.is_set() or acked.wait(0.25) or time.monotonic() > give_up:
                break
        # Our last tick can come before the referee's last frame (schemas/README.md): wait for it. The
        # referee sends it at tick total_ticks in every match that ends; 30 s bounds a void one only.
        ended.wait(30.0)
        print(
            json.dumps(
                {
                    "digest": summary["digest"],
                    "sent": sent,
                    "acked": acked.is_set(),
                    "field": field,
                    "stages": sorted(stages),
                    "commands": sorted(commands),
                }
            )
        )
        for entity in reversed(keep):
            entity.undeclare()
        return 0 if acked.is_set() or not collector.is_set() else 1
    finally:
        session.close()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
