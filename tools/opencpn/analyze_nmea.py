#!/usr/bin/env python3
"""Check a recorded tracker NMEA stream the way OpenCPN will use it.
usage: analyze_nmea.py TAPFILE   (lines: 'epoch sentence')"""
import sys, math, collections, re
def cks(s):
    body, _, ck = s[1:].partition('*')
    c = 0
    for ch in body: c ^= ord(ch)
    return ck.strip().upper() == f'{c:02X}'
def dm(v, h):
    if not v: return None
    x = float(v); d = int(x / 100); m = x - 100 * d
    r = d + m / 60
    return -r if h in ('S', 'W') else r
try:
    from geographiclib.geodesic import Geodesic
    print('TTM against TLL along the WGS84 geodesic (geographiclib)')
except ImportError:
    Geodesic = None
    print('geographiclib not installed: TTM against TLL on a plane at own ship (up to 37 m off at 10 NM)')
def ll_to_en(lat0, lon0, lat, lon):
    # East and north of (lat0, lon0) along the WGS84 geodesic (Karney's, geographiclib), as
    # the product's TLL puts a target at TTM's range and bearing (origin.rs). Without
    # geographiclib, the WGS84 radii at lat0: up to 37 m off at 10 NM at 50 deg N.
    if Geodesic is not None:
        g = Geodesic.WGS84.Inverse(lat0, lon0, lat, lon)
        az = math.radians(g['azi1'])
        return (g['s12'] * math.sin(az), g['s12'] * math.cos(az))
    else:
        a, f = 6378137.0, 1 / 298.257223563
        e2 = f * (2 - f)
        def w2(lat):
            return 1 - e2 * math.sin(math.radians(lat)) ** 2
        m = a * (1 - e2) / w2((lat0 + lat) / 2) ** 1.5
        n = a / math.sqrt(w2(lat0))
        return (math.radians(lon - lon0) * n * math.cos(math.radians(lat0)), math.radians(lat - lat0) * m)
lines = [l.rstrip('\n').split(' ', 1) for l in open(sys.argv[1]) if ' ' in l]
bad_ck = 0; too_long = 0; kinds = collections.Counter(); ais_decoded = 0
own = None; scans = []; cur = {'ttm': {}, 'tll': {}}
for t, s in lines:
    t = float(t)
    if not s.startswith('$'): continue
    if not cks(s): bad_ck += 1
    if len(s) > 82: too_long += 1
    f = s.split('*')[0].split(',')
    k = f[0][3:]; kinds[f[0]] += 1
    # OpenCPN 5.10 runs TTM/TLL/OSD through its AIS reassembly: fields 1 and 2 read by atoi
    # as part count and part number; equal and over 1, it decodes its buffer (a crash once
    # the buffer is long: docs/nmea.md).
    lead = lambda x: int(re.match(r'\d*', x).group() or 0)
    if k in ('TTM', 'TLL', 'OSD') and len(f) > 2 and lead(f[1]) > 1 and lead(f[1]) == lead(f[2]):
        ais_decoded += 1
    if k == 'TTM':
        # Units K (km, km/h) for a target whose number is its distance's whole NM (targets.rs).
        per = 1.852 if f[10] == 'K' else 1.0
        cur['ttm'][f[1]] = dict(t=t, rng=float(f[2] or 0) / per, brg=float(f[3] or 0), spd=float(f[5] or 0) / per, crs=float(f[6] or 0), motion_sent=bool(f[5] and f[6]),
                                cpa=(float(f[8]) / per if f[8] else None), tcpa=f[9], name=f[11], st=f[12], raw=s)
    elif k == 'TLL':
        cur['tll'][f[1]] = dict(t=t, lat=dm(f[2], f[3]), lon=dm(f[4], f[5]), name=f[6], st=f[8])
    elif k == 'RMC':
        own = dict(t=t, lat=dm(f[3], f[4]), lon=dm(f[5], f[6]), sog=float(f[7] or 0), cog=float(f[8] or 0), utc=f[1], date=f[9])
        # A scan's own ship comes first, before its targets (since 2026-12-07; after them
        # before): a scan runs from one RMC to the next.
        if 'own' in cur: scans.append(cur)
        cur = {'ttm': {}, 'tll': {}, 'own': own}
# The last scan, and the run's end (every target still shown goes as L after it).
if 'own' in cur:
    scans.append(cur)
print(f'sentences: {dict(kinds)}; bad checksums: {bad_ck}; longer than 82 chars: {too_long}; scans: {len(scans)}')
print(f'sentences OpenCPN 5.10 would decode as an AIS message (its crash, docs/nmea.md): {ais_decoded}')
nums = set(); stat = collections.Counter()
# TTM vs TLL consistency (TTM range/bearing from the RMC sent in the same scan)
dif = []; sec_split = 0
for sc in scans:
    o = sc['own']
    for n, m in sc['ttm'].items():
        nums.add(int(n)); stat[m['st']] += 1
        l = sc['tll'].get(n)
        if l and l['lat'] is not None:
            e, nn = ll_to_en(o['lat'], o['lon'], l['lat'], l['lon'])
            r = math.hypot(e, nn) / 1852; b = math.degrees(math.atan2(e, nn)) % 360
            # position from TTM
            te = m['rng'] * 1852 * math.sin(math.radians(m['brg'])); tn = m['rng'] * 1852 * math.cos(math.radians(m['brg']))
            dif.append(math.hypot(te - e, tn - nn))
            if int(m['t']) != int(l['t']): sec_split += 1
print(f'target numbers used: {len(nums)}, min {min(nums)} max {max(nums)}; status counts {dict(stat)}')
dif.sort()
print(f'TTM-vs-TLL position difference (m): median {dif[len(dif)//2]:.1f}, 95% {dif[int(len(dif)*.95)]:.1f}, max {dif[-1]:.1f}')
print(f'TTM/TLL pairs whose TLL arrived in a later wall-clock second than its TTM (OpenCPN then derives SOG/COG from the pair): {sec_split}')
# per number history: reuse / jumps / lost handling
hist = collections.defaultdict(list)
for i, sc in enumerate(scans):
    o = sc['own']
    for n, m in sc['ttm'].items():
        l = sc['tll'].get(n)
        if l and l['lat'] is not None:
            hist[n].append((i, m['st'], l['lat'], l['lon'], m['spd'], m['crs']))
reuse = []; jumps = []; lost_runs = []
for n, h in hist.items():
    for a, b in zip(h, h[1:]):
        gap = b[0] - a[0]
        e, nn = ll_to_en(a[2], a[3], b[2], b[3]); d = math.hypot(e, nn)
        if a[1] == 'L' and b[1] != 'L':
            reuse.append((n, a[0], b[0], d))
        elif gap == 1 and d > 200 + a[4] * 0.5144 * 2.5 * 2:
            jumps.append((n, a[0], a[1], b[1], round(d)))
    # length of L runs
    run = 0
    for x in h:
        if x[1] == 'L': run += 1
        elif run: lost_runs.append(run); run = 0
    if run: lost_runs.append(run)
print(f'numbers sent again after L (L then Q/T on the same number: the same track back, or another given the number): {len(reuse)}  e.g. {reuse[:8]}')
print(f'same number jumping >200 m + 2x its speed between consecutive scans (not via L): {len(jumps)} e.g. {jumps[:8]}')
if lost_runs: print(f'L is repeated for {min(lost_runs)}..{max(lost_runs)} scans (median {sorted(lost_runs)[len(lost_runs)//2]})')
qzero = sum(1 for sc in scans for m in sc['ttm'].values() if m['st'] in 'QL' and m['motion_sent'] and m['spd'] == 0 and m['crs'] == 0)
print(f'Q/L TTMs sent with speed 0.0 and course 0.0 (shown by OpenCPN as a stationary target; empty fields, a motion not known, are not counted): {qzero}')
print('first and last RMC:', scans[0]['own'] if scans else None, scans[-1]['own'] if scans else None)
# status transitions and reuse gaps
trans = collections.Counter(); gaps = collections.Counter()
for n, h in hist.items():
    for a, b in zip(h, h[1:]):
        if b[0] - a[0] == 1: trans[(a[1], b[1])] += 1
        if a[1] == 'L': gaps[b[0] - a[0]] += 1
    # number disappearing without an L
for n, h in hist.items():
    for a, b in zip(h, h[1:]):
        if b[0] - a[0] > 1 and a[1] != 'L': trans[(a[1], 'gap-without-L')] += 1
print('status transitions scan to scan:', dict(trans))
print('scans between an L and the number being used again:', dict(sorted(gaps.items())))
tl = [(n, a[0]) for n, h in hist.items() for a, b in zip(h, h[1:]) if a[1] == 'T' and b[1] == 'L']
print(f'confirmed (T) tracks that were lost (T->L): {len(tl)} {tl[:10]}')
