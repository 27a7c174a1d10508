#!/usr/bin/python3
"""Fault injection against the station daemon: the station itself fails, its clients attack.

Runs `eol station` against `eol fixture-sim` over real Modbus TCP on 127.0.0.1, with a TCP proxy
of our own between them (to damage the fixture link), and repeats every failure of the safety
issue from outside, with nothing of the station's code (Python's socket, struct and sqlite3):

  plc_clients   idle, slow (one byte every 0.4 s), malformed and connect-and-close clients on
                the line-PLC Modbus port beside one well-behaved PLC: the daemon keeps serving;
  kill          SIGKILL in excitation, no restart: time until the fixture opens the relay;
  stop          SIGSTOP in excitation: time until the fixture opens the relay;
  stall         SIGSTOP for 1.5 s in excitation while the door (or the clamp) drops and comes
                back inside the stall: the test must not PASS;
  glitch        one reply of the fixture link truncated, garbage, late or from another unit
                id during excitation: the test must not PASS; time until the relay opens;
  http          a JSON body nested 100,000 deep, a request head with 20,000 header lines, 200
                slow clients and 100 event streams: the daemon lives, memory stays bounded,
                GET /api/status p99 is measured;
  store         a page of the store zeroed, the store emptied, the WAL deleted after SIGKILL:
                the daemon refuses the damaged store at start, and a verdict missing after the
                WAL was lost is named at start.

The relay is watched from outside: a third Modbus client reads the fixture's
excitation_enable coil (coil 1 of the default map) every 2 ms, straight from the emulator.

Prints one line per figure and writes them as JSON (--json FILE). Exits 0 when every check
holds, 1 when one fails, 2 on a usage or setup error.
"""
import argparse
import http.client
import json
import os
import random
import shutil
import signal
import socket
import sqlite3
import struct
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from soak_station import Fixture, Station, free_port, rss_mib, wait_verdict  # noqa: E402

EXCITATION_COIL = 1  # drivers/fixture/modbus_map.h: coil 1 excitation_enable
FIXTURE_UNIT = 1
PLC_UNIT = 1
PLC_SERIAL_REGISTER = 100  # station/daemon/plc/plc_map.h: holding registers 100.. serial


# --- Modbus TCP by hand ---------------------------------------------------------------------

def recv_exact(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError("closed by the peer")
        data += chunk
    return data


def read_frame(sock):
    """One Modbus TCP frame (MBAP header and PDU) as bytes."""
    head = recv_exact(sock, 7)
    length = struct.unpack(">H", head[4:6])[0]
    return head + recv_exact(sock, length - 1)


def request(sock, tid, unit, pdu):
    sock.sendall(struct.pack(">HHHB", tid, 0, len(pdu) + 1, unit) + pdu)
    return read_frame(sock)


class RelayWatch:
    """Reads the fixture's excitation coil every 2 ms on a thread; keeps (time, state)."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=2)
        self.state, self.changed_at, self.alive = None, time.monotonic(), True
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        tid = 0
        while self.alive:
            tid = (tid + 1) & 0xFFFF
            try:
                reply = request(self.sock, tid, FIXTURE_UNIT,
                                struct.pack(">BHH", 1, EXCITATION_COIL, 1))
                on = len(reply) >= 10 and reply[7] == 1 and (reply[9] & 1) == 1
            except OSError:
                on = None  # the emulator is gone or busy: unknown
            with self.lock:
                if on != self.state:
                    self.state, self.changed_at = on, time.monotonic()
            time.sleep(0.002)

    def wait(self, want, timeout_s):
        """The monotonic time the coil was first seen `want`, or None."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            with self.lock:
                if self.state == want:
                    return self.changed_at
            time.sleep(0.001)
        return None

    def close(self):
        self.alive = False
        self.thread.join(2)
        self.sock.close()


# --- A fixture link that can be damaged -----------------------------------------------------

class GlitchProxy:
    """TCP proxy station <-> fixture emulator. Once armed with a mode, the first reply sent
    at least `after_s` after the station switched excitation on is damaged:
      truncate  only its first 5 bytes are sent, then the connection stays silent;
      garbage   its bytes after the MBAP header are replaced by random ones;
      late      it is held back 0.4 s;
      foreign   its unit id is changed to another unit's."""

    def __init__(self, upstream_port):
        self.upstream_port = upstream_port
        self.listener = socket.socket()
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(8)
        self.port = self.listener.getsockname()[1]
        self.mode, self.after_s, self.excited_at, self.glitched_at = None, 0.1, None, None
        self.lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def arm(self, mode, after_s=0.1):
        with self.lock:
            self.mode, self.after_s, self.excited_at, self.glitched_at = mode, after_s, None, None

    def _accept(self):
        while True:
            try:
                client, _ = self.listener.accept()
            except OSError:
                return
            try:
                upstream = socket.create_connection(("127.0.0.1", self.upstream_port), timeout=5)
            except OSError:
                client.close()
                continue
            threading.Thread(target=self._pipe_requests, args=(client, upstream),
                             daemon=True).start()
            threading.Thread(target=self._pipe_replies, args=(upstream, client),
                             daemon=True).start()

    def _pipe_requests(self, client, upstream):
        try:
            while True:
                frame = read_frame(client)
                pdu = frame[7:]
                # Write single coil 1 = 0xFF00: the station closes the excitation relay.
                if len(pdu) >= 5 and pdu[0] == 5 and struct.unpack(">HH", pdu[1:5]) == (
                        EXCITATION_COIL, 0xFF00):
                    with self.lock:
                        if self.excited_at is None:
                            self.excited_at = time.monotonic()
                upstream.sendall(frame)
        except OSError:
            pass
        finally:
            client.close()
            upstream.close()

    def _take_glitch(self):
        with self.lock:
            if (self.mode is None or self.excited_at is None or self.glitched_at is not None
                    or time.monotonic() - self.excited_at < self.after_s):
                return None
            self.glitched_at = time.monotonic()
            return self.mode

    def _pipe_replies(self, upstream, client):
        try:
            while True:
                frame = read_frame(upstream)
                mode = self._take_glitch()
                if mode == "truncate":
                    client.sendall(frame[:5])
                    time.sleep(3600)  # silence: the frame never completes
                elif mode == "garbage":
                    frame = frame[:7] + bytes(random.randrange(256) for _ in frame[7:])
                elif mode == "late":
                    time.sleep(0.4)
                elif mode == "foreign":
                    frame = frame[:6] + bytes([(frame[6] % 247) + 1]) + frame[7:]
                client.sendall(frame)
        except OSError:
            pass
        finally:
            client.close()
            upstream.close()


# --- The scenarios --------------------------------------------------------------------------

class Rig:
    def __init__(self, eol, recipe, work, time_scale):
        self.eol, self.recipe, self.work, self.time_scale = eol, recipe, work, time_scale
        self.fixture = Fixture(eol, free_port(), work)
        self.proxy = None
        self.plc_port = free_port()
        self.db = os.path.join(work, "station.sqlite")
        self.config = os.path.join(work, "station.json")
        self.station = None
        self.serials = 0

    def write_config(self, db=None):
        with open(self.config, "w") as f:
            json.dump({"station_id": "fault", "recipe": os.path.abspath(self.recipe),
                       "db": db or self.db, "http": {"listen": "127.0.0.1", "port": 0},
                       "fixture": {"driver": "modbus-tcp", "host": "127.0.0.1",
                                   "port": self.proxy.port},
                       "daq": {"driver": "sim", "time_scale": self.time_scale,
                               "relay": "external"},
                       "plc": {"listen": "127.0.0.1", "port": self.plc_port},
                       "sim": {"clamp_close_s": 0.05, "clamp_open_s": 0.03}}, f)

    def start(self):
        self.fixture.start()
        self.proxy = GlitchProxy(self.fixture.port)
        self.write_config()
        self.station = Station(self.eol, self.config, self.work)
        self.station.start()

    def _start_fixture_with(self, extra):
        ready = os.path.join(self.work, "fixture.port")
        if os.path.exists(ready):
            os.remove(ready)
        self.fixture.proc = subprocess.Popen(
            [self.eol, "fixture-sim", "--port", str(self.fixture.port), "--ready-file", ready,
             "--part", "FAULT-ROTOR"] + extra, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        deadline = time.time() + 30
        while not os.path.exists(ready):
            if self.fixture.proc.poll() is not None or time.time() > deadline:
                raise RuntimeError("fixture-sim did not start")
            time.sleep(0.02)

    def restart_fixture(self, extra):
        self.fixture.stop()
        self._start_fixture_with(extra)

    def next_serial(self):
        self.serials += 1
        return f"FI-{self.serials:04d}"

    def start_test(self, serial):
        deadline = time.time() + 20
        while time.time() < deadline:
            try:
                status, _ = self.station.request("POST", "/api/tests", {"serial": serial})
            except OSError:
                status = 0
            if status == 202:
                return True
            time.sleep(0.1)
        return False

    def stop(self):
        if self.station:
            if self.station.proc and self.station.proc.poll() is None:
                try:
                    self.station.proc.send_signal(signal.SIGCONT)
                except OSError:
                    pass
            self.station.stop()
        self.fixture.stop()


def relay_runs(rig, how, runs):
    """SIGKILL or SIGSTOP in excitation; seconds until the fixture's relay opens."""
    times, stuck = [], 0
    for _ in range(runs):
        rig.restart_fixture([])
        rig.station.stop()
        rig.station.start()
        watch = RelayWatch(rig.fixture.port)
        serial = rig.next_serial()
        if not rig.start_test(serial):
            watch.close()
            raise RuntimeError("the station refused a test")
        on = watch.wait(True, 30)
        if on is None:
            watch.close()
            raise RuntimeError(f"{how}: excitation never seen on the fixture; see "
                               f"{rig.work}/station-{rig.station.starts:04d}.log")
        time.sleep(0.05)
        sig = signal.SIGKILL if how == "kill" else signal.SIGSTOP
        rig.station.proc.send_signal(sig)
        sent = time.monotonic()
        off = watch.wait(False, 10)
        watch.close()
        if off is None:
            stuck += 1
        else:
            times.append(max(0.0, off - sent))
        if how == "stop":
            rig.station.proc.send_signal(signal.SIGCONT)
            wait_verdict(rig.station, serial, 30)
        else:
            rig.station.proc.wait(10)
            rig.station.start()
    return {"runs": runs, "relay_stuck_10s": stuck,
            "relay_off_ms_max": round(1000 * max(times), 1) if times else None,
            "relay_off_ms_min": round(1000 * min(times), 1) if times else None}


def stall_runs(rig, fault, runs):
    """A 1.5 s SIGSTOP in excitation with `fault` coming and going inside it."""
    outcomes = []
    for _ in range(runs):
        rig.restart_fixture(["--fault", fault, "--fault-on-excitation", "--fault-after-ms",
                             "150", "--fault-duration-ms", "500"])
        watch = RelayWatch(rig.fixture.port)
        # The first test after the emulator restarted may find the fixture link broken (the
        # station reconnects for the next test): it ends ERROR without exciting; test again.
        for _attempt in range(3):
            serial = rig.next_serial()
            rig.start_test(serial)
            if watch.wait(True, 15) is not None:
                break
            wait_verdict(rig.station, serial, 30)
        else:
            watch.close()
            raise RuntimeError(f"stall {fault}: excitation never seen on the fixture; see "
                               f"{rig.work}/station-{rig.station.starts:04d}.log")
        rig.station.proc.send_signal(signal.SIGSTOP)
        time.sleep(1.5)
        rig.station.proc.send_signal(signal.SIGCONT)
        watch.close()
        t = wait_verdict(rig.station, serial, 60)
        outcomes.append(t["outcome"] if t else "none")
    return {"runs": runs, "outcomes": outcomes, "pass": outcomes.count("PASS")}


def glitch_runs(rig, modes, runs_each):
    result = {}
    for mode in modes:
        outcomes, late_ms = [], []
        for _ in range(runs_each):
            rig.restart_fixture([])
            rig.proxy.arm(mode, after_s=0.1)
            watch = RelayWatch(rig.fixture.port)
            serial = rig.next_serial()
            rig.start_test(serial)
            t = wait_verdict(rig.station, serial, 60)
            off = watch.wait(False, 5)
            watch.close()
            outcomes.append(t["outcome"] if t else "none")
            if rig.proxy.glitched_at is not None and off is not None:
                late_ms.append(1000 * max(0.0, off - rig.proxy.glitched_at))
            rig.proxy.arm(None)
            # A truncated reply leaves that link silent: the station reconnects.
        result[mode] = {"runs": runs_each, "outcomes": outcomes, "pass": outcomes.count("PASS"),
                        "relay_off_ms_max": round(max(late_ms), 1) if late_ms else None}
    return result


def plc_read(sock, tid):
    reply = request(sock, tid, PLC_UNIT, struct.pack(">BHH", 3, PLC_SERIAL_REGISTER, 1))
    return len(reply) >= 8 and reply[7] == 3


def plc_clients(rig, seconds=5.0):
    """A PLC polling every 100 ms on its own connection while 8 idle, 4 slow, 4 malformed
    and 4 connect-and-close clients crowd the port; after 3 s a second PLC connects."""
    socks, stop = [], threading.Event()
    good = socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2)
    for _ in range(8):
        try:
            socks.append(socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2))
        except OSError:
            pass
    frame = struct.pack(">HHHBBHH", 7, 0, 6, PLC_UNIT, 3, PLC_SERIAL_REGISTER, 1)

    def slow():
        try:
            s = socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2)
            i = 0
            while not stop.is_set():
                s.send(frame[i % len(frame):i % len(frame) + 1])
                i += 1
                stop.wait(0.4)
            s.close()
        except OSError:
            pass

    def malformed():
        while not stop.is_set():
            try:
                s = socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2)
                s.send(bytes(random.randrange(256) for _ in range(40)))
                s.send(struct.pack(">HHHB", 1, 0, 60000, 1) + b"\x03")  # a length of 60000
                stop.wait(0.3)
                s.close()
            except OSError:
                stop.wait(0.1)

    def churn():
        while not stop.is_set():
            try:
                socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2).close()
            except OSError:
                pass
            stop.wait(0.05)

    threads = [threading.Thread(target=f, daemon=True)
               for f in [slow] * 4 + [malformed] * 4 + [churn] * 4]
    for t in threads:
        t.start()
    answered, tries, worst, tid, late_ok = 0, 0, 0.0, 0, False
    begin = time.monotonic()
    while time.monotonic() - begin < seconds:
        tries += 1
        tid += 1
        t0 = time.monotonic()
        try:
            if plc_read(good, tid & 0xFFFF):
                answered += 1
                worst = max(worst, time.monotonic() - t0)
        except OSError:
            try:  # a PLC reconnects when its connection breaks
                good.close()
                good = socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2)
            except OSError:
                pass
        if not late_ok and time.monotonic() - begin > 3.0:
            try:
                with socket.create_connection(("127.0.0.1", rig.plc_port), timeout=2) as s:
                    s.settimeout(2)
                    late_ok = plc_read(s, 1)
            except OSError:
                pass
        time.sleep(0.1)
    stop.set()
    for t in threads:
        t.join(2)
    for s in socks + [good]:
        s.close()
    alive = rig.station.proc.poll() is None
    try:
        status, _ = rig.station.request("GET", "/api/status")
    except OSError:
        status = 0
    return {"daemon_alive": alive and status == 200, "good_plc_answered": answered,
            "good_plc_tries": tries, "good_plc_worst_ms": round(1000 * worst, 1),
            "second_plc_served": late_ok}


def http_attacks(rig):
    out = {}
    port = rig.station.port
    rss_before = rss_mib(rig.station.proc.pid)
    deep = ("[" * 100000 + "]" * 100000).encode()
    for path in ("/api/pod.svg", "/api/gap.svg"):
        try:
            c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
            c.request("POST", path, body=deep, headers={"Content-Type": "application/json"})
            out[f"deep_json{path}"] = c.getresponse().status
            c.close()
        except OSError as e:
            out[f"deep_json{path}"] = f"no answer: {e}"
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(b"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n")
            for i in range(20000):
                s.sendall(f"X-Filler-{i}: {'a' * 40}\r\n".encode())
            s.sendall(b"\r\n")
            out["wide_head_reply"] = s.recv(64).split(b"\r\n")[0].decode(errors="replace")
    except OSError as e:
        out["wide_head_reply"] = f"closed: {e.__class__.__name__}"
    def open_many(n, head):
        socks = []
        for _ in range(n):
            try:
                s = socket.create_connection(("127.0.0.1", port), timeout=2)
                s.send(head)
                socks.append(s)
            except OSError:
                break
        return socks

    slow = open_many(200, b"GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # never ends
    streams = open_many(100, b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    times, failed, kinds = [], 0, {}
    for _ in range(100):
        t0 = time.monotonic()
        try:
            status, _ = rig.station.request("GET", "/api/status")
            if status == 200:
                times.append(time.monotonic() - t0)
            else:
                failed += 1
                kinds[str(status)] = kinds.get(str(status), 0) + 1
        except OSError as e:
            failed += 1
            kinds[e.__class__.__name__] = kinds.get(e.__class__.__name__, 0) + 1
        for s in slow[:20]:
            try:
                s.send(b"X")  # keep the slow heads trickling
            except OSError:
                pass
    for s in slow + streams:
        s.close()
    times.sort()
    out["slow_clients"] = len(slow)
    out["event_streams"] = len(streams)
    out["status_failed"] = failed
    out["status_failed_kinds"] = kinds
    out["status_p99_ms"] = round(1000 * times[min(len(times) - 1, int(0.99 * len(times)))],
                                 1) if times else None
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
            s.sendall(b"GET /api/status HTTP/1.1\r\nHost: rebind.example.com\r\n\r\n")
            out["foreign_host_reply"] = s.recv(64).split(b"\r\n")[0].decode(errors="replace")
    except OSError as e:
        out["foreign_host_reply"] = f"closed: {e.__class__.__name__}"
    out["daemon_alive"] = rig.station.proc.poll() is None
    rss_after = rss_mib(rig.station.proc.pid) if out["daemon_alive"] else None
    out["rss_mib_before"] = round(rss_before or 0, 1)
    out["rss_mib_after"] = round(rss_after or 0, 1)
    return out


def start_exit(rig, db, seconds=20):
    """Starts the daemon on `db`; (exit code or None if it came up, its log text)."""
    rig.write_config(db=db)
    st = Station(rig.eol, rig.config, rig.work)
    try:
        st.start()
    except RuntimeError:
        pass
    code = st.proc.poll()
    if code is None:
        time.sleep(1.0)
        code = st.proc.poll()
    log = open(os.path.join(rig.work, f"station-{st.starts:04d}.log"), "rb").read().decode(
        errors="replace")
    st.stop()
    rig.write_config()
    return code, log


def store_damage(rig):
    out = {}
    # Some acknowledged verdicts, then a clean stop.
    for _ in range(3):
        serial = rig.next_serial()
        rig.start_test(serial)
        wait_verdict(rig.station, serial, 60)
    rig.station.stop()
    con = sqlite3.connect(rig.db)
    page_size = con.execute("PRAGMA page_size").fetchone()[0]
    pages = con.execute("PRAGMA page_count").fetchone()[0]
    con.close()
    damaged = os.path.join(rig.work, "zeroed.sqlite")
    shutil.copy(rig.db, damaged)
    with open(damaged, "r+b") as f:
        f.seek(page_size * (pages // 2))
        f.write(b"\0" * page_size)
    code, log = start_exit(rig, damaged)
    out["zeroed_page"] = {"refused": code not in (None, 0), "exit": code,
                          "says": last_error(log)}
    empty = os.path.join(rig.work, "empty.sqlite")
    open(empty, "w").close()
    code, log = start_exit(rig, empty)
    out["empty_file"] = {"refused": code not in (None, 0), "exit": code,
                         "says": last_error(log), "size_after": os.path.getsize(empty)}
    # SIGKILL right after a verdict was acknowledged, then the WAL deleted.
    rig.station.start()
    acked = []
    for _ in range(3):
        serial = rig.next_serial()
        rig.start_test(serial)
        t = wait_verdict(rig.station, serial, 60)
        if t:
            acked.append(serial)
    rig.station.kill()
    for suffix in ("-wal", "-shm"):
        if os.path.exists(rig.db + suffix):
            os.remove(rig.db + suffix)
    con = sqlite3.connect(rig.db)
    have = {r[0] for r in con.execute("SELECT serial FROM tests")}
    con.close()
    missing = [s for s in acked if s not in have]
    code, log = start_exit(rig, rig.db)
    named = all(s in log for s in missing) or ("lost" in log.lower() and missing)
    out["wal_deleted"] = {"acknowledged": len(acked), "missing": len(missing),
                          "missing_named_or_none": bool(not missing or named),
                          "says": last_error(log) if missing else ""}
    rig.station.start()
    return out


def last_error(log):
    lines = [ln for ln in log.splitlines() if "error" in ln.lower() or "refus" in ln.lower()]
    return (lines[-1] if lines else log.strip().splitlines()[-1] if log.strip() else "")[:300]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eol", required=True, help="the eol binary")
    ap.add_argument("--recipe", required=True, help="recipe JSON")
    ap.add_argument("--runs", type=int, default=3, help="runs of each kill/stop/stall/glitch")
    ap.add_argument("--time-scale", type=float, default=1.0, help="simulated DAQ time scale")
    ap.add_argument("--only", default="", help="comma-separated scenarios (default: all)")
    ap.add_argument("--out", help="work folder (default: a new temporary one)")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()
    only = set(filter(None, a.only.split(",")))

    def want(name):
        if only and name not in only:
            return False
        print(f"fault_injection: {name} ...", file=sys.stderr, flush=True)
        return True

    random.seed(1)
    work = a.out or tempfile.mkdtemp(prefix="eol-faults-")
    os.makedirs(work, exist_ok=True)
    rig = Rig(a.eol, a.recipe, work, a.time_scale)
    fig, failures = {}, []
    try:
        rig.start()
        if want("plc_clients"):
            fig["plc_clients"] = f = plc_clients(rig)
            if (not f["daemon_alive"] or f["good_plc_answered"] < f["good_plc_tries"] * 0.9
                    or not f["second_plc_served"]):
                failures.append("plc_clients")
        for how in ("kill", "stop"):
            if want(how):
                fig[how] = f = relay_runs(rig, how, a.runs)
                if f["relay_stuck_10s"] > 0:
                    failures.append(how)
        if want("stall"):
            fig["stall"] = {fault: stall_runs(rig, fault, a.runs)
                            for fault in ("door_opens", "clamp_drops")}
            if any(v["pass"] for v in fig["stall"].values()):
                failures.append("stall")
        if want("glitch"):
            fig["glitch"] = glitch_runs(rig, ["truncate", "garbage", "late", "foreign"], a.runs)
            if any(v["pass"] for v in fig["glitch"].values()):
                failures.append("glitch")
        if want("http"):
            fig["http"] = f = http_attacks(rig)
            if (not f["daemon_alive"] or f["status_failed"] > 2
                    or f["rss_mib_after"] > f["rss_mib_before"] + 100
                    or not str(f["foreign_host_reply"]).startswith(("HTTP/1.1 4", "closed"))):
                failures.append("http")
        if want("store"):
            rig.restart_fixture([])
            fig["store"] = f = store_damage(rig)
            if not (f["zeroed_page"]["refused"] and f["empty_file"]["refused"]
                    and f["wal_deleted"]["missing_named_or_none"]):
                failures.append("store")
    except (RuntimeError, OSError) as e:
        print(f"fault_injection: setup failed: {e}", file=sys.stderr)
        if rig.station is not None:
            log = os.path.join(work, f"station-{rig.station.starts:04d}.log")
            if os.path.exists(log):
                tail = open(log, "rb").read().decode(errors="replace").splitlines()[-15:]
                print("\n".join(["the station's log ends:"] + tail), file=sys.stderr)
        rig.stop()
        return 2
    finally:
        rig.stop()
    fig["failed"] = failures
    text = json.dumps(fig, indent=2)
    print(text)
    if a.json:
        with open(a.json, "w") as f:
            f.write(text + "\n")
    print(f"fault_injection: {len(failures)} of the scenarios failed: {', '.join(failures)}"
          if failures else "fault_injection: every check held")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
