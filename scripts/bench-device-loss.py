#!/usr/bin/env python3
"""A lost GPU under `pointrast serve`: the server is started with POINTRAST_INJECT_DEVICE_LOST=N (the Nth
submission of the process fails as a lost device), one WebSocket client at 1920x1080 zooms in and out at
every frame it gets, and the script records what the page was told, when its connection closed and when
the process exited, with its exit status and stderr. Writes device-loss.json and device-loss.md to OUT.

    python3 scripts/bench-device-loss.py POINTRAST OUT [SCENE ARGS...]   (default: terrain --points 1G)

INJECT (default 2000) names the submission that fails: past the upload (about one submission for every
4 M points) and some frames (one or two each), which the client keeps coming.
"""
import base64
import json
import os
import socket
import struct
import subprocess
import sys
import time


def ws_connect(port, path="/ws"):
    s = socket.create_connection(("127.0.0.1", port), timeout=120)
    key = base64.b64encode(os.urandom(16)).decode()
    s.sendall(("GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: %s\r\nSec-WebSocket-Version: 13\r\n\r\n" % (path, port, key)).encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = s.recv(4096)
        if not chunk:
            raise SystemExit("no WebSocket answer")
        head += chunk
    if b" 101 " not in head.split(b"\r\n")[0]:
        raise SystemExit("WebSocket refused: " + head.split(b"\r\n")[0].decode())
    return s, head.split(b"\r\n\r\n", 1)[1]


def ws_send(s, text):
    data = text.encode()
    mask = os.urandom(4)
    header = bytes([0x81])
    n = len(data)
    header += bytes([0x80 | n]) if n < 126 else bytes([0x80 | 126]) + struct.pack(">H", n)
    s.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))


class Reader:
    def __init__(self, s, rest):
        self.s, self.buf = s, rest

    def need(self, n):
        while len(self.buf) < n:
            chunk = self.s.recv(1 << 20)
            if not chunk:
                raise EOFError
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def message(self):
        b0, b1 = self.need(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self.need(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self.need(8))[0]
        return b0 & 0x0F, self.need(n)


def main():
    pr, out = sys.argv[1], sys.argv[2]
    scene = sys.argv[3:] or ["terrain", "--points", "1G"]
    inject = os.environ.get("INJECT", "2000")
    os.makedirs(out, exist_ok=True)
    env = dict(os.environ, POINTRAST_INJECT_DEVICE_LOST=inject)
    started = time.monotonic()
    server = subprocess.Popen([pr, "serve", *scene, "--port", "0", "--events", "--quiet"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env)
    port = None
    for line in server.stdout:
        event = json.loads(line)
        if event.get("event") == "listening":
            port = event["port"]
            break
    if port is None:
        raise SystemExit("serve exited before listening: " + server.stderr.read())
    listening_s = time.monotonic() - started
    s, rest = ws_connect(port)
    reader = Reader(s, rest)
    ws_send(s, json.dumps({"t": "resize", "w": 1920, "h": 1080}))
    frames, errors, told_at, closed_at, close_reason = 0, [], None, None, ""
    try:
        while True:
            opcode, data = reader.message()
            if opcode == 8:
                closed_at = time.monotonic()
                close_reason = data[2:].decode(errors="replace")
                break
            if opcode == 1:
                message = json.loads(data)
                if message.get("t") == "error":
                    errors.append(message.get("message", ""))
                    told_at = told_at or time.monotonic()
            elif opcode == 2:
                frame = struct.unpack_from("<I", data, 4)[0] if len(data) >= 8 else 0
                frames += 1
                ws_send(s, json.dumps({"t": "ack", "frame": frame}))
                ws_send(s, json.dumps({"t": "wheel", "x": 0.5, "y": 0.5, "steps": 1 if frames % 2 else -1}))
    except (EOFError, OSError):
        closed_at = closed_at or time.monotonic()
    try:
        status = server.wait(60)
    except subprocess.TimeoutExpired:
        server.kill()
        status = None
    exited_at = time.monotonic()
    stderr = server.stderr.read().strip()
    events = [json.loads(l) for l in server.stdout if l.strip().startswith("{")]
    result = {"scene": " ".join(scene), "inject_submission": int(inject), "listening_s": round(listening_s, 2),
              "frames_before_loss": frames, "page_told": errors, "close_reason": close_reason,
              "told_to_close_s": round(closed_at - told_at, 3) if told_at else None,
              "close_to_exit_s": round(exited_at - closed_at, 3), "exit_status": status, "stderr": stderr,
              "stderr_lines": len(stderr.splitlines()), "exit_event": [e for e in events if e.get("event") == "exit"]}
    print(json.dumps(result, indent=1))
    with open(os.path.join(out, "device-loss.json"), "w") as f:
        json.dump(result, f, indent=1)
    ok = status == 1 and errors and result["close_to_exit_s"] <= 5 and result["stderr_lines"] == 1
    with open(os.path.join(out, "device-loss.md"), "w") as f:
        f.write("# A lost GPU under `pointrast serve`\n\n")
        f.write("`POINTRAST_INJECT_DEVICE_LOST=%s pointrast serve %s` (the %sth submission of the process fails as "
                "a lost device), one WebSocket client at 1920x1080 zooming at every frame "
                "(`scripts/bench-device-loss.py`).\n\n" % (inject, " ".join(scene), inject))
        f.write("| | |\n| --- | --- |\n")
        f.write("| frames the client got before the loss | %d |\n" % frames)
        f.write("| what the page was told | %s |\n" % "; ".join(errors))
        f.write("| close reason | %s |\n" % close_reason)
        f.write("| from the message to the close | %s s |\n" % result["told_to_close_s"])
        f.write("| from the close to the process's exit | %.3f s |\n" % result["close_to_exit_s"])
        f.write("| exit status | %s |\n" % status)
        f.write("| stderr | %s |\n" % stderr.replace("|", "\\|"))
        f.write("| verdict | %s |\n" % ("reported to the page, exit 1 within 5 s, one line" if ok else "FAILED"))
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
