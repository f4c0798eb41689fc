#!/usr/bin/env python3
"""How long a session's start and stop take to reach the console's event stream.

latency.py BINARY SESSION_DIR WORK_DIR [ROUNDS]: starts `BINARY daemon` on a config replaying
SESSION_DIR (one paced, looping camera; port 0), opens GET /api/events, then ROUNDS times posts
/api/session/start and /api/session/stop and times, from just before each POST, the first patch
in which status.session.active has the new value. Prints the milliseconds, their median and max.
"""
import http.client, json, os, re, subprocess, sys, threading, time, queue, statistics

binary, session, work = sys.argv[1], sys.argv[2], sys.argv[3]
rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 10
os.makedirs(work, exist_ok=True)
config = os.path.join(work, "station.yaml")
with open(config, "w") as f:
    f.write(f"""version: 1
cameras:
  - name: cam0
    source: replay
    session: {session}
    loop: true
    realtime: true
storage:
  bank: {work}/station.bank
  recording_dir: {work}/sessions
  stop_recording_below_mib: 0
  stop_sprites_below_mib: 0
control:
  address: 127.0.0.1
  port: 0
""")
daemon = subprocess.Popen([binary, "daemon", "--config", config], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True)
port = None
for line in daemon.stdout:
    m = re.search(r"console on http://127\.0\.0\.1:(\d+)", line)
    if m:
        port = int(m.group(1))
        break
threading.Thread(target=lambda: [None for _ in daemon.stdout], daemon=True).start()
assert port, "no port"
time.sleep(2)  # the camera trains

events = queue.Queue()
def stream():
    c = http.client.HTTPConnection("127.0.0.1", port)
    c.request("GET", "/api/events", headers={"Accept": "text/event-stream"})
    r = c.getresponse()
    name, data = None, None
    while True:
        line = r.readline().decode()
        if not line:
            return
        line = line.rstrip("\n")
        if line.startswith("event: "):
            name = line[7:]
        elif line.startswith("data: "):
            data = line[6:]
        elif line == "" and name:
            events.put((time.monotonic(), name, json.loads(data)))
            name = None
threading.Thread(target=stream, daemon=True).start()
events.get(timeout=10)  # the snapshot

def post(path, body):
    c = http.client.HTTPConnection("127.0.0.1", port)
    c.request("POST", path, body=json.dumps(body), headers={"Content-Type": "application/json"})
    r = c.getresponse()
    r.read()
    return r.status

def until_active(active, since):
    while True:
        t, name, data = events.get(timeout=10)
        if name == "patch" and isinstance(data.get("session"), dict) and \
                data["session"].get("active") == active and t >= since:
            return (t - since) * 1000

out = []
for k in range(rounds):
    time.sleep(0.37)  # off any beat of the daemon's
    t0 = time.monotonic()
    assert post("/api/session/start", {"name": f"round{k}"}) == 200
    out.append(until_active(True, t0))
    time.sleep(0.41)
    t0 = time.monotonic()
    assert post("/api/session/stop", {}) == 200
    out.append(until_active(False, t0))
daemon.terminate()
daemon.wait(timeout=20)
print("ms:", " ".join(f"{x:.0f}" for x in out))
print(f"median {statistics.median(out):.1f} ms, max {max(out):.1f} ms, n {len(out)}")
