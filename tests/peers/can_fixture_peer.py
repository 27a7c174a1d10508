#!/usr/bin/python3
"""An independent CAN peer for the fixture frame map (deploy/OPERATIONS.md "Fixture over CAN"), on
python3-can's socketcan interface. The frame layout is written out here from deploy/OPERATIONS.md,
not taken from our code, so a drift between the two fails the tests.

  node IFNAME [--node-id N] [--pressure-counts C] [--heartbeat-stops-after-ms T]
              [--malformed-status] [--run-s S]
      plays a fixture controller: status frame 0x180+N every 50 ms and at once after a
      command, heartbeat 0x700+N every 100 ms; applies command frames 0x200+N (clamped
      follows clamp_cmd after 0.1 s); prints "ready", then one JSON line per command frame
      received: {"id", "data": [bytes]}.

  client IFNAME [--node-id N]
      talks to a fixture node: waits for status and heartbeat, commands clamp + phase pair
      V-W + lamp_pass, waits until clamped, then releases; prints one JSON object with what
      it saw.
"""
import argparse
import json
import sys
import time

import can

NMT_OPERATIONAL = 0x05


def status_bytes(clamped, released, part, door, estop, outputs, pair, pressure_counts, counter):
    b0 = clamped | released << 1 | part << 2 | door << 3 | estop << 4
    b1 = outputs["clamp"] | outputs["excitation"] << 1 | outputs["lamp_pass"] << 2 | \
        outputs["lamp_fail"] << 3
    return bytes([b0, b1, pair, pressure_counts & 0xFF, pressure_counts >> 8, counter & 0xFF])


def run_node(a):
    bus = can.Bus(interface="socketcan", channel=a.ifname,
                  can_filters=[{"can_id": 0x200 + a.node_id, "can_mask": 0x7FF,
                                "extended": False}])
    outputs = {"clamp": 0, "excitation": 0, "lamp_pass": 0, "lamp_fail": 0}
    pair = 0
    clamp_at = None
    counter = 0
    beat = 0
    start = time.monotonic()
    next_status = start
    next_beat = start
    print("ready", flush=True)

    def send_status():
        nonlocal counter
        now = time.monotonic()
        clamped = int(outputs["clamp"] and clamp_at is not None and now - clamp_at >= 0.1)
        released = int(not outputs["clamp"])
        data = status_bytes(clamped, released, 1, 1, 1, outputs, pair,
                            a.pressure_counts if clamped else 0, counter)
        if a.malformed_status:
            data = data[:3]
        bus.send(can.Message(arbitration_id=0x180 + a.node_id, is_extended_id=False, data=data))
        counter += 1

    while time.monotonic() - start < a.run_s:
        msg = bus.recv(timeout=0.01)
        now = time.monotonic()
        if msg is not None and not msg.is_error_frame and not msg.is_remote_frame:
            print(json.dumps({"id": msg.arbitration_id, "data": list(msg.data)}), flush=True)
            if len(msg.data) == 4 and msg.data[1] <= 2:
                b0 = msg.data[0]
                if (b0 & 1) and not outputs["clamp"]:
                    clamp_at = now
                outputs = {"clamp": b0 & 1, "excitation": b0 >> 1 & 1,
                           "lamp_pass": b0 >> 2 & 1, "lamp_fail": b0 >> 3 & 1}
                pair = msg.data[1]
                send_status()
                next_status = now + 0.05
        if now >= next_status:
            send_status()
            next_status = now + 0.05
        beats_allowed = a.heartbeat_stops_after_ms < 0 or \
            (now - start) * 1000 < a.heartbeat_stops_after_ms
        if now >= next_beat and beats_allowed:
            bus.send(can.Message(arbitration_id=0x700 + a.node_id, is_extended_id=False,
                                 data=bytes([NMT_OPERATIONAL, beat & 0xFF])))
            beat += 1
            next_beat = now + 0.1
    bus.shutdown()


def run_client(a):
    node = a.node_id
    bus = can.Bus(interface="socketcan", channel=a.ifname,
                  can_filters=[{"can_id": 0x180 + node, "can_mask": 0x7FF, "extended": False},
                               {"can_id": 0x700 + node, "can_mask": 0x7FF, "extended": False}])
    seen = {"status_dlc": None, "heartbeats": [], "nmt_state": None}

    def decode(m):
        d = m.data
        return {"clamped": d[0] & 1, "released": d[0] >> 1 & 1, "part_present": d[0] >> 2 & 1,
                "door_closed": d[0] >> 3 & 1, "estop_ok": d[0] >> 4 & 1,
                "clamp_echo": d[1] & 1, "excitation_echo": d[1] >> 1 & 1,
                "lamp_pass_echo": d[1] >> 2 & 1, "lamp_fail_echo": d[1] >> 3 & 1,
                "phase_pair_echo": d[2], "pressure_counts": d[3] | d[4] << 8, "counter": d[5]}

    def wait_status(pred, timeout_s):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            m = bus.recv(timeout=0.05)
            if m is None:
                continue
            if m.arbitration_id == 0x700 + node:
                seen["heartbeats"].append(m.data[1])
                seen["nmt_state"] = m.data[0]
                continue
            seen["status_dlc"] = m.dlc
            if m.dlc != 6:
                continue
            s = decode(m)
            if pred(s):
                return s
        return None

    def command(b0, pair, counter):
        bus.send(can.Message(arbitration_id=0x200 + node, is_extended_id=False,
                             data=bytes([b0, pair, counter, counter])))  # alive: the counter

    out = {"first": wait_status(lambda s: True, 5.0)}
    command(0x01 | 0x04, 1, 1)  # clamp_cmd + lamp_pass, phase pair V-W
    out["echo"] = wait_status(lambda s: s["clamp_echo"] == 1, 2.0)
    out["clamped"] = wait_status(lambda s: s["clamped"] == 1, 5.0)
    command(0x00, 1, 2)  # release
    out["released"] = wait_status(lambda s: s["released"] == 1, 5.0)
    wait_status(lambda s: False, 0.5)  # collect heartbeats
    out["status_dlc"] = seen["status_dlc"]
    out["heartbeats"] = seen["heartbeats"]
    out["nmt_state"] = seen["nmt_state"]
    bus.shutdown()
    print(json.dumps(out), flush=True)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("mode", choices=["node", "client"])
    p.add_argument("ifname")
    p.add_argument("--node-id", type=int, default=1)
    p.add_argument("--pressure-counts", type=int, default=550)
    p.add_argument("--heartbeat-stops-after-ms", type=int, default=-1)
    p.add_argument("--malformed-status", action="store_true")
    p.add_argument("--run-s", type=float, default=30.0)
    a = p.parse_args()
    run_node(a) if a.mode == "node" else run_client(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
