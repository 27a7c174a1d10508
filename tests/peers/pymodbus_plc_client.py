#!/usr/bin/python3
"""The line PLC, played by an independent Modbus client (pymodbus 3.0), for the tests of the
station's PLC handshake (station/daemon/plc/plc_map.h).

The operations of pymodbus_fixture_client.py (read_coils, read_di, read_hr, read_ir,
write_coil, write_hr, write_coils, write_hrs, sleep), plus what a PLC program does:

  ["write_text", address, count, "SN-1"]   the text into `count` holding registers, two
                                           characters per register, high byte first, NUL
                                           padded (written here independently of the station)
  ["wait_coil", address, value, timeout_s] poll (every 20 ms) until the coil reads `value`
  ["wait_di", address, value, timeout_s]   the same for a discrete input

A wait answers {"op", "ok": true, "waited_s": s} or {"op", "error": "timeout ..."}.
Prints one JSON list with one result per operation, as pymodbus_fixture_client.py does, and
closes the connection when the list is done (a PLC that disconnects).
"""

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pymodbus.client import ModbusTcpClient  # noqa: E402

from pymodbus_fixture_client import run_op  # noqa: E402


def encode_text(text, count):
    data = text.encode("ascii")
    if len(data) > 2 * count:
        sys.exit(f"{text!r} does not fit {count} registers")
    data = data + b"\0" * (2 * count - len(data))
    return [(data[2 * i] << 8) | data[2 * i + 1] for i in range(count)]


def wait_bit(client, op, unit):
    name, address, value, timeout_s = op[0], op[1], op[2], float(op[3])
    read = client.read_coils if name == "wait_coil" else client.read_discrete_inputs
    t0 = time.monotonic()
    while True:
        rsp = read(address, 1, slave=unit)
        if not rsp.isError() and int(rsp.bits[0]) == int(value):
            return {"op": name, "ok": True, "waited_s": round(time.monotonic() - t0, 3)}
        if time.monotonic() - t0 > timeout_s:
            return {"op": name, "error": f"timeout after {timeout_s} s waiting for "
                                         f"{address} == {value} (last answer {rsp})"}
        time.sleep(0.02)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tcp", required=True, help="HOST:PORT")
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--ops", required=True, help="JSON list of operations")
    args = p.parse_args()
    host, port = args.tcp.rsplit(":", 1)
    client = ModbusTcpClient(host, port=int(port), timeout=2, retries=0)
    if not client.connect():
        sys.exit(f"cannot connect ({args.tcp})")
    results = []
    try:
        for op in json.loads(args.ops):
            if op[0] == "write_text":
                results.append(run_op(client, ["write_hrs", op[1], encode_text(op[3], op[2])],
                                      args.unit))
                results[-1]["op"] = "write_text"
            elif op[0] in ("wait_coil", "wait_di"):
                results.append(wait_bit(client, op, args.unit))
            else:
                results.append(run_op(client, op, args.unit))
    finally:
        client.close()
    print(json.dumps(results), flush=True)


if __name__ == "__main__":
    main()
