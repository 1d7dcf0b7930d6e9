#!/usr/bin/env python3
"""Which range scale fits a Navico capture's echoes to the AIS ships recorded beside it?

A research check, outside the product (which decodes a 4G or HALO spoke's range as radar_pi
and mayara do: `small / 4` when `large` is 0x80, as in the 4G capture). For each trial scale S (metres across the spoke's
samples) and each heading H (0-359 degrees), the mean echo occupancy (fraction of rotations
with a sample of at least level 8) at the places of the AIS ships that stand still (SOG
under 0.5 kn), seen from own ship's mean GPS position; it prints, per scale, the score at the
heading given (`--heading`) with its rank among the 360 headings, and the best heading. A
scale whose best heading is the ship's known heading, well above the rest, is the one the
echoes agree with.

Usage: navico_range_fit.py CAPTURE.pcap[.gz] NMEA_LOG --heading DEG [--scales 195,780,926]
Needs pyais (3.3.1, as tools/ais_reference.py; `pip install pyais==3.3.1`). Pure Python
otherwise; a few seconds. Captures: pcap with microsecond times, Ethernet or Linux cooked
(SLL) link layers.
"""
import argparse
import collections
import gzip
import math
import struct

from pyais import decode

LEVEL = 8  # of 15: an echo
BINS = 256  # range bins a spoke (4 samples each)


def spokes(path, group=(236, 6, 7, 8), port=6678):
    """(angle 0-4095, 512-byte data) of every 4G/HALO spoke sent to `group`:`port`."""
    f = gzip.open(path, "rb") if path.endswith(".gz") else open(path, "rb")
    head = f.read(24)
    assert struct.unpack("<I", head[:4])[0] == 0xA1B2C3D4, "pcap (microseconds) only"
    link = struct.unpack("<I", head[20:24])[0]
    # Bytes before the IP header: Ethernet, Linux cooked capture (SLL); nothing else read.
    skip = {1: 14, 113: 16}.get(link)
    if skip is None:
        raise SystemExit(f"{path}: link type {link} not read (Ethernet or Linux SLL only)")
    frags = collections.defaultdict(dict)
    while True:
        rec = f.read(16)
        if len(rec) < 16:
            return
        _, _, incl, _ = struct.unpack("<IIII", rec)
        data = f.read(incl)
        ip = data[skip:]
        if link == 1 and data[12:14] == b"\x81\x00":
            ip = data[18:]  # a VLAN tag
        if len(ip) < 20 or ip[0] >> 4 != 4 or ip[9] != 17 or tuple(ip[16:20]) != group:
            continue
        ihl = (ip[0] & 15) * 4
        total, ident, flags = struct.unpack(">HHH", ip[2:8])
        more, offset = flags & 0x2000, (flags & 0x1FFF) * 8
        body = ip[ihl:total]
        if more or offset:
            parts = frags[(bytes(ip[12:20]), ident)]
            parts[offset] = (body, more)
            at, whole = 0, False
            while at in parts:
                piece, m = parts[at]
                at += len(piece)
                if not m:
                    whole = True
                    break
            if not whole:
                continue
            body = b"".join(parts[o][0] for o in sorted(parts))
            del frags[(bytes(ip[12:20]), ident)]
        if struct.unpack(">H", body[2:4])[0] != port:
            continue
        payload = body[8:]
        for k in range((len(payload) - 8) // 536):
            spoke = payload[8 + 536 * k : 8 + 536 * (k + 1)]
            yield struct.unpack("<H", spoke[8:10])[0], spoke[24:]


def occupancy(path):
    """Per spoke (2048) and range bin (256): the fraction of rotations with an echo."""
    hits = [[0] * BINS for _ in range(2048)]
    seen = [0] * 2048
    count = 0
    for angle, data in spokes(path):
        count += 1
        a = (angle // 2) % 2048
        seen[a] += 1
        row = hits[a]
        for j in range(BINS):
            b0, b1 = data[2 * j], data[2 * j + 1]
            if max(b0 & 15, b0 >> 4, b1 & 15, b1 >> 4) >= LEVEL:
                row[j] += 1
    if count == 0:
        raise SystemExit(f"{path}: no Navico spokes (236.6.7.8:6678) found")
    return [[h / max(n, 1) for h in row] for row, n in zip(hits, seen)]


def still_ships(log):
    """Own ship's mean GPS position, and (range m, bearing deg) of the AIS ships under 0.5 kn."""
    own, ships, fragments = [], collections.defaultdict(list), []
    for line in open(log, errors="replace"):
        line = line.strip()
        f = line.split(",")
        if line[3:6] == "RMC" and len(f) > 6 and f[3] and f[5]:
            lat = int(f[3][:2]) + float(f[3][2:]) / 60
            lon = int(f[5][:3]) + float(f[5][3:]) / 60
            own.append((lat if f[4] == "N" else -lat, lon if f[6] == "E" else -lon))
        if line.startswith("!AIVDM"):
            fragments.append(line)
            if f[1] != f[2]:
                continue
            try:
                m = decode(*fragments).asdict()
            except Exception:
                fragments = []
                continue
            fragments = []
            if m["msg_type"] in (1, 2, 3, 18, 19) and m.get("lat") is not None and abs(m["lat"]) < 91:
                ships[m["mmsi"]].append((m["lat"], m["lon"], m.get("speed") or 0.0))
    if not own:
        raise SystemExit(f"{log}: no RMC with a position: own ship unknown")
    lat0 = sum(p[0] for p in own) / len(own)
    lon0 = sum(p[1] for p in own) / len(own)
    out = []
    for reports in ships.values():
        if max(r[2] for r in reports) >= 0.5:
            continue
        lat = sum(r[0] for r in reports) / len(reports)
        lon = sum(r[1] for r in reports) / len(reports)
        north = (lat - lat0) * 111_320
        east = (lon - lon0) * 111_320 * math.cos(math.radians(lat0))
        out.append((math.hypot(east, north), math.degrees(math.atan2(east, north)) % 360))
    return out


def score(occ, ships, scale_m, heading_deg):
    """Mean occupancy about the ships' places (±2 bins, ±4 spokes), head-up at `heading_deg`."""
    total = 0.0
    for r, b in ships:
        a0 = int(((b - heading_deg) % 360) / 360 * 2048)
        j0 = int(r / scale_m * BINS)
        cells = [
            occ[a % 2048][j]
            for a in range(a0 - 4, a0 + 5)
            for j in range(max(j0 - 2, 0), min(j0 + 3, BINS))
        ]
        total += sum(cells) / len(cells)
    return total / len(ships)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("capture")
    p.add_argument("nmea_log")
    p.add_argument("--heading", type=float, required=True, help="own ship's heading, deg")
    p.add_argument("--scales", default="195,390,585,740,780,820,926,1100,1389")
    a = p.parse_args()
    occ = occupancy(a.capture)
    ships = still_ships(a.nmea_log)
    given = round(a.heading) % 360
    print(f"{len(ships)} still AIS ships; nearest {min(r for r, _ in ships):.0f} m")
    print("| scale m | ships inside | score at the heading given | its rank of 360 | best heading | its score | chance (mean) |")
    print("|---|---|---|---|---|---|---|")
    for s in (float(x) for x in a.scales.split(",")):
        inside = [x for x in ships if x[0] < 0.97 * s]
        if len(inside) < 3:
            print(f"| {s:.0f} | {len(inside)} | too few to judge | | | | |")
            continue
        by_heading = [score(occ, inside, s, h) for h in range(360)]
        best = max(range(360), key=lambda h: by_heading[h])
        # Ties count against the heading given (a flat score ranks it last, not first).
        rank = sum(x >= by_heading[given] for x in by_heading)
        print(
            f"| {s:.0f} | {len(inside)} | {by_heading[given]:.3f} | {rank} | {best} | "
            f"{by_heading[best]:.3f} | {sum(by_heading) / 360:.3f} |"
        )


if __name__ == "__main__":
    main()
