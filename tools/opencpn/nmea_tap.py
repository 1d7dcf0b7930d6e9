#!/usr/bin/env python3
"""Record the tracker's NMEA TCP stream (as a second client) with arrival timestamps."""
import socket, sys, time
host, port, out, dur = sys.argv[1], int(sys.argv[2]), sys.argv[3], float(sys.argv[4])
t0 = time.time()
while True:
    try:
        s = socket.create_connection((host, port)); break
    except OSError:
        if time.time() - t0 > 30: raise
        time.sleep(0.5)
s.settimeout(5)
f = open(out, 'w'); buf = b''
while time.time() - t0 < dur:
    try: d = s.recv(65536)
    except socket.timeout: continue
    if not d: break
    buf += d
    *lines, buf = buf.split(b'\n')
    now = time.time()
    for l in lines:
        f.write(f'{now:.3f} {l.decode(errors="replace").strip()}\n')
    f.flush()
