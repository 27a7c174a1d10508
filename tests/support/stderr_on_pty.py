#!/usr/bin/env python3
"""Runs a command with its stderr on a pseudo-terminal (as when a person watches a terminal)
and its stdout on a pipe (as when results are redirected), and prints one JSON object:
{"code": exit code, "stdout": ..., "stderr": what the terminal received}.

Usage: stderr_on_pty.py COMMAND [ARGS...]
"""
import json
import os
import pty
import subprocess
import sys
import threading


def main():
    master, slave = pty.openpty()
    proc = subprocess.Popen(sys.argv[1:], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=slave)
    os.close(slave)
    out = []
    reader = threading.Thread(target=lambda: out.append(proc.stdout.read()))
    reader.start()
    err = b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: every writer of the terminal has closed it
            break
        if not chunk:
            break
        err += chunk
    code = proc.wait()
    reader.join()
    os.close(master)
    print(json.dumps({"code": code, "stdout": out[0].decode("utf-8", "replace"),
                      "stderr": err.decode("utf-8", "replace")}))


if __name__ == "__main__":
    main()
