#!/usr/bin/python3
"""An independent Modbus client (pymodbus 3.0) for the peer tests of `eol fixture-sim`.

Runs a list of operations given as JSON and prints one JSON line with what each returned,
so that the C++ test holds the expectations:

  --ops '[["read_di", 0, 5], ["write_coil", 0, 1], ["sleep", 0.3], ["read_ir", 0, 2],
          ["read_di", 0, 5, {"unit": 2}]]'

Operations: read_coils, read_di, read_hr, read_ir (address, count); write_coil,
write_hr (address, value); write_coils, write_hrs (address, [values]);
mask_write_hr (address, and_mask, or_mask); sleep (seconds). An optional trailing object
overrides the unit id for that operation. Each result is {"op": name, "values": [...]},
{"op": name, "ok": true} for a write, {"op": name, "exception_code": n} for a Modbus
exception, or {"op": name, "error": text} when no valid answer came (a timeout).

Transport: --tcp HOST:PORT, or --rtu DEVICE with --baud/--parity/--data-bits/--stop-bits.
The unit id is always sent explicitly (--unit, default 1). Run with /usr/bin/python3.
"""

import argparse
import json
import sys
import time

from pymodbus.client import ModbusSerialClient, ModbusTcpClient
from pymodbus.exceptions import ModbusException
from pymodbus.framer.rtu_framer import ModbusRtuFramer
from pymodbus.pdu import ExceptionResponse
from pymodbus.register_write_message import MaskWriteRegisterRequest


def run_op(client, op, default_unit):
    name, args = op[0], list(op[1:])
    unit = default_unit
    if args and isinstance(args[-1], dict):
        unit = args.pop().get("unit", unit)
    if name == "sleep":
        time.sleep(float(args[0]))
        return {"op": name, "ok": True}
    calls = {
        "read_coils": lambda: client.read_coils(args[0], args[1], slave=unit),
        "read_di": lambda: client.read_discrete_inputs(args[0], args[1], slave=unit),
        "read_hr": lambda: client.read_holding_registers(args[0], args[1], slave=unit),
        "read_ir": lambda: client.read_input_registers(args[0], args[1], slave=unit),
        "write_coil": lambda: client.write_coil(args[0], bool(args[1]), slave=unit),
        "write_hr": lambda: client.write_register(args[0], args[1], slave=unit),
        "write_coils": lambda: client.write_coils(args[0], [bool(v) for v in args[1]],
                                                  slave=unit),
        "write_hrs": lambda: client.write_registers(args[0], args[1], slave=unit),
        # The mixin of pymodbus 3.0.0 does not pass slave= on for this one.
        "mask_write_hr": lambda: client.execute(
            MaskWriteRegisterRequest(args[0], args[1], args[2], unit=unit)),
    }
    if name not in calls:
        sys.exit(f"unknown operation {name!r}")
    try:
        rsp = calls[name]()
    except ModbusException as exc:
        return {"op": name, "error": str(exc)}
    if isinstance(rsp, ExceptionResponse):
        return {"op": name, "exception_code": rsp.exception_code}
    if isinstance(rsp, Exception) or rsp is None or rsp.isError():
        return {"op": name, "error": str(rsp)}
    if name in ("read_coils", "read_di"):
        return {"op": name, "values": [int(b) for b in rsp.bits[: args[1]]]}
    if name in ("read_hr", "read_ir"):
        return {"op": name, "values": list(rsp.registers)}
    return {"op": name, "ok": True}


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tcp", help="HOST:PORT")
    p.add_argument("--rtu", help="serial device")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--parity", default="E")
    p.add_argument("--data-bits", type=int, default=8)
    p.add_argument("--stop-bits", type=int, default=1)
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--timeout", type=int, default=1, help="seconds (pymodbus takes whole ones)")
    p.add_argument("--ops", required=True, help="JSON list of operations")
    args = p.parse_args()

    if bool(args.tcp) == bool(args.rtu):
        sys.exit("give exactly one of --tcp HOST:PORT and --rtu DEVICE")
    if args.tcp:
        host, port = args.tcp.rsplit(":", 1)
        client = ModbusTcpClient(host, port=int(port), timeout=args.timeout, retries=0)
    else:
        client = ModbusSerialClient(args.rtu, framer=ModbusRtuFramer, baudrate=args.baud,
                                    parity=args.parity, bytesize=args.data_bits,
                                    stopbits=args.stop_bits, timeout=args.timeout, retries=0)
    if not client.connect():
        sys.exit(f"cannot connect ({args.tcp or args.rtu})")
    try:
        results = [run_op(client, op, args.unit) for op in json.loads(args.ops)]
    finally:
        client.close()
    print(json.dumps(results), flush=True)


if __name__ == "__main__":
    main()
