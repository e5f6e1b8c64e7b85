#!/usr/bin/env python3
"""A Foxglove WebSocket client for tests/live.rs, independent of wraptree's code.

Usage: python3 tests/foxglove_ws_client.py ws://HOST:PORT OUT.json [TIMEOUT_S [STOP_FILE]]

Connects with the `websockets` package, offering the subprotocol `foxglove.sdk.v1` (the name
the `foxglove` crate's server speaks; the same protocol as `foxglove.websocket.v1`), subscribes
to every channel the server advertises (also those advertised later), and decodes every message
with the protobuf schema its channel advertises (`google.protobuf`, from the FileDescriptorSet).
It stops once `/grouping/finish` has arrived, STOP_FILE (if given) exists, and nothing more has
come for one second, and writes OUT.json:

  {"subprotocol": ..., "server": name, "channels": {topic: schemaName},
   "messages": [[topic, log_time_ns, sha256 of the payload], ...],
   "merge_steps": [step, ...], "finish": {"root": r, "rounds": r, "merges": m}}

Exits 1 with `foxglove_ws_client: FAIL ...` on a protocol error, an undecodable message or a
timeout (default 120 s), 2 when a module is missing.
"""

import asyncio
import base64
import hashlib
import json
import os
import struct
import sys
import time

try:
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    from websockets.asyncio.client import connect
except ImportError as e:  # CI installs them; a missing module must not pass silently
    print(f"foxglove_ws_client: FAIL missing Python module ({e}); "
          "pip install websockets protobuf", file=sys.stderr)
    sys.exit(2)

QUIET_S = 1.0
MESSAGE_DATA = 0x01


def fail(msg):
    print(f"foxglove_ws_client: FAIL {msg}", file=sys.stderr)
    sys.exit(1)


def message_class(channel):
    """The protobuf class of a channel's advertised schema."""
    if channel.get("encoding") != "protobuf" or channel.get("schemaEncoding") != "protobuf":
        fail(f"{channel['topic']}: expected protobuf, got {channel}")
    fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    pool = descriptor_pool.DescriptorPool()
    pending = list(fds.file)
    while pending:  # add each file after its dependencies
        added = [f for f in pending if all(pool_has(pool, d) for d in f.dependency)]
        if not added:
            fail(f"{channel['topic']}: schema files with unresolved dependencies")
        for f in added:
            pool.Add(f)
            pending.remove(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(channel["schemaName"]))


def pool_has(pool, name):
    try:
        pool.FindFileByName(name)
        return True
    except KeyError:
        return False


async def run(url, out, timeout_s, stop_file):
    deadline = time.monotonic() + timeout_s
    async with connect(url, subprotocols=["foxglove.sdk.v1"], max_size=None,
                       open_timeout=timeout_s) as ws:
        channels, classes, subscriptions = {}, {}, {}
        server, messages, steps, finish = None, [], [], None
        finished = False
        last_frame = time.monotonic()
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                fail(f"timed out after {timeout_s} s ({len(messages)} messages, finish "
                     f"{'seen' if finished else 'not seen'})")
            try:
                frame = await asyncio.wait_for(ws.recv(), timeout=min(left, 0.1))
            except TimeoutError:
                told = stop_file is None or os.path.exists(stop_file)
                if finished and told and time.monotonic() - last_frame >= QUIET_S:
                    break
                continue
            last_frame = time.monotonic()
            if isinstance(frame, str):
                msg = json.loads(frame)
                op = msg.get("op")
                if op == "serverInfo":
                    server = msg.get("name")
                elif op == "advertise":
                    subs = []
                    for ch in msg["channels"]:
                        channels[ch["id"]] = ch
                        classes[ch["id"]] = message_class(ch)
                        sub = len(subscriptions) + 1
                        subscriptions[sub] = ch["id"]
                        subs.append({"id": sub, "channelId": ch["id"]})
                    await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
                elif op == "status" and msg.get("level", 0) >= 2:
                    fail(f"server error: {msg.get('message')}")
                continue
            if not frame or frame[0] != MESSAGE_DATA:
                continue
            sub, log_time = struct.unpack_from("<IQ", frame, 1)
            payload = frame[13:]
            if sub not in subscriptions:
                fail(f"message for unknown subscription {sub}")
            ch = subscriptions[sub]
            topic = channels[ch]["topic"]
            try:
                decoded = classes[ch].FromString(payload)
            except Exception as e:  # noqa: BLE001 - any decoding error fails the check
                fail(f"{topic}: message at {log_time} does not decode: {e}")
            messages.append([topic, log_time, hashlib.sha256(payload).hexdigest()])
            if topic == "/grouping/merge":
                steps.append(decoded.step)
            elif topic == "/grouping/finish":
                finish = {"root": decoded.root, "rounds": decoded.rounds,
                          "merges": decoded.merges}
                finished = True
        result = {
            "subprotocol": ws.subprotocol,
            "server": server,
            "channels": {c["topic"]: c["schemaName"] for c in channels.values()},
            "messages": messages,
            "merge_steps": steps,
            "finish": finish,
        }
    with open(out, "w") as f:
        json.dump(result, f)
    print(f"foxglove_ws_client: ok, {len(messages)} messages on {len(channels)} channels, "
          f"{len(steps)} merges")


def main():
    if len(sys.argv) not in (3, 4, 5):
        fail("usage: foxglove_ws_client.py ws://HOST:PORT OUT.json [TIMEOUT_S [STOP_FILE]]")
    timeout_s = float(sys.argv[3]) if len(sys.argv) >= 4 else 120.0
    stop_file = sys.argv[4] if len(sys.argv) == 5 else None
    asyncio.run(run(sys.argv[1], sys.argv[2], timeout_s, stop_file))


if __name__ == "__main__":
    main()
