#!/usr/bin/python3
"""An independent Modbus TCP fixture controller for the station's peer tests (pymodbus 3.0).

It holds the station's default fixture map (drivers/fixture/modbus_map.h), unit 1, with
zero_mode=True so that protocol address 0 is block index 0:

  coils              0 clamp_cmd, 1 excitation_enable, 2 lamp_pass, 3 lamp_fail
  discrete inputs    0 clamped, 1 released, 2 part_present, 3 door_closed, 4 estop_ok
  input registers    0 clamp_pressure (0.01 bar counts), 1 heartbeat
  holding registers  0 phase_pair (0, 1, 2)

The discrete inputs and the clamp pressure are fixed by the command line; the heartbeat
counts up every --heartbeat-ms from --heartbeat-start. After every write the coils and
holding registers are mirrored to --state-file as JSON (written to a temporary file and
renamed, so a reader never sees half a file). Once listening, the bound port is written to
--ready-file the same way. SIGTERM or SIGINT stops the server cleanly (exit code 0).

Run with /usr/bin/python3 (Debian's python3-pymodbus).
"""

import argparse
import asyncio
import json
import logging
import os
import signal
import sys

from pymodbus.datastore import (
    ModbusSequentialDataBlock,
    ModbusServerContext,
    ModbusSlaveContext,
)
from pymodbus.server.async_io import ModbusTcpServer

NUM_COILS = 4
NUM_DISCRETE = 5
NUM_INPUT_REGS = 2
NUM_HOLDING = 1


def write_atomically(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


class MirroredBlock(ModbusSequentialDataBlock):
    """A data block that reports every write to a callback."""

    def __init__(self, address, values, on_write):
        super().__init__(address, values)
        self._on_write = on_write

    def setValues(self, address, values):  # noqa: N802 (pymodbus' name)
        super().setValues(address, values)
        self._on_write()


def parse_ints(text, count, name):
    values = [int(v) for v in text.split(",")]
    if len(values) != count:
        sys.exit(f"--{name}: expected {count} comma-separated values, got {text!r}")
    return values


async def serve(args):
    state = {}
    coils = None
    holding = None

    def mirror():
        if args.state_file and coils is not None and holding is not None:
            state["coils"] = [int(bool(v)) for v in coils.getValues(0, NUM_COILS)]
            state["holding_registers"] = list(holding.getValues(0, NUM_HOLDING))
            write_atomically(args.state_file, json.dumps(state))

    discrete = ModbusSequentialDataBlock(0, parse_ints(args.discrete, NUM_DISCRETE, "discrete"))
    coils = MirroredBlock(0, [0] * NUM_COILS, mirror)
    holding = MirroredBlock(0, [0] * NUM_HOLDING, mirror)
    inputs = ModbusSequentialDataBlock(0, [args.pressure_counts, args.heartbeat_start])
    slave = ModbusSlaveContext(di=discrete, co=coils, hr=holding, ir=inputs, zero_mode=True)
    context = ModbusServerContext(slaves={args.unit: slave}, single=False)
    mirror()

    server = ModbusTcpServer(context, address=(args.host, args.port), allow_reuse_address=True)
    server_task = asyncio.create_task(server.serve_forever())
    await server.serving
    port = server.server.sockets[0].getsockname()[1]

    async def heartbeat():
        beat = args.heartbeat_start
        while True:
            await asyncio.sleep(args.heartbeat_ms / 1000.0)
            beat = (beat + 1) & 0xFFFF
            inputs.setValues(1, [beat])

    beat_task = asyncio.create_task(heartbeat())

    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    for sig in (signal.SIGTERM, signal.SIGINT):
        loop.add_signal_handler(sig, stop.set)
    if args.ready_file:
        write_atomically(args.ready_file, f"{port}\n")
    print(f"pymodbus fixture server on {args.host}:{port} unit {args.unit}", file=sys.stderr,
          flush=True)
    await stop.wait()
    beat_task.cancel()
    await server.shutdown()
    server_task.cancel()
    try:
        await server_task
    except asyncio.CancelledError:
        pass


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--host", default="127.0.0.1")
    p.add_argument("--port", type=int, default=0, help="0 = let the kernel pick a free port")
    p.add_argument("--unit", type=int, default=1)
    p.add_argument("--discrete", default="0,1,1,1,1",
                   help="clamped,released,part_present,door_closed,estop_ok as 0/1")
    p.add_argument("--pressure-counts", type=int, default=0, help="clamp pressure, 0.01 bar")
    p.add_argument("--heartbeat-start", type=int, default=0)
    p.add_argument("--heartbeat-ms", type=int, default=100)
    p.add_argument("--ready-file", help="written with the bound port once listening")
    p.add_argument("--state-file", help="coils and holding registers, as JSON, after writes")
    args = p.parse_args()
    logging.basicConfig(level=logging.WARNING, stream=sys.stderr)
    asyncio.run(serve(args))


if __name__ == "__main__":
    main()
