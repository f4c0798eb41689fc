#!/usr/bin/env python3
"""The console's calibration wizard on a replayed two-camera rig, driven over HTTP (issue 41).

    bench/calib_rig/console_rig.py BIN [--work DIR] [--seconds 90] [--seed 5] [--minutes 8]

Renders (once, cached in WORK) a synthetic two-camera calibration session: the boards held
before each camera, then the chessboard held where both see it, then both lying on the floor
(docs/synth.md). A daemon replays it, looping, as two cameras of a config naming only them, and
this script does what an operator does on the page: start the wizard, solve each camera when it
has 10 views or more (again at every new view while a solve is rejected), say "board on floor"
only while the boards lie on the floor (by the session's frame number), and once a camera is
posed and the joint solve has run after it, save. It prints the joint solve's figures, and each
saved model and cam1's pose relative to cam0 against the truth.
"""
import argparse
import ast
import json
import math
import os
import re
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request


def rodrigues(r):
    th = math.sqrt(sum(x * x for x in r))
    if th < 1e-15:
        return [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    x, y, z = (v / th for v in r)
    c, s = math.cos(th), math.sin(th)
    C = 1 - c
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def mul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def tr(A):
    return [[A[j][i] for j in range(3)] for i in range(3)]


def mv(A, v):
    return [sum(A[i][k] * v[k] for k in range(3)) for i in range(3)]


def pose(path):
    """cam_from_ground (R, t) of a .cameramodel (mrcal's extrinsics: rt_cam_ref)."""
    text = open(path).read()
    e = ast.literal_eval(text[text.index('{'):])['extrinsics']
    return rodrigues(e[:3]), list(e[3:6])


def angle_deg(R):
    return math.degrees(math.acos(max(-1.0, min(1.0, (sum(R[i][i] for i in range(3)) - 1) / 2))))


def against(saved, truth):
    """mm and degrees between two camera poses (camera centres, rotations)."""
    (Ra, ta), (Rb, tb) = saved, truth
    ca = [-v for v in mv(tr(Ra), ta)]
    cb = [-v for v in mv(tr(Rb), tb)]
    return math.dist(ca, cb) * 1000, angle_deg(mul(Ra, tr(Rb)))


def relative(a, b):
    """b_from_a."""
    (Ra, ta), (Rb, tb) = a, b
    R = mul(Rb, tr(Ra))
    Rt = mv(R, ta)
    return R, [tb[i] - Rt[i] for i in range(3)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('bin')
    ap.add_argument('--work', default='/tmp/ss-console-rig')
    ap.add_argument('--seconds', type=float, default=90)
    ap.add_argument('--fps', type=float, default=8)
    ap.add_argument('--seed', type=int, default=5)
    ap.add_argument('--minutes', type=float, default=8)
    a = ap.parse_args()
    session = os.path.join(a.work, f'rig-{a.seconds:g}s-{a.fps:g}fps-seed{a.seed}')
    if not os.path.exists(os.path.join(session, 'session.json')):
        subprocess.run([a.bin, '--log-level', 'warn', 'synth', '--out', session, '--kind', 'calibration',
                        '--seconds', str(a.seconds), '--fps', str(a.fps), '--size', '640x480', '--cameras', '2',
                        '--seed', str(a.seed), '--threads', '2', '--no-mattes'], check=True)
    frames = round(a.seconds * a.fps)
    # The boards lie on the floor for the last max(10 %, ...) of the session: say the word in its
    # first two thirds, so that they lie still long enough after it.
    floor_from = frames - round(0.1 * frames) + 4
    floor_to = frames - round(0.1 * frames) / 3
    run = os.path.join(a.work, 'station')
    subprocess.run(['rm', '-rf', run], check=True)
    os.makedirs(run)
    cfg = os.path.join(run, 'station.yaml')
    with open(cfg, 'w') as f:
        f.write('version: 1\ncameras:\n')
        for cam in ('cam0', 'cam1'):
            f.write(f'  - name: {cam}\n    source: replay\n    session: {session}\n    session_camera: {cam}\n'
                    '    loop: true\n    realtime: true\n')
        f.write('storage: {bank: station.bank, recording_dir: rec}\ncontrol: {address: 127.0.0.1, port: 0}\n')
    daemon = subprocess.Popen([a.bin, '--log-level', 'info', 'daemon', '--config', cfg, '--no-transitions'],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    url = None
    for line in daemon.stdout:
        m = re.search(r'http://127\.0\.0\.1:\d+', line)
        url = m.group(0) if m else url
        if 'control API on' in line and url:
            break
    log = open(os.path.join(run, 'daemon.log'), 'w')
    threading.Thread(target=lambda: [log.write(x) for x in daemon.stdout], daemon=True).start()

    def call(path, body=None):
        req = urllib.request.Request(url + path, method='GET' if body is None else 'POST',
                                     data=None if body is None else json.dumps(body).encode(),
                                     headers={'Content-Type': 'application/json'})
        try:
            with urllib.request.urlopen(req, timeout=30) as r:
                return json.loads(r.read())
        except urllib.error.HTTPError as e:
            return {'http': e.code, 'error': e.read().decode()[:300]}

    call('/api/calibration/start', {'board': 'chessboard:10x7:0.03', 'board_pose': [-0.15, 0.105, 0],
                                    'board_thickness_m': 0.001, 'floor_still_s': 0.5, 'min_coverage': 0.3})
    t0 = time.time()
    solved_at, posed_at, saved, c = {}, None, None, {}
    while time.time() - t0 < a.minutes * 60:
        c = call('/api/calibration')
        j = c.get('joint') or {}
        for k in c['cameras']:
            if k['step'] == 'intrinsics' and k['views'] >= max(10, solved_at.get(k['name'], 0) + 1) and not c.get('busy'):
                solved_at[k['name']] = k['views']
                call('/api/calibration/solve', {'camera': k['name']})
            if k['step'] == 'ground' and k.get('ground_word_needed'):
                v = call(f"/api/calibration/cameras/{k['name']}/view.json?width=64")
                if floor_from <= v.get('frame', -1) % frames < floor_to:
                    call('/api/calibration/ground', {'camera': k['name']})
        if posed_at is None and any(k['step'] in ('enclosure', 'done') for k in c['cameras']):
            posed_at = time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime(time.time() - 10))
        if posed_at and j.get('state') == 'solved' and j.get('at', '') >= posed_at:
            saved = call('/api/calibration/save', {}).get('saved')
            break
        time.sleep(2)
    daemon.terminate()
    daemon.wait()
    print(f'{time.time() - t0:.0f} s; load {os.getloadavg()[0]:.1f}')
    for k in c.get('cameras', []):
        print(f"{k['name']}: step {k['step']}, {k['views']} views, {k['frames']} frames fed; "
              f"ground {json.dumps(k.get('ground'))}; check {json.dumps(k.get('ground_check'))}")
    print('joint:', json.dumps(c.get('joint'), indent=1))
    if not saved:
        print('not saved')
        return 1
    models = {os.path.basename(f).split('.')[0]: f for f in saved['files'] if f.endswith('.cameramodel')}
    truth = {cam: pose(os.path.join(session, 'truth', cam + '.cameramodel')) for cam in ('cam0', 'cam1')}
    got = {cam: pose(models[cam]) for cam in ('cam0', 'cam1')}
    for cam in ('cam0', 'cam1'):
        mm, deg = against(got[cam], truth[cam])
        print(f'{cam} saved pose against the truth: {mm:.2f} mm, {deg:.3f} deg')
    rs, rt = relative(got['cam0'], got['cam1']), relative(truth['cam0'], truth['cam1'])
    print('cam1 relative to cam0 against the truth: %.2f mm, %.3f deg' %
          (math.dist(rs[1], rt[1]) * 1000, angle_deg(mul(rs[0], tr(rt[0])))))
    return 0


if __name__ == '__main__':
    sys.exit(main())
