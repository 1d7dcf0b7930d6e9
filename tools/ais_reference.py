#!/usr/bin/env python3
"""Reference AIS decode for the tests of our Rust AIS decoder, made with pyais (3.3.1).
This is a test tool and is not part of the product.

Usage: ais_reference.py FILE... > OUT.csv

Each line that holds a !xxVDM or !xxVDO sentence (any talker) is used. Anything before the
`!` (gpsd `#` comments, tag blocks, time stamps) and anything after the `*HH` checksum
(receiver metadata such as `,s36310,d-081`) is cut off. A line whose checksum is wrong is
refused, as our parser refuses it. B&G/Navico GoFree sentences have an extra field after the
fill bits (`...,payload,0,2*CS`). The script removes that field and recomputes the checksum,
so the fill bits are read from the correct field. The script puts fragments back together
itself: the key is (formatter, sequential message id, channel), fragments must arrive in
order, and groups that never complete are dropped. pyais decodes each whole message.

CSV on stdout: file,line,formatter,msg_type,mmsi,lat_deg,lon_deg,sog_kn,cog_deg,heading_deg,name
`line` is the 1-based line of the message's last fragment. Fields that are missing or
"not available" are left empty. lat/lon are given only for types that report the sender's
position, not for positions inside type 6/8 application data. pyais returns type 17
positions in unsigned minutes, so this script converts them to signed degrees. Per-file
counts go to stderr. When pyais refuses a message (empty payload, unknown type), every line
of that message counts as refused.
"""
import csv
import os
import re
import sys
from functools import reduce

import pyais

SENTENCE = re.compile(r"!([A-Z]{2})(VD[MO]),[^*]*\*[0-9A-Fa-f]{2}")
FIELDS = ["file", "line", "formatter", "msg_type", "mmsi", "lat_deg", "lon_deg",
          "sog_kn", "cog_deg", "heading_deg", "name"]


def checksum(body):
    """XOR of the characters between `!` and `*`."""
    return reduce(lambda a, c: a ^ ord(c), body, 0)


def clean(text):
    """(sentence, gofree) for the VDM/VDO sentence in a line, or None when there is none or
    its checksum is wrong. gofree is True when the GoFree extra field was removed."""
    m = SENTENCE.search(text)
    if not m:
        return None
    sentence = m.group(0)
    body, cs = sentence[1:].split("*")
    if checksum(body) != int(cs, 16):
        return None
    fields = body.split(",")
    if len(fields) == 8:  # GoFree: VDM,count,num,id,chan,payload,fill,extra
        body = ",".join(fields[:7])
        return "!%s*%02X" % (body, checksum(body)), True
    return sentence, False


def value(x, na, digits=None):
    """x rounded to `digits` (if given), or "" when x is missing or equal to the n/a value na."""
    if x is None or (na is not None and abs(float(x) - na) < 1e-6):
        return ""
    return round(float(x), digits) if digits is not None else x


# Types whose lat/lon is the sender's position. Types 6/8 may carry a position inside their
# application data (pyais decodes some), which is left out.
POSITION_TYPES = {1, 2, 3, 4, 9, 11, 17, 18, 19, 21, 27}


def signed_tenth_minutes(minutes, bits):
    """Degrees from pyais' type 17 value. pyais gives minutes (raw / 10) and reads the field
    unsigned, so the sign is restored here."""
    raw = round(minutes * 10)
    return (raw - (1 << bits) if raw >= 1 << (bits - 1) else raw) / 600.0


def row(name, line, formatter, msg):
    t = msg.msg_type
    # n/a values: position 91/181 everywhere; type 27 sends whole knots and degrees
    # (63, 511), type 9 whole knots (1023), all other types tenths (102.3, 360).
    sog_na, cog_na = {27: (63, 511), 9: (1023, 360)}.get(t, (102.3, 360))
    lat, lon = getattr(msg, "lat", None), getattr(msg, "lon", None)
    if t not in POSITION_TYPES:
        lat = lon = None
    elif t == 17 and lat is not None and lon is not None:
        lat, lon = signed_tenth_minutes(lat, 17), signed_tenth_minutes(lon, 18)
    shipname = getattr(msg, "shipname", None) if t in (5, 19, 24) else None
    return {
        "file": name, "line": line, "formatter": formatter, "msg_type": t, "mmsi": msg.mmsi,
        "lat_deg": "" if value(lat, 91) == "" else "%.6f" % lat,
        "lon_deg": "" if value(lon, 181) == "" else "%.6f" % lon,
        "sog_kn": value(getattr(msg, "speed", None), sog_na, 1),
        "cog_deg": value(getattr(msg, "course", None), cog_na, 1),
        "heading_deg": value(getattr(msg, "heading", None), 511),
        "name": (shipname or "").replace("@", "").rstrip(),
    }


def run(path, out):
    name = os.path.basename(path)
    n = {"lines": 0, "decoded": 0, "dropped": 0, "refused": 0, "gofree": 0}
    pending = {}  # key -> (count, [(line, sentence)])

    def decode(formatter, frags):
        try:
            msg = pyais.decode(*[s for _, s in frags])
        except Exception:  # pyais refuses the message: all its lines are counted
            n["refused"] += len(frags)
            return
        n["decoded"] += 1
        out.writerow(row(name, frags[-1][0], formatter, msg))

    with open(path, errors="replace") as f:
        for lineno, text in enumerate(f, 1):
            if not re.search(r"![A-Z]{2}VD[MO]", text):
                continue
            n["lines"] += 1
            got = clean(text)
            if got is None:
                n["refused"] += 1
                continue
            sentence, gofree = got
            n["gofree"] += gofree
            fields = sentence.split(",")
            formatter = fields[0][3:]
            try:
                count, num = int(fields[1]), int(fields[2])
            except ValueError:
                n["refused"] += 1
                continue
            if count == 1:
                decode(formatter, [(lineno, sentence)])
                continue
            key = (formatter, fields[3], fields[4])
            have = pending.pop(key, None)
            if have and (have[0] != count or len(have[1]) + 1 != num):
                n["dropped"] += len(have[1])  # a group broken off by a fragment out of order
                have = None
            if have is None:
                if num != 1:
                    n["dropped"] += 1
                    continue
                have = (count, [])
            have[1].append((lineno, sentence))
            if num == count:
                decode(formatter, have[1])
            else:
                pending[key] = have
    n["dropped"] += sum(len(frags) for _, frags in pending.values())
    print("%s: %d VDM/VDO lines, %d messages decoded, %d fragments dropped, %d lines refused"
          " (%d GoFree lines normalised)" % (name, n["lines"], n["decoded"], n["dropped"],
                                            n["refused"], n["gofree"]), file=sys.stderr)


def main(paths):
    out = csv.DictWriter(sys.stdout, FIELDS, lineterminator="\n")
    out.writeheader()
    for path in paths:
        run(path, out)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
