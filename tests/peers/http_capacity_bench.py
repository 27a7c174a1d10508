#!/usr/bin/env python3
"""Capacity of the station's HTTP API, as stated in station/daemon/http/README.md ("Capacity").

Starts `eol station` (simulated fixture and DAQ, its own temporary directory), then
  1. holds N live event streams (GET /api/events, drained as they arrive) and runs
     `wrk` with C concurrent connections on GET /api/status: latency percentiles;
  2. sends a chunked request body of B bytes to POST /api/tests and samples the daemon's
     peak RSS (VmHWM in /proc) before and after: the body is refused at 64 KiB (413).

usage: http_capacity_bench.py EOL_BINARY [--streams 100] [--clients 200] [--seconds 20]
                              [--body-mb 1024]
Needs wrk (Debian package wrk). Prints one JSON object.
"""
import argparse
import json
import os
import re
import selectors
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def vm_hwm_kb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return -1


def start_station(eol, tmp):
    shutil.copy(os.path.join(ROOT, "recipes", "pmsm-10pole.json"), tmp)
    with open(os.path.join(tmp, "station.json"), "w") as f:
        json.dump({"station_id": "bench", "recipe": "pmsm-10pole.json", "db": "s.sqlite",
                   "http": {"listen": "127.0.0.1", "port": 0},
                   "fixture": {"driver": "sim"}, "daq": {"driver": "sim"}}, f)
    p = subprocess.Popen([eol, "station", "--config", os.path.join(tmp, "station.json")],
                         stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    deadline = time.time() + 60
    while time.time() < deadline:
        line = p.stdout.readline()
        m = re.search(r"ready, .* http://127\.0\.0\.1:(\d+)/", line)
        if m:
            return p, int(m.group(1))
        if not line and p.poll() is not None:
            break
    p.kill()
    raise SystemExit("the station did not start")


def hold_streams(port, n):
    """n event streams, read on one thread until stop is set; returns (sockets, stop, ok)."""
    sel = selectors.DefaultSelector()
    socks, ok = [], []
    for _ in range(n):
        s = socket.create_connection(("127.0.0.1", port))
        s.sendall(b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
        socks.append(s)
    for s in socks:
        s.settimeout(10)
        head = s.recv(4096)
        ok.append(head.startswith(b"HTTP/1.1 200") and b"text/event-stream" in head)
        s.setblocking(False)
        sel.register(s, selectors.EVENT_READ)
    stop = threading.Event()

    def drain():
        while not stop.is_set():
            for key, _ in sel.select(timeout=0.2):
                try:
                    key.fileobj.recv(65536)
                except OSError:
                    pass

    threading.Thread(target=drain, daemon=True).start()
    return socks, stop, sum(ok)


def wrk_latency(port, clients, seconds):
    out = subprocess.run(["wrk", "-t2", f"-c{clients}", f"-d{seconds}s", "--latency",
                          f"http://127.0.0.1:{port}/api/status"],
                         capture_output=True, text=True, check=True).stdout
    pct = {m.group(1): m.group(2) for m in re.finditer(r"^\s+(50|75|90|99)%\s+(\S+)", out, re.M)}
    rps = re.search(r"Requests/sec:\s+(\S+)", out)
    non2xx = re.search(r"Non-2xx or 3xx responses:\s+(\d+)", out)
    errors = re.search(r"Socket errors: (.*)", out)
    return {"p50": pct.get("50"), "p75": pct.get("75"), "p90": pct.get("90"),
            "p99": pct.get("99"), "requests_per_s": float(rps.group(1)) if rps else None,
            "non_2xx": int(non2xx.group(1)) if non2xx else 0,
            "socket_errors": errors.group(1) if errors else "none", "wrk": out}


def chunked_body(port, pid, total_bytes):
    before = vm_hwm_kb(pid)
    s = socket.create_connection(("127.0.0.1", port))
    s.sendall(b"POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
              b"Transfer-Encoding: chunked\r\n\r\n")
    chunk = b"100000\r\n" + b"x" * 0x100000 + b"\r\n"
    answer = bytearray()

    def read():
        s.settimeout(30)
        try:
            while True:
                b = s.recv(4096)
                if not b:
                    break
                answer.extend(b)
        except OSError:
            pass

    reader = threading.Thread(target=read)
    reader.start()
    sent = 0
    t0 = time.time()
    try:
        while sent < total_bytes:
            s.sendall(chunk)
            sent += 0x100000
    except OSError as e:
        refused = type(e).__name__
    else:
        refused = "not refused"
    reader.join()
    s.close()
    return {"body_bytes_offered": total_bytes, "body_bytes_sent_before_refusal": sent,
            "sender_saw": refused, "seconds": round(time.time() - t0, 3),
            "status_line": bytes(answer).split(b"\r\n", 1)[0].decode(errors="replace"),
            "peak_rss_kb_before": before, "peak_rss_kb_after": vm_hwm_kb(pid)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("eol")
    ap.add_argument("--streams", type=int, default=100)
    ap.add_argument("--clients", type=int, default=200)
    ap.add_argument("--seconds", type=int, default=20)
    ap.add_argument("--body-mb", type=int, default=1024)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        p, port = start_station(a.eol, tmp)
        try:
            socks, stop, live = hold_streams(port, a.streams)
            lat = wrk_latency(port, a.clients, a.seconds)
            still = sum(1 for s in socks if s.fileno() >= 0)
            stop.set()
            for s in socks:
                s.close()
            body = chunked_body(port, p.pid, a.body_mb << 20)
            print(json.dumps({"streams_requested": a.streams, "streams_live": live,
                              "streams_open_after": still, "clients": a.clients,
                              "status_latency": {k: v for k, v in lat.items() if k != "wrk"},
                              "chunked_body": body}, indent=2))
            sys.stderr.write(lat["wrk"])
        finally:
            p.terminate()
            p.wait(timeout=30)


if __name__ == "__main__":
    main()
