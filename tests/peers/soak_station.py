#!/usr/bin/python3
"""Soak test of the station daemon (issue 14), driven from outside like a plant would.

Runs `eol station` against `eol fixture-sim` over real Modbus TCP and the simulated DAQ, and
starts N tests one after another through the HTTP API. At random it mixes in:

  fault      the fixture emulator is restarted with a fault that shows during excitation
             (door, clamp, pressure, e-stop, heartbeat, silence): that test must not PASS;
  kill       the daemon gets SIGKILL at a random moment of a test and is started again;
  full       the daemon runs with its files capped (RLIMIT_FSIZE, SIGXFSZ ignored, so a write
             beyond the cap fails like a full disk) for a few tests, then gets room again.

A verdict is "acknowledged" once GET /api/units/<serial> shows it finished. At the end it
checks, from the database file itself (Python's sqlite3, not our code): every acknowledged
verdict is stored with the same outcome; no test with a fault during it is PASS; nothing is
left RUNNING once the daemon has recovered; PRAGMA integrity_check is ok; and the daemon's
resident memory is flat over its longest life (growth from its 50th test to its last).

Prints a summary and writes it as JSON (--json FILE); exits 0 when every check holds, 1 when
one fails, 2 on a usage or setup error.
"""
import argparse
import http.client
import json
import os
import random
import resource
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time

FAULTS = ["door_opens", "clamp_drops", "pressure_low", "estop", "heartbeat_freezes",
          "stops_answering"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rss_mib(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


class Fixture:
    """`eol fixture-sim` on a fixed port, restarted with or without a fault."""

    def __init__(self, eol, port, workdir):
        self.eol, self.port, self.workdir, self.proc = eol, port, workdir, None

    def start(self, fault=None):
        self.stop()
        ready = os.path.join(self.workdir, "fixture.port")
        if os.path.exists(ready):
            os.remove(ready)
        args = [self.eol, "fixture-sim", "--port", str(self.port), "--ready-file", ready,
                "--part", "SOAK-ROTOR"]
        if fault:
            args += ["--fault", fault, "--fault-on-excitation", "--fault-after-ms", "20",
                     "--fault-duration-ms", "2500"]
        self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 30
        while not os.path.exists(ready):
            if self.proc.poll() is not None or time.time() > deadline:
                raise RuntimeError(f"fixture-sim did not start (exit {self.proc.poll()})")
            time.sleep(0.02)

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(10)
        self.proc = None


class Station:
    """`eol station` with its config; started (a log file per start), killed, capped."""

    def __init__(self, eol, config, workdir):
        self.eol, self.config, self.workdir = eol, config, workdir
        self.proc, self.port, self.starts = None, None, 0

    def start(self, fsize_cap=None):
        def limits():
            if fsize_cap is not None:
                signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a failed write, not a signal
                resource.setrlimit(resource.RLIMIT_FSIZE, (fsize_cap, fsize_cap))
        self.starts += 1
        log_path = os.path.join(self.workdir, f"station-{self.starts:04d}.log")
        with open(log_path, "wb") as log:
            self.proc = subprocess.Popen([self.eol, "station", "--config", self.config],
                                         stdout=log, stderr=subprocess.STDOUT,
                                         preexec_fn=limits)
        deadline = time.time() + 30
        while time.time() < deadline:
            with open(log_path, "rb") as f:
                for line in f.read().decode(errors="replace").splitlines():
                    if line.startswith("eol station:") and "http://127.0.0.1:" in line:
                        self.port = int(line.split("http://127.0.0.1:")[1].split("/")[0])
                        return
            if self.proc.poll() is not None:
                raise RuntimeError(f"eol station exited {self.proc.poll()} at start; "
                                   f"see {log_path}")
            time.sleep(0.05)
        raise RuntimeError(f"eol station did not say it was up within 30 s; see {log_path}")

    def kill(self):
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
            self.proc.wait(10)

    def stop(self):
        if self.proc and self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.kill()

    def request(self, method, path, body=None):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        try:
            headers = {"Content-Type": "application/json"} if body is not None else {}
            conn.request(method, path, body=json.dumps(body) if body is not None else None,
                         headers=headers)
            res = conn.getresponse()
            return res.status, res.read()
        finally:
            conn.close()


def wait_verdict(station, serial, timeout_s):
    """The finished test of `serial` as the API shows it, or None (timeout or daemon gone)."""
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        if station.proc.poll() is not None:
            return None
        try:
            status, body = station.request("GET", f"/api/units/{serial}")
        except OSError:
            status, body = 0, b""
        if status == 200:
            tests = json.loads(body)["tests"]
            if tests and tests[-1].get("finished_at"):
                return tests[-1]
        time.sleep(0.02)
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eol", required=True, help="the eol binary")
    ap.add_argument("--recipe", required=True, help="recipe JSON")
    ap.add_argument("--tests", type=int, default=200)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--fault-share", type=float, default=0.05)
    ap.add_argument("--kill-share", type=float, default=0.03)
    ap.add_argument("--full-share", type=float, default=0.01)
    ap.add_argument("--time-scale", type=float, default=0.05, help="simulated DAQ time scale")
    ap.add_argument("--out", help="work folder (default: a new temporary one)")
    ap.add_argument("--json", help="write the summary here")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = a.out or tempfile.mkdtemp(prefix="eol-soak-")
    os.makedirs(work, exist_ok=True)
    db_path = os.path.join(work, "soak.sqlite")
    fixture = Fixture(a.eol, free_port(), work)
    config = os.path.join(work, "station.json")
    with open(config, "w") as f:
        json.dump({"station_id": "soak", "recipe": os.path.abspath(a.recipe), "db": db_path,
                   "http": {"listen": "127.0.0.1", "port": 0},
                   "fixture": {"driver": "modbus-tcp", "host": "127.0.0.1",
                               "port": fixture.port},
                   "daq": {"driver": "sim", "time_scale": a.time_scale, "relay": "external"},
                   "safety": {"heartbeat_timeout_ms": 1000},
                   "sim": {"clamp_close_s": 0.05, "clamp_open_s": 0.03}}, f)
    station = Station(a.eol, config, work)
    acknowledged = {}      # serial -> outcome the API showed
    faulted = set()        # serials with a fault during their test
    counts = {"fault": 0, "kill": 0, "full": 0, "no_verdict": 0, "full_no_verdict": 0}
    rss = []               # (life, test index in that life, MiB)
    refusals = {}          # "status code" -> times POST /api/tests was refused
    life, in_life = 0, 0
    started_at = time.time()
    try:
        fixture.start()
        station.start()
        full_left = 0
        for i in range(a.tests):
            serial = f"SOAK-{a.seed}-{i:05d}"
            r = rng.random()
            episode = None
            forced = {10: "fault", 20: "kill", 30: "full"} if a.tests > 40 else {}
            if full_left == 0 and i in forced:
                episode = forced[i]  # every kind of episode at least once
            elif full_left == 0:
                if r < a.fault_share:
                    episode = "fault"
                elif r < a.fault_share + a.kill_share:
                    episode = "kill"
                elif r < a.fault_share + a.kill_share + a.full_share:
                    episode = "full"
            if episode == "fault":
                fixture.start(rng.choice(FAULTS))
                faulted.add(serial)
            if episode == "full":
                station.stop()
                # The cap is per file: the WAL (which starts empty after a clean stop) gets
                # room for about one record, the database file none to grow.
                cap = 64 * 1024
                station.start(fsize_cap=cap)
                life, in_life = life + 1, 0
                full_left = 4
            if episode:
                counts[episode] += 1
            # A busy or recovering station refuses; like a line PLC, retry for a while.
            deadline = time.time() + 15
            while True:
                try:
                    status, body = station.request("POST", "/api/tests", {"serial": serial})
                except OSError as e:
                    status, body = 0, str(e).encode()
                if status == 202 or time.time() > deadline or station.proc.poll() is not None:
                    break
                try:
                    code = json.loads(body)["error"]["code"]
                except (ValueError, KeyError, TypeError):
                    code = "no_answer"
                refusals[f"{status} {code}"] = refusals.get(f"{status} {code}", 0) + 1
                time.sleep(0.2)
            if status != 202:
                counts["no_verdict"] += 1
            elif episode == "kill":
                time.sleep(rng.uniform(0.0, 1.0))
                station.kill()
                station.start()
                life, in_life = life + 1, 0
            else:
                # Under the cap the record cannot be stored, so the API never shows it
                # finished (the station's board says "record not stored"): a short wait.
                t = wait_verdict(station, serial, 5 if full_left > 0 else 60)
                if t is None:
                    counts["no_verdict"] += 1
                else:
                    acknowledged[serial] = t["outcome"]
                if full_left > 0 and (t is None or t["outcome"] not in ("PASS", "FAIL")):
                    counts["full_no_verdict"] += 1
            if episode == "fault":
                time.sleep(2.6)  # the fault clears; the emulator then serves a healthy fixture
                fixture.start()
            if full_left > 0:
                full_left -= 1
                if full_left == 0:
                    station.stop()
                    station.start()
                    life, in_life = life + 1, 0
            in_life += 1
            m = rss_mib(station.proc.pid)
            if m is not None:
                rss.append((life, in_life, m))
            if (i + 1) % 50 == 0:
                print(f"soak: {i + 1}/{a.tests} tests, {time.time() - started_at:.0f} s",
                      file=sys.stderr, flush=True)
        station.stop()
        station.start()  # recovers whatever the last kill left
        station.stop()
    finally:
        station.kill()
        fixture.stop()

    con = sqlite3.connect(f"file:{db_path}?mode=ro", uri=True)
    integrity = con.execute("PRAGMA integrity_check").fetchone()[0]
    stored = {}
    for serial, outcome, finished in con.execute(
            "SELECT serial, outcome, finished_at FROM tests ORDER BY id"):
        stored[serial] = (outcome, finished)
    con.close()
    lost = [s for s, o in acknowledged.items() if s not in stored or stored[s][0] != o]
    pass_during_fault = [s for s in faulted if s in stored and stored[s][0] == "PASS"]
    running = [s for s, (o, f) in stored.items() if not f]
    lives = {}
    for lf, n, m in rss:
        lives.setdefault(lf, []).append((n, m))
    longest = max(lives.values(), key=len) if lives else []
    growth = None
    if len(longest) > 60:
        growth = longest[-1][1] - dict(longest).get(50, longest[0][1])
    summary = {"tests": a.tests, "seed": a.seed, "seconds": round(time.time() - started_at, 1),
               "episodes": counts, "refusals": refusals,
               "acknowledged": len(acknowledged), "stored": len(stored),
               "acknowledged_lost": len(lost), "pass_during_fault": len(pass_during_fault),
               "left_running": len(running), "integrity": integrity,
               "outcomes": {o: sum(1 for x in stored.values() if x[0] == o)
                            for o in sorted({x[0] for x in stored.values()})},
               "longest_life_tests": len(longest),
               "rss_growth_mib_longest_life": growth,
               "rss_first_mib": longest[0][1] if longest else None,
               "rss_last_mib": longest[-1][1] if longest else None}
    print(json.dumps(summary, indent=2))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(summary, f, indent=2)
    ok = (not lost and not pass_during_fault and not running and integrity == "ok"
          and (growth is None or growth < 20.0))
    for s in lost[:10]:
        print(f"LOST: {s} acknowledged {acknowledged[s]}, stored {stored.get(s)}", file=sys.stderr)
    for s in pass_during_fault[:10]:
        print(f"PASS DURING FAULT: {s}", file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except RuntimeError as e:
        print(f"soak: {e}", file=sys.stderr)
        sys.exit(2)
